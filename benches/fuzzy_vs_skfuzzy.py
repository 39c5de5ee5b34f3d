"""Per-evaluation cost of the Rust fuzzy engine versus scikit-fuzzy on the same system.

scikit-fuzzy: `ControlSystemSimulation.compute()` for one (E, EC) pair, all three
outputs, built exactly as in tests/reference/test_fuzzy_skfuzzy.py (same sets, rules,
min/max, centroid). Rust: `examples/fuzzy_timing.rs`, which times N evaluations of all
three outputs. Prints both and their ratio; the target is a ratio of at least 100.

Run from the repository root:
    .venv/bin/python benches/fuzzy_vs_skfuzzy.py \
        [--evals 100] [--points 20001 601]
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
from test_fuzzy_skfuzzy import build_simulation  # noqa: E402  (one definition of the system)


def skfuzzy_seconds_per_eval(points, evals, rng):
    sim = build_simulation(points)
    pairs = rng.uniform(-3.0, 3.0, size=(evals + 5, 2))
    for e, ec in pairs[:5]:  # warm-up
        sim.input["E"], sim.input["EC"] = e, ec
        sim.compute()
    start = time.perf_counter()
    for e, ec in pairs[5:]:
        sim.input["E"], sim.input["EC"] = e, ec
        sim.compute()
        sim.output["dkp"], sim.output["dki"], sim.output["dkd"]
    return (time.perf_counter() - start) / evals


def rust_seconds_per_eval(evals):
    cmd = ["cargo", "run", "--quiet", "--release", "--example", "fuzzy_timing", "--", str(evals)]
    out = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True, check=True).stdout
    return json.loads(out)["ns_per_eval"] * 1e-9


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
    args = parser.parse_args()

    rust = rust_seconds_per_eval(args.rust_evals)
    print(f"rust engine        : {rust * 1e9:10.1f} ns per evaluation (3 outputs)")
    rng = np.random.default_rng(1)
    worst = None
    for points in args.points:
        sk = skfuzzy_seconds_per_eval(points, args.evals, rng)
        ratio = sk / rust
        worst = ratio if worst is None else min(worst, ratio)
        print(
            f"scikit-fuzzy {points:>6}: {sk * 1e9:10.1f} ns per evaluation "
            f"-> rust is {ratio:,.0f}x faster"
        )
    verdict = "met" if worst >= 100 else "MISSED"
    print(f"target >= 100x: {verdict} (smallest ratio {worst:,.0f}x)")
    return 0 if worst >= 100 else 1


if __name__ == "__main__":
    sys.exit(main())
