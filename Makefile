# The two commands of the README, and what they need on a fresh machine.
#   make demo   build the FMUs and the tuner, run the closed-loop demo; needs only cargo and
#               python3 (no root): the venv gets the run set and the contour_fmu package
#   make test   lint, then every test (Rust unit/ABI tests, fmpy/libcosim/ecos and reference
#               tests); installs libclang-dev, libtbb12 and valgrind through apt when they
#               are missing (root), the venv gets the test set and the package
#   make fmus-all  the FMUs with linux64, win64 and aarch64-linux binaries (the distribution
#               build); installs its cross toolchain through apt (root) when missing
# Other targets: check (the fast development loop), fmus, ccc-tune, bindings, lint, asan,
# fuzz-smoke, fuzz-long, bench, leak-check, pso-claim, setup, cross-toolchain.

VENV   := .venv
PYTHON := $(VENV)/bin/python
PIP    := $(PYTHON) -m pip install --quiet --disable-pip-version-check
CARGO  ?= cargo

.PHONY: demo test check fmus fmus-all cross-toolchain ccc-tune contour-eval bindings lint bench pso-claim setup libclang libtbb valgrind leak-check \
        asan fuzz-smoke fuzz-long cargo-fuzz

# --- demo: cargo and python3 only ---------------------------------------------------------

demo: fmus ccc-tune contour-eval $(VENV)/.run-installed
	MPLBACKEND=Agg $(PYTHON) -m contour_fmu.demo --tune

fmus:
	$(CARGO) run --release -p fmu-build
	$(CARGO) build --release -p contour-cosim

ccc-tune:
	$(CARGO) build --release -p contour-tune --bin ccc-tune

# The distribution build (fmu-build/src/platform.rs): every FMU in target/fmu and
# target/fmu-si with linux64 (glibc 2.28), win64 and aarch64-linux binaries of one build
# (the FMI 3.0 FMUs in target/fmu3 and target/fmu3-si, the same binaries under
# x86_64-linux, x86_64-windows and aarch64-linux), compiled by Debian's rustc-web with the
# standard library built from its sources, and each platform's contour-cosim in
# target/cross/<triple>/release. About 7 minutes on 2 cores.
fmus-all: cross-toolchain
	$(CARGO) run --release -p fmu-build -- --platforms all
	$(CARGO) build --release -p contour-cosim

# The demo's ballbar test runs the circular test of ISO 230-4 with it.
contour-eval:
	$(CARGO) build --release -p contour-eval

# --- the Python venv ----------------------------------------------------------------------
# The package is installed in editable mode: python/contour_fmu is what runs. The test set
# includes the run set (requirements/test.txt starts with -r run.txt).

$(PYTHON):
	python3 -m venv $(VENV)

$(VENV)/.run-installed: requirements/run.txt python/pyproject.toml | $(PYTHON)
	$(PIP) -r requirements/run.txt -e './python[campaign,engines,plots,reference]'
	touch $@

$(VENV)/.test-installed: requirements/test.txt requirements/run.txt python/pyproject.toml | $(PYTHON)
	$(PIP) -r requirements/test.txt -e './python[test]'
	touch $@ $(VENV)/.run-installed

# --- test: may use root (apt) -------------------------------------------------------------

# bindgen needs libclang (the C API in libclang-dev; Debian images often carry only
# libclang-cpp, which bindgen cannot use): for the FMI-bindings regeneration (xtask).
libclang:
	@if ! dpkg -s libclang-dev >/dev/null 2>&1; then \
		echo "installing libclang-dev (needed by bindgen)"; \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libclang-dev; \
	fi

# ecospy's native engine (libecosc.so, the second co-simulation engine of the tests) links
# against Intel TBB's runtime, libtbb.so.12, which the wheel does not bundle.
libtbb:
	@if ! dpkg -s libtbb12 >/dev/null 2>&1; then \
		echo "installing libtbb12 (needed by ecospy)"; \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libtbb12; \
	fi

