"""contour-eval on a long five-axis run: this build against an earlier one, in the same run.

The workload (issue 43, item 4): a helix of 80 001 CL points (4 m of path, the tool leaning
20 ± 5° and turning with it) and the five-axis loop's own run along it through the FMUs
(`contour-cosim run five_axis.ssd`, feed 1.111 mm/s for 3600 s: 3.6 million samples of
X, Y, Z, A, C). Both are made once and kept in <target>/bench-data/contour_eval/.

Timed in turn, `--rounds` times each: this build (all cores), this build with
`--threads 1`, and the build of `--baseline-rev` (default: ea31c36, the commit before the
item; checked out with `git worktree` and built once into <target>/bench-data/). Every
run's error and reference files must be identical, byte for byte, to the baseline's.
Reports the medians and the ratios (target: this build <= 0.45x the baseline).

    .venv/bin/python benches/contour_eval_speed.py [--rounds 3] [--baseline-rev REV] [--json FILE]
"""

import argparse
import filecmp
import json
import math
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))

from baseline import checkout  # noqa: E402
from contour_fmu import repo  # noqa: E402

TARGET = Path(os.environ.get("CARGO_TARGET_DIR") or REPO / "target")
DATA = TARGET / "bench-data" / "contour_eval"
POINTS = 80_001
FEED = 1.111
DURATION = 3600.0
TARGET_RATIO = 0.45


def write_helix(path):
    """The CL reference: a 30 mm helix rising 10 mm over 4 m of path."""
    length, radius = 4000.0, 30.0
    turns = length / (2 * math.pi * radius)
    lines = ["PARTNO/HELIX BENCH", "UNITS/MM", "MULTAX"]
    for i in range(POINTS):
        s = i / (POINTS - 1)
        t = 2 * math.pi * turns * s
        lean = math.radians(20 + 5 * math.sin(3 * t))
        azimuth = t + math.pi
        axis = (math.sin(lean) * math.cos(azimuth), math.sin(lean) * math.sin(azimuth), math.cos(lean))
        lines.append(f"GOTO/{radius * math.cos(t):.5f},{radius * math.sin(t):.5f},{2.0 + 10.0 * s:.5f},"
                     f"{axis[0]:.7f},{axis[1]:.7f},{axis[2]:.7f}")
    path.write_text("\n".join(lines) + "\n")


def workload():
    """The CL file and the run's CSV (time,X,Y,Z,A,C), made when missing."""
    DATA.mkdir(parents=True, exist_ok=True)
    helix, run = DATA / "helix.cl", DATA / "run.csv"
    if not helix.exists():
        write_helix(helix)
    if not run.exists():
        raw = DATA / "run_raw.csv"
        joints = ",".join(f"plant.pos.{axis}" for axis in "XYZAC")
        subprocess.run([str(TARGET / "release" / "contour-cosim"), "run", str(TARGET / "fmu" / "five_axis.ssd"),
                        "--start", f"interpolator.path={helix}", "--start", f"interpolator.feed={FEED}",
                        "--stop", str(DURATION), "--step", "0.001", "--record", joints,
                        "--output", str(raw)], check=True)
        with raw.open() as source, (DATA / "run.partial").open("w") as out:
            source.readline()
            out.write("time,X,Y,Z,A,C\n")
            for chunk in iter(lambda: source.read(1 << 24), ""):
                out.write(chunk)
        raw.unlink()
        (DATA / "run.partial").rename(run)
    return helix, run


def baseline_binary(rev):
    """contour-eval as `rev` builds it (a worktree, built once), or None without git."""
    tree, target = DATA / f"baseline-{rev}", DATA / "baseline-target"
    binary = target / "release" / "contour-eval"
    stamp = DATA / f"baseline-{rev}.built"
    if stamp.exists() and binary.exists():
        return binary
    try:
        checkout(rev, DATA)
        subprocess.run(["cargo", "build", "--release", "-q", "-p", "contour-eval"], cwd=tree, check=True,
                       env={**os.environ, "CARGO_TARGET_DIR": str(target)})
    except (OSError, subprocess.CalledProcessError) as e:
        print(f"contour_eval_speed: no baseline build of {rev}: {e}", file=sys.stderr)
        return None
    stamp.write_text(rev)
    return binary


def evaluate(binary, helix, run, name, extra=()):
    """Seconds for one evaluation, its outputs kept as <name>.err.csv and <name>.ref.csv."""
    err, ref = DATA / f"{name}.err.csv", DATA / f"{name}.ref.csv"
    started = time.perf_counter()
    subprocess.run([str(binary), "--path", str(helix), "--measured", str(run), "--out", str(err),
                    "--out-reference", str(ref), *extra], check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - started, (err, ref)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--baseline-rev", default="ea31c36")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()

    helix, run = workload()
    samples = sum(1 for _ in run.open()) - 1
    ways = {"this build": (repo.contour_eval(), ()), "this build, --threads 1": (repo.contour_eval(), ("--threads", "1"))}
    baseline = baseline_binary(args.baseline_rev)
    if baseline is not None:
        ways = {f"baseline {args.baseline_rev}": (baseline, ()), **ways}
    times = {name: [] for name in ways}
    outputs = {}
    for _ in range(args.rounds):
        for k, (name, (binary, extra)) in enumerate(ways.items()):
            seconds, files = evaluate(binary, helix, run, f"way{k}", extra)
            times[name].append(seconds)
            outputs[name] = files
    first = next(iter(outputs.values()))
    identical = all(filecmp.cmp(a, b, shallow=False) for files in outputs.values() for a, b in zip(first, files))
    medians = {name: statistics.median(t) for name, t in times.items()}
    result = {"samples": samples, "reference_points": POINTS, "median_s": medians, "identical_outputs": identical,
              "cores": os.cpu_count()}
    print(f"contour-eval, {samples:,} five-axis samples against {POINTS:,} CL points, medians of {args.rounds}:")
    for name, s in medians.items():
        print(f"  {name:<32} {s:7.2f} s")
    if baseline is not None:
        key = f"baseline {args.baseline_rev}"
        result["baseline_rev"] = args.baseline_rev
        result["over_baseline"] = medians["this build"] / medians[key]
        result["one_thread_over_baseline"] = medians["this build, --threads 1"] / medians[key]
        verdict = "met" if result["over_baseline"] <= TARGET_RATIO else "MISSED"
        print(f"  this build / baseline: {result['over_baseline']:.3f}x (target <= {TARGET_RATIO}x: {verdict}); "
              f"one thread / baseline: {result['one_thread_over_baseline']:.3f}x")
    print(f"  outputs identical: {'yes' if identical else 'NO'}")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(result, indent=2))
    return 0 if identical else 1


if __name__ == "__main__":
    sys.exit(main())
