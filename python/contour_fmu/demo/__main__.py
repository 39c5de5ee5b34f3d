"""Demo: the command line of the demo, `python -m contour_fmu.demo` (also `contour-fmu
demo`): the paper's comparison (contour_fmu.demo.paper), then the part demo
(contour_fmu.demo.part: the G-code part examples/parts/bracket.ngc planned within
acceleration and jerk limits, without and with the CCC, on the part and on its mirror
image; a table, CSVs and out/part_bracket.png), the ballbar test of ISO 230-4 on the plant
with friction (contour_fmu.demo.ballbar: no CCC, CCC, CCC + feed-forward;
out/ballbar_*.png) and the five-axis demo (contour_fmu.demo.five_axis).

usage: python -m contour_fmu.demo [--fmu-dir DIR] [--out DIR]
                                  [--tune | --params tuned.json] [--ccc-tune PROGRAM]

--tune runs ccc-tune (improved and standard PSO, the paper's budget, fitness = max
|true contour error|) on each path; --params applies one ccc-tune result to every path.
The defaults are in the checkout <repo> (contour_fmu.repo: $CONTOUR_FMU_REPO, else the
working directory or a parent of it, else the checkout the package is installed from in
editable mode): <repo>/target/fmu, <repo>/out, <repo>/target/release/ccc-tune.

Needs the plots and reference extras (matplotlib; geomdl, scipy).
"""

import argparse
from pathlib import Path

from .. import repo
from . import ballbar, five_axis, paper, part

FMUS = ("PathInterpolator2D.fmu", "ContourCCC2D.fmu", "XYServoPlant.fmu",
        "PathInterpolator5X.fmu", "ContourCCC5X.fmu", "FiveAxisPlant.fmu")


def build_ccc_tune():
    """The cargo command that builds ccc-tune."""
    return f"cargo build --release -p {repo.TUNER_PACKAGE} --bin ccc-tune"


def parse_args(argv=None, prog="python -m contour_fmu.demo"):
    """The options, with the defaults resolved in the checkout (only those needed: with
    --fmu-dir and --out given, no checkout is needed unless --tune runs ccc-tune)."""
    parser = argparse.ArgumentParser(
        prog=prog, description="The paper's comparison of contour error with and without CCC, "
                                "through the FMUs, then the part, ballbar and five-axis demos.",
        epilog=f"<repo> is the checkout: ${repo.ENV}, else the working directory or a parent of "
               "it, else the checkout the package is installed from in editable mode; "
               "$CARGO_TARGET_DIR replaces <repo>/target.")
    parser.add_argument("--fmu-dir", type=Path, help="the FMUs (default: <repo>/target/fmu)")
    parser.add_argument("--out", type=Path, help="the output folder (default: <repo>/out)")
    choice = parser.add_mutually_exclusive_group()
    choice.add_argument("--tune", action="store_true", help="tune each path with ccc-tune")
    choice.add_argument("--params", type=Path, help="a ccc-tune JSON applied to every path")
    parser.add_argument("--ccc-tune", type=Path,
                        help="the tuner, for --tune (default: <repo>/target/release/ccc-tune)")
    args = parser.parse_args(argv)
    try:
        args.fmu_dir = args.fmu_dir or repo.fmu_dir()
        args.out = args.out or repo.out_dir()
        if args.tune:
            args.ccc_tune = args.ccc_tune or repo.ccc_tune()
    except repo.RepoNotFound as e:
        parser.error(str(e))
    missing = [name for name in FMUS if not (args.fmu_dir / name).is_file()]
    if missing:
        parser.error(f"no {', '.join(missing)} in {args.fmu_dir}: build the FMUs with "
                     "`cargo run --release -p fmu-build` (or `make fmus`), or give --fmu-dir")
    if args.tune and not args.ccc_tune.is_file():
        parser.error(f"no ccc-tune at {args.ccc_tune}: build it with `{build_ccc_tune()}` "
                     "or give --ccc-tune")
    if args.params and not args.params.is_file():
        parser.error(f"no parameter file {args.params}")
    if not repo.contour_eval().is_file():
        parser.error(f"no contour-eval at {repo.contour_eval()} (the ballbar test runs "
                     "it): build it with `cargo build --release -p contour-eval`")
    return args


def main(argv=None, prog="python -m contour_fmu.demo"):
    args = parse_args(argv, prog)
    args.out.mkdir(parents=True, exist_ok=True)
    rows = paper.paper_demo(args.fmu_dir, args.out, args.ccc_tune if args.tune else None,
                            args.params)
    paper.print_table(rows)
    print()
    program = part.default_program()
    if program is None:
        print(f"the part demo skipped: no checkout holds {part.PROGRAM.as_posix()}")
    else:
        part.print_table(part.part_demo(args.fmu_dir, args.out, program))
    print()
    ballbar.print_table(ballbar.ballbar_demo(args.fmu_dir, args.out))
    print()
    five_axis_rows = five_axis.main(args.fmu_dir, args.out)
    five_axis.print_table(five_axis_rows)
    print(f"wrote CSV, PNG and cross-check files to {args.out}")
    return rows


if __name__ == "__main__":
    main()