# The leak test's checker.
valgrind:
	@if ! command -v valgrind >/dev/null 2>&1; then \
		echo "installing valgrind (the leak test)"; \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq valgrind; \
	fi

# The fuzzer's driver (cargo-fuzz, from crates.io).
cargo-fuzz:
	@if ! $(CARGO) fuzz --version >/dev/null 2>&1; then \
		echo "installing cargo-fuzz (the fuzz smoke run)"; \
		$(CARGO) install --locked cargo-fuzz; \
	fi

# The distribution build's toolchain, pinned by path in fmu-build/src/platform.rs: Debian's
# rustc-web (rustc 1.96 as /usr/bin/rustc) with its standard library's sources, mingw-w64
# and aarch64 gcc, cargo-zigbuild and zig (ziglang, in the venv) for glibc 2.28; Wine and
# QEMU run the win64 and aarch64 programs in the tests.
CROSS_DEBS := rustc-web cargo-web rust-web-src gcc-mingw-w64-x86-64 gcc-aarch64-linux-gnu \
              libc6-dev-arm64-cross wine64 qemu-user
cross-toolchain: $(VENV)/.cross-installed
	@missing=$$(for p in $(CROSS_DEBS); do dpkg -s $$p >/dev/null 2>&1 || echo $$p; done); \
	if [ -n "$$missing" ]; then \
		echo "installing the cross toolchain:" $$missing; \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing; \
	fi
	@if ! cargo-zigbuild --version >/dev/null 2>&1; then \
		echo "installing cargo-zigbuild (links the Linux binaries against glibc 2.28)"; \
		$(CARGO) install --locked cargo-zigbuild@0.24.1; \
	fi

$(VENV)/.cross-installed: requirements/cross.txt | $(PYTHON)
	$(PIP) -r requirements/cross.txt
	touch $@

# Everything `make test` installs.
setup: libclang libtbb valgrind cargo-fuzz cross-toolchain $(VENV)/.test-installed

# The fast development loop: format, lints, the libraries' unit tests and the Rust
# integration and ABI tests; nothing installed, no Python, no sanitizer, no fuzzer.
check: lint
	$(CARGO) test -p contour-core -p contour-fmu --features contour-fmu/test-hooks

lint:
	$(CARGO) fmt --all -- --check
	$(CARGO) clippy --workspace --all-targets --features contour-fmu/test-hooks -- -D warnings

# Each stage prints the time it starts, and pytest its slowest tests: where the
# 35 minutes go is in every CI log.
test: setup lint
	@date '+%T cargo test'
	$(CARGO) test --workspace --features contour-fmu/test-hooks
	@date '+%T asan'
	$(MAKE) --no-print-directory asan
	@date '+%T fuzz smoke'
	fuzz/smoke.sh 30
	@date '+%T pytest'
	$(PYTHON) -m pytest -q --durations=15 tests/fmpy tests/reference
	@date '+%T done'

# Every fuzz target (fuzz/README.md) for 30 s each (about 2 min once built), or 10 M
# executions each (about 6 h for fmi_calls and deserialize_state on 2 loaded cores;
# MAX_SECONDS=N fuzz/long.sh caps each target).
fuzz-smoke: cargo-fuzz
	fuzz/smoke.sh 30
fuzz-long: cargo-fuzz
	fuzz/long.sh 10000000

