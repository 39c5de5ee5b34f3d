"""What a ContourCCC2D sample costs a C importer, this build against an earlier one, in the
same run, with identical outputs (issue 43, item 3: <= 8x the bare C pass-through).

The earlier build's FMUs are made once from a worktree of `--baseline-rev` (6298f9b, the
commit before item 3's work) into <target>/bench-data/. benches/c_harness/harness then
times the bare C pass-through, the earlier ContourCCC2D and this build's in one run
(passes alternate between them), and dumps every output of both ContourCCC2D builds over
the same samples: the workload is the same only if the dumps are equal byte for byte.
Beside them, this build's ContourCCC2D with the `program` estimator, along a G-code program
of as many full circles as the run's lagging circle makes (G3 about the origin, 10 mm).

    .venv/bin/python benches/ccc_sample_cost.py [--passes 101] [--baseline-rev REV] [--json FILE]
"""

import argparse
import filecmp
import json
import os
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

from baseline import DATA, REPO, checkout

TARGET_DIR = Path(os.environ.get("CARGO_TARGET_DIR") or REPO / "target")
MODEL = "ContourCCC2D"
TARGET_RATIO = 8.0


def fmu_of(tree, target_dir):
    """The ContourCCC2D FMU the tree at `tree` packages (built if missing)."""
    fmu = target_dir / "fmu" / f"{MODEL}.fmu"
    if not fmu.exists():
        subprocess.run(["cargo", "run", "--release", "-p", "fmu-build"], cwd=tree, check=True,
                       env={**os.environ, "CARGO_TARGET_DIR": str(target_dir)})
    return fmu


def unpacked(fmu, folder):
    """`LIBRARY:MODEL_DESCRIPTION` of `fmu` unpacked into `folder`."""
    with zipfile.ZipFile(fmu) as archive:
        archive.extractall(folder)
    return f"{folder}/binaries/linux64/{MODEL}.so:{folder}/modelDescription.xml"


def circles_program(folder, passes):
    """A G-code program of enough full circles for `passes` (after 3 warm-up passes, both
    loops) of 4000 samples: the harness's lagging circle turns once every 2000 samples."""
    turns = 2 * 2 * (passes + 3) + 10
    program = Path(folder) / "circles.ngc"
    program.write_text("\n".join(["G21 G17 G90", "G0 X10 Y0", *["G3 X10 Y0 I-10 J0 F600"] * turns,
                                  "M2"]) + "\n")
    return program


def harness(*args):
    done = subprocess.run([str(TARGET_DIR / "c_harness" / "harness"), *args], check=True,
                          capture_output=True, text=True)
    return done.stdout


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--passes", type=int, default=101)
    parser.add_argument("--baseline-rev", default="6298f9b")
    parser.add_argument("--json", type=Path, help="write the figures to this file")
    args = parser.parse_args()
    tree = checkout(args.baseline_rev, DATA / "ccc_sample_cost")
    before_fmu = fmu_of(tree, tree / "target")
    after_fmu = fmu_of(REPO, TARGET_DIR)
    # Builds the harness and the bare pass-through (a one-sample run).
    subprocess.run([str(REPO / "benches" / "c_harness" / "run.sh"), "--samples", "1", "--passes", "1",
                    "--warmup", "0"], check=True, capture_output=True)
    bare = (f"{TARGET_DIR}/c_harness/PassThroughC.so:"
            f"{REPO}/benches/c_harness/PassThroughC.xml")
    with tempfile.TemporaryDirectory() as scratch:
        specs = {"bare": bare,
                 "before": unpacked(before_fmu, f"{scratch}/before"),
                 "after": unpacked(after_fmu, f"{scratch}/after")}
        dumps = {}
        for label in ("before", "after"):
            dumps[label] = f"{scratch}/{label}.bin"
            harness("--samples", "4000", "--passes", "5", "--warmup", "1", "--only", label,
                    "--dump", dumps[label], f"{label}={specs[label]}")
        identical = filecmp.cmp(dumps["before"], dumps["after"], shallow=False)
        specs["program"] = specs["after"]
        program = circles_program(scratch, args.passes)
        report = f"{scratch}/timing.json"
        print(harness("--passes", str(args.passes), "--json", report,
                      "--set", "program:estimator=4", "--set", f"program:path={program}",
                      *(f"{label}={spec}" for label, spec in specs.items())), end="")
        timing = json.loads(Path(report).read_text())
    ns = {label: {loop: timing["models"][label][loop]["median_ns_per_sample"]
                  for loop in ("calls_only", "importer_loop")} for label in specs}
    over_bare = {label: {loop: timing["ratios_over_baseline"][loop][label]
                         for loop in ("calls_only", "importer_loop")} for label in ("before", "after", "program")}
    after_over_before = ns["after"]["calls_only"] / ns["before"]["calls_only"]
    met = over_bare["after"]["importer_loop"] <= TARGET_RATIO
    print(f"{MODEL} / bare, importer loop: {args.baseline_rev} {over_bare['before']['importer_loop']:.2f}x, "
          f"this build {over_bare['after']['importer_loop']:.2f}x (target <= {TARGET_RATIO:g}x: "
          f"{'met' if met else 'MISSED'}); calls only, this build / {args.baseline_rev}: "
          f"{after_over_before:.3f}x; outputs identical: {'yes' if identical else 'NO'}")
    program_over_free = ns["program"]["calls_only"] / ns["after"]["calls_only"]
    print(f"  program estimator: importer loop {over_bare['program']['importer_loop']:.2f}x the bare "
          f"pass-through, calls {program_over_free:.2f}x the free-curve estimator's")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps({
            "baseline_rev": args.baseline_rev, "passes": args.passes, "median_ns_per_sample": ns,
            "over_bare": over_bare, "calls_only_after_over_before": after_over_before,
            "identical_outputs": identical, "program_over_free_curve": program_over_free,
            "target_ratio": TARGET_RATIO}, indent=1) + "\n")
    return 0 if identical else 1


if __name__ == "__main__":
    sys.exit(main())
