"""The fuzz target that checks restored FMU states, `deserialize_state`: its executions a
second from the seeds, this build against an earlier one, in the same run (issue 43,
item 2: restores at full speed, target >= 10x the build before, 2874cbe).

Each build's target is built as fuzz/smoke.sh builds it (cargo fuzz, AddressSanitizer);
the earlier one from a worktree of `--baseline-rev`, once, into <target>/bench-data/.
Each writes its own seed states (a build reads its own layout) and then fuzzes from them
for `--seconds` on one core, with a fresh corpus, the two in turn for `--rounds` rounds.
Reported: executions a second and coverage (libFuzzer's cov) at the end of each run, their
medians and the ratio of the medians.

    .venv/bin/python benches/restore_fuzz_speed.py [--seconds 30] [--rounds 2] [--baseline-rev REV] [--json FILE]
"""

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from baseline import DATA, REPO, checkout

TARGET = "deserialize_state"
BINARY = Path("target") / "x86_64-unknown-linux-gnu" / "release" / TARGET
TARGET_RATIO = 10.0


def built(tree):
    """The fuzz target of the tree at `tree`, built (cargo fuzz, as fuzz/smoke.sh)."""
    subprocess.run(["cargo", "fuzz", "build", TARGET], cwd=tree / "fuzz", check=True,
                   env={**os.environ, "RUSTC_BOOTSTRAP": "1"})
    return tree / "fuzz" / BINARY


def fuzz(binary, seconds, scratch):
    """(executions a second, coverage) of `seconds` of fuzzing from the build's own seeds."""
    seeds, corpus = Path(scratch) / "seeds", Path(scratch) / "corpus"
    for folder in (seeds, corpus):
        folder.mkdir(parents=True, exist_ok=True)
    subprocess.run([str(binary)], env={**os.environ, "CONTOUR_FUZZ_SEEDS": str(seeds)},
                   check=True, capture_output=True)
    done = subprocess.run([str(binary), str(corpus), str(seeds), f"-max_total_time={seconds}",
                           "-print_final_stats=1", "-timeout=10", "-rss_limit_mb=2048"],
                          env={**os.environ, "ASAN_OPTIONS": "detect_odr_violation=0"},
                          capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{binary} found something: {done.stderr[-2000:]}")
    speed = int(re.search(r"stat::average_exec_per_sec:\s*(\d+)", done.stderr).group(1))
    coverage = int(re.findall(r"cov: (\d+)", done.stderr)[-1])
    return speed, coverage


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=int, default=30)
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--baseline-rev", default="2874cbe")
    parser.add_argument("--json", type=Path, help="write the figures to this file")
    args = parser.parse_args()
    binaries = {"this build": built(REPO),
                args.baseline_rev: built(checkout(args.baseline_rev, DATA / "restore_fuzz"))}
    runs = {name: [] for name in binaries}
    with tempfile.TemporaryDirectory() as scratch:
        for r in range(args.rounds):
            for name, binary in binaries.items():
                runs[name].append(fuzz(binary, args.seconds, Path(scratch) / f"round{r}" / name.replace(" ", "-")))
    median = {name: statistics.median(s for s, _ in found) for name, found in runs.items()}
    ratio = median["this build"] / median[args.baseline_rev]
    print(f"{TARGET}, {args.seconds} s from each build's seeds, {args.rounds} rounds, medians:")
    for name, found in runs.items():
        print(f"  {name:12s} {median[name]:8.0f} executions/s  (rounds: "
              + ", ".join(f"{s} exec/s, cov {c}" for s, c in found) + ")")
    print(f"  this build / {args.baseline_rev}: {ratio:.1f}x (target >= {TARGET_RATIO:g})")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps({
            "target": TARGET, "seconds": args.seconds, "baseline_rev": args.baseline_rev,
            "runs": {name: [{"exec_per_s": s, "coverage": c} for s, c in found] for name, found in runs.items()},
            "exec_per_s": median, "ratio": ratio, "target_ratio": TARGET_RATIO}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
