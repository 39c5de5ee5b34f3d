# The two commands of the README, and what they need on a fresh machine.
#   make demo   build the FMUs and run the closed-loop demo
#   make test   run every test (Rust unit/ABI tests, fmpy/libcosim and reference tests)

VENV   := .venv
PYTHON := $(VENV)/bin/python
CARGO  ?= cargo

.PHONY: demo test fmus setup libclang libtbb lint bench pso-claim

setup: libclang libtbb $(VENV)/.installed

# fmi-sys generates its FMI bindings with bindgen, which needs libclang (the C API in
# libclang-dev; Debian images often carry only libclang-cpp, which bindgen cannot use).
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

$(VENV)/.installed: requirements.txt
	python3 -m venv $(VENV)
	$(VENV)/bin/pip install --quiet --disable-pip-version-check -r requirements.txt
	touch $@

fmus: setup
	$(CARGO) run --release -p fmu-build

demo: fmus
	$(CARGO) build --release --bin ccc-tune
	MPLBACKEND=Agg $(PYTHON) tests/fmpy/demo.py --tune

lint: setup
	$(CARGO) fmt --all -- --check
	$(CARGO) clippy --workspace --all-targets --features contour-fmu/test-hooks -- -D warnings

test: setup lint
	$(CARGO) test --workspace --features contour-fmu/test-hooks
	$(PYTHON) -m pytest -q tests/fmpy tests/reference

bench: setup
	$(CARGO) bench --bench fuzzy --bench controller
	$(CARGO) build --release --bin ccc-tune --example fuzzy_timing
	$(PYTHON) benches/fuzzy_vs_skfuzzy.py
	$(PYTHON) benches/tuning_vs_pyswarms_fmu.py
	$(PYTHON) benches/pso_tables.py

# The paper's PSO claim at its full budget (about 10 minutes).
pso-claim: setup
	$(CARGO) run --release --example pso_claim
