# Sourced by smoke.sh and long.sh: builds the targets and runs each with the libFuzzer
# flags given, then prints one line per target and returns nonzero if any target found
# a crash, a leak, a timeout or an out-of-memory.
#
# The machine has one stable toolchain: RUSTC_BOOTSTRAP=1 lets cargo-fuzz pass its
# nightly-only flags to it (the sanitizer runtimes ship with stable's standard library).

TARGETS=(fmi_calls deserialize_state nurbs_json apt_cl gcode_program)
FUZZ_DIR=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
BIN="$FUZZ_DIR/target/x86_64-unknown-linux-gnu/release"
export RUSTC_BOOTSTRAP=1

build_targets() {
    (cd "$FUZZ_DIR" && cargo fuzz build)
}

# The seeds the targets write themselves (not committed, so they follow the formats):
# valid FMU states of every model for deserialize_state, and for fmi_calls a few call
# sequences random bytes seldom reach, in the input format of the build.
write_seeds() {
    local target
    mkdir -p "$FUZZ_DIR/logs"
    : >"$FUZZ_DIR/logs/seeds.log"
    for target in deserialize_state fmi_calls; do
        mkdir -p "$FUZZ_DIR/corpus/$target"
        CONTOUR_FUZZ_SEEDS="$FUZZ_DIR/corpus/$target" "$BIN/$target" \
            >>"$FUZZ_DIR/logs/seeds.log" 2>&1 || {
            echo "writing the $target seeds failed: see fuzz/logs/seeds.log" >&2
            return 1
        }
    done
}

# run_targets LIBFUZZER_FLAGS... : each target in turn (one core), logs in logs/.
run_targets() {
    local failed=0 target corpus log status
    mkdir -p "$FUZZ_DIR/logs"
    printf '%-18s %12s %10s %8s %8s %8s  %s\n' target executions exec/s cov ft seconds result
    for target in "${TARGETS[@]}"; do
        corpus=("corpus/$target")
        mkdir -p "$FUZZ_DIR/corpus/$target"
        [ -d "$FUZZ_DIR/seeds/$target" ] && corpus+=("seeds/$target")
        log="$FUZZ_DIR/logs/$target.log"
        local start=$SECONDS
        mkdir -p "$FUZZ_DIR/artifacts/$target"
        # The binaries of the one build above (what `cargo fuzz run` runs, minus its
        # rebuild check: other work on src/ must not rebuild the library mid-run).
        # -timeout: no input may take 10 s (a hang is a finding); -rss_limit_mb: nor
        # 2 GB of memory.
        if (cd "$FUZZ_DIR" && ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_odr_violation=0" \
            "$BIN/$target" -artifact_prefix="artifacts/$target/" "${corpus[@]}" \
            -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 "$@") >"$log" 2>&1; then
            status=ok
        else
            status="FAILED (see $log and artifacts/$target/)"
            failed=1
        fi
        local runs speed cov ft
        runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
        # No final stats after a crash: the last status line's count.
        [ -n "$runs" ] || runs=$(grep -o '^#[0-9]*' "$log" | tail -1 | tr -d '#' || true)
        speed=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
        cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*' || true)
        ft=$(grep -o 'ft: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*' || true)
        printf '%-18s %12s %10s %8s %8s %8s  %s\n' "$target" "${runs:-?}" "${speed:-?}" \
            "${cov:-?}" "${ft:-?}" "$((SECONDS - start))" "$status"
    done
    return $failed
}
