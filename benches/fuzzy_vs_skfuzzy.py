"""Per-evaluation cost of the Rust fuzzy engine versus scikit-fuzzy on the same system.

scikit-fuzzy: `ControlSystemSimulation.compute()` for one (E, EC) pair, all three
outputs, built exactly as in tests/reference/test_fuzzy_skfuzzy.py (same sets, rules,
min/max, centroid). Rust: `examples/fuzzy_timing.rs`, which times N evaluations of all
three outputs. Prints both and their ratio; the target is a ratio of at least 100.
The timed scikit-fuzzy points are drawn from the 61 x 61 grid of examples/fuzzy_dump.rs,
so the same run also gives the largest |Rust - scikit-fuzzy| over them (the agreement).

Run from the repository root:
    .venv/bin/python benches/fuzzy_vs_skfuzzy.py \
        [--evals 100] [--points 20001 601] [--json FILE]
"""

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests" / "reference"))
from test_fuzzy_skfuzzy import GRID, OUTPUTS, build_simulation  # noqa: E402  (one definition of the system)


def cargo_example(name, *args):
    cmd = ["cargo", "run", "--quiet", "--release", "--example", name, "--", *map(str, args)]
    out = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True, check=True).stdout
    return json.loads(out)


def skfuzzy_seconds_per_eval(points, evals, rng, rust):
    """Seconds per scikit-fuzzy evaluation on `evals` grid points, and the largest
    |Rust - scikit-fuzzy| over them (any output)."""
    grid = np.asarray(rust["grid"])
    sim = build_simulation(points)
    idx = rng.integers(0, len(grid), size=(evals + 5, 2))
    for i, j in idx[:5]:  # warm-up
        sim.input["E"], sim.input["EC"] = grid[i], grid[j]
        sim.compute()
    outputs = np.empty((evals, len(OUTPUTS)))
    start = time.perf_counter()
    for k, (i, j) in enumerate(idx[5:]):
        sim.input["E"], sim.input["EC"] = grid[i], grid[j]
        sim.compute()
        outputs[k] = [sim.output[name] for name in OUTPUTS]
    seconds = (time.perf_counter() - start) / evals
    ours = np.column_stack([np.asarray(rust[name])[idx[5:, 0], idx[5:, 1]] for name in OUTPUTS])
    return seconds, float(np.abs(ours - outputs).max())


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--evals", type=int, default=100, help="scikit-fuzzy evaluations")
    parser.add_argument("--rust-evals", type=int, default=5_000_000)
    parser.add_argument(
        "--points",
        type=int,
        nargs="+",
        default=[20001, 601],
        help="scikit-fuzzy universe sizes (20001 = the accuracy test, 601 = a coarse one)",
    )
    parser.add_argument("--json", type=Path, help="also write the figures to this file")
    args = parser.parse_args()

    rust = cargo_example("fuzzy_timing", args.rust_evals)["ns_per_eval"] * 1e-9
    grid = cargo_example("fuzzy_dump", GRID)
    print(f"rust engine        : {rust * 1e9:10.1f} ns per evaluation (3 outputs)")
    rng = np.random.default_rng(1)
    worst = None
    figures = {"rust_s_per_eval": rust, "evals": args.evals, "skfuzzy": []}
    for points in args.points:
        sk, deviation = skfuzzy_seconds_per_eval(points, args.evals, rng, grid)
        ratio = sk / rust
        worst = ratio if worst is None else min(worst, ratio)
        figures["skfuzzy"].append({"universe_points": points, "s_per_eval": sk, "ratio": ratio,
                                   "max_abs_deviation": deviation})
        print(
            f"scikit-fuzzy {points:>6}: {sk * 1e9:10.1f} ns per evaluation "
            f"-> rust is {ratio:,.0f}x faster; max |rust - skfuzzy| {deviation:.2g}"
        )
    verdict = "met" if worst >= 100 else "MISSED"
    print(f"target >= 100x: {verdict} (smallest ratio {worst:,.0f}x)")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(figures, indent=2) + "\n")
    return 0 if worst >= 100 else 1


if __name__ == "__main__":
    sys.exit(main())