# AddressSanitizer, with its leak checker, over the FMI boundary: the libraries' unit tests
# (contour-fmu's and contour-core's) and the ABI test binary, the dlopened cdylib
# instrumented as well. The stable toolchain's -Zsanitizer needs RUSTC_BOOTSTRAP; --target keeps build scripts and proc macros
# uninstrumented; the test executables export the ASan runtime for the cdylib to find.
HOST       := $(shell rustc -vV 2>/dev/null | sed -n 's/^host: //p')
ASAN_FLAGS := -Zsanitizer=address -Clink-arg=-Wl,--export-dynamic
ASAN_TESTS := --lib --test abi
asan:
	RUSTC_BOOTSTRAP=1 CARGO_TARGET_DIR=target/asan RUSTFLAGS="$(ASAN_FLAGS)" \
		$(CARGO) test -p contour-fmu --target $(HOST) --features test-hooks $(ASAN_TESTS)
	RUSTC_BOOTSTRAP=1 CARGO_TARGET_DIR=target/asan RUSTFLAGS="$(ASAN_FLAGS)" \
		$(CARGO) test -p contour-core --target $(HOST) --lib
	@nm -D target/asan/$(HOST)/debug/deps/libcontour_fmu.so | grep -q __asan_report_load8 \
		|| { echo "asan: the library under test is not instrumented"; exit 1; }
	@echo "asan: no report from AddressSanitizer or LeakSanitizer"

# Regenerates fmi2-bindings/src/bindings.rs from the FMI 2.0 headers.
bindings: libclang
	$(CARGO) run -p xtask -- bindings

# --- measurements -------------------------------------------------------------------------

# One page of ratios measured in this run (target/bench-report/report.md); a part that
# fails still lets the page print, marked "not measured". benches/c_harness/run.sh times
# the packaged FMUs from a C importer against a bare C pass-through FMU it builds (gcc),
# then counts their instructions per sample under callgrind (needs valgrind).
BENCH_REPORT := $(or $(CARGO_TARGET_DIR),target)/bench-report
CRITERION    := --warm-up-time 1 --measurement-time 3 --sample-size 50 --noplot

bench: fmus ccc-tune contour-eval $(VENV)/.test-installed
	$(PYTHON) benches/report.py --start
	-PYTHON=$(PYTHON) benches/c_harness/run.sh --json $(BENCH_REPORT)/c_harness.json
	-PYTHON=$(PYTHON) benches/c_harness/run.sh --callgrind --json $(BENCH_REPORT)/c_harness_callgrind.json
	-$(CARGO) bench --features test-hooks --bench fuzzy --bench controller --bench five_axis \
		--bench fmu_abi -- $(CRITERION)
	-$(CARGO) build --release -p contour-fmu --example fuzzy_timing --example fuzzy_dump
	-$(PYTHON) benches/fuzzy_vs_skfuzzy.py --evals 30 --json $(BENCH_REPORT)/fuzzy_vs_skfuzzy.json
	-$(PYTHON) benches/tuning_vs_pyswarms_fmu.py --particles 6 --iters 5 \
		--json $(BENCH_REPORT)/tuning_vs_pyswarms_fmu.json
	-$(PYTHON) benches/pso_tables.py --json $(BENCH_REPORT)/pso_tables.json
	-$(CARGO) build --release -p contour-fmu --example closed_loop_timing
	-$(PYTHON) benches/native_throughput.py --json $(BENCH_REPORT)/native_throughput.json
	-$(PYTHON) benches/campaign_scaling.py --json $(BENCH_REPORT)/campaign_scaling.json
	-$(PYTHON) benches/contour_eval_speed.py --json $(BENCH_REPORT)/contour_eval_speed.json
	-$(PYTHON) benches/restore_fuzz_speed.py --json $(BENCH_REPORT)/restore_fuzz_speed.json
	-$(PYTHON) benches/ccc_sample_cost.py --json $(BENCH_REPORT)/ccc_sample_cost.json
	$(PYTHON) benches/report.py

# Every model's life cycle 10 000 times under valgrind's full memcheck: leaks and
# uninitialised values (hours on 2 cores).
leak-check: valgrind
	$(CARGO) build --release --example lifecycle
	valgrind --leak-check=full --errors-for-leak-kinds=definite,indirect,possible \
		--undef-value-errors=yes --error-exitcode=1 target/release/examples/lifecycle 10000

# The paper's PSO claim at its full budget (about 10 minutes).
pso-claim:
	$(CARGO) run --release -p contour-tune --example pso_claim
