#!/bin/sh
# Builds and runs the C harness (benches/c_harness/harness.c) on the bare C pass-through
# (pass_through.c, built here) and on the packaged XYServoPlant and ContourCCC2D FMUs,
# unpacked from <target>/fmu/ (`cargo run --release -p fmu-build` makes them; FMU_DIR=DIR
# takes them from DIR instead). Everything it builds goes to <target>/c_harness/.
#
#   benches/c_harness/run.sh [--json FILE] [harness options]   ns per sample and ratios
#   benches/c_harness/run.sh --callgrind [--json FILE]          instructions per sample
#
# The second runs each model alone under valgrind --tool=callgrind, counting only the
# calls-only loop (--toggle-collect=run_calls_only): instruction counts do not depend on
# the load of the machine, so they show a change that timings on 2 shared cores hide.
set -eu
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../.." && pwd)
TARGET=${CARGO_TARGET_DIR:-$ROOT/target}
FMU_DIR=${FMU_DIR:-$TARGET/fmu}
OUT=$TARGET/c_harness
CC=${CC:-gcc}
PYTHON=${PYTHON:-python3}
MODELS="XYServoPlant ContourCCC2D"

mkdir -p "$OUT"
$CC -O2 -Wall -Wextra -I"$ROOT/third_party/fmi2" -o "$OUT/harness" "$HERE/harness.c" -ldl -lm
$CC -O2 -Wall -Wextra -shared -fPIC -I"$ROOT/third_party/fmi2" -o "$OUT/PassThroughC.so" \
    "$HERE/pass_through.c"

set -- "$@" ""
callgrind=no
while [ -n "${1-}" ]; do
    case $1 in
        --callgrind) callgrind=yes ;;
        *) set -- "$@" "$1" ;;
    esac
    shift
done
shift  # the "" marker

specs="bare=$OUT/PassThroughC.so:$HERE/PassThroughC.xml"
for model in $MODELS; do
    fmu=$FMU_DIR/$model.fmu
    [ -f "$fmu" ] || { echo "run.sh: no $fmu (cargo run --release -p fmu-build)" >&2; exit 1; }
    rm -rf "$OUT/fmu/$model"
    "$PYTHON" -m zipfile -e "$fmu" "$OUT/fmu/$model"
    specs="$specs $model=$OUT/fmu/$model/binaries/linux64/$model.so:$OUT/fmu/$model/modelDescription.xml"
done

if [ $callgrind = no ]; then
    # shellcheck disable=SC2086
    exec "$OUT/harness" "$@" $specs
fi

command -v valgrind >/dev/null 2>&1 || { echo "run.sh: --callgrind needs valgrind" >&2; exit 1; }
json=
if [ "${1-}" = --json ]; then json=$2; fi
SAMPLES=2000 PASSES=4 WARMUP=1
lines=
for spec in $specs; do
    label=${spec%%=*}
    file=$OUT/callgrind.$label.out
    # shellcheck disable=SC2086
    valgrind --tool=callgrind --toggle-collect=run_calls_only --callgrind-out-file="$file" \
        "$OUT/harness" --samples $SAMPLES --passes $PASSES --warmup $WARMUP --only "$label" \
        $specs >/dev/null 2>"$OUT/callgrind.$label.log" \
        || { cat "$OUT/callgrind.$label.log" >&2; exit 1; }
    total=$(sed -n 's/^summary: *\([0-9]*\).*/\1/p; s/^totals: *\([0-9]*\).*/\1/p' "$file" | head -n 1)
    per=$(( total / (SAMPLES * (PASSES + WARMUP)) ))
    printf '  %-14s %8d instructions per sample\n' "$label" "$per"
    lines="$lines${lines:+, }\"$label\": $per"
done
if [ -n "$json" ]; then
    printf '{"instructions_per_sample": {%s}}\n' "$lines" >"$json"
fi
