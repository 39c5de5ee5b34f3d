#!/usr/bin/env bash
# Smoke run of every fuzz target: build (release, debug assertions, AddressSanitizer),
# then SECONDS (default 30) of fuzzing each. Exits nonzero on any crash, leak, timeout or
# out-of-memory; the input that caused it is in fuzz/artifacts/<target>/.
#
#   fuzz/smoke.sh [SECONDS]
set -euo pipefail
source "$(dirname "$0")/common.sh"
seconds=${1:-30}
build_targets
write_seeds
run_targets -max_total_time="$seconds"
