# The two commands of the README, and what they need on a fresh machine.
#   make demo   build the FMUs and run the closed-loop demo
#   make test   run every test (Rust unit/ABI tests, fmpy/libcosim and reference tests)

VENV   := .venv
PYTHON := $(VENV)/bin/python
CARGO  ?= cargo

.PHONY: demo test fmus setup libclang lint bench

setup: libclang $(VENV)/.installed

# fmi-sys generates its FMI bindings with bindgen, which needs libclang.
libclang:
	@if ! ls /usr/lib/llvm-*/lib/libclang*.so* >/dev/null 2>&1 && ! ldconfig -p | grep -q libclang; then \
		echo "installing libclang-dev (needed by bindgen)"; \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libclang-dev; \
	fi

$(VENV)/.installed: requirements.txt
	python3 -m venv $(VENV)
	$(VENV)/bin/pip install --quiet --disable-pip-version-check -r requirements.txt
	touch $@

fmus: setup
	$(CARGO) run --release -p fmu-build

demo: fmus
	MPLBACKEND=Agg $(PYTHON) tests/fmpy/demo.py

lint: setup
	$(CARGO) fmt --all -- --check
	$(CARGO) clippy --workspace --all-targets --features contour-fmu/test-hooks -- -D warnings

test: setup lint
	$(CARGO) test --workspace --features contour-fmu/test-hooks
	$(PYTHON) -m pytest -q tests/fmpy tests/reference

bench: setup
	$(CARGO) bench --bench fuzzy --bench controller
