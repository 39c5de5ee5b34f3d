#!/usr/bin/env bash
# Long run of every fuzz target, one after the other: RUNS executions each (default
# 10 000 000), or fewer if MAX_SECONDS (per target) runs out first. Prints executions,
# executions per second, coverage (cov: edges, ft: features) and the result per target;
# exits nonzero on any crash. Corpora grow in fuzz/corpus/ and are reused by later runs.
#
#   fuzz/long.sh [RUNS] [TARGET...]
#   MAX_SECONDS=3600 fuzz/long.sh 10000000 fmi_calls
set -euo pipefail
source "$(dirname "$0")/common.sh"
runs=${1:-10000000}
shift || true
[ $# -gt 0 ] && TARGETS=("$@")
build_targets
write_seeds
run_targets -runs="$runs" ${MAX_SECONDS:+-max_total_time=$MAX_SECONDS}
