"""Runs per second on one core of the two-axis circle (2 s, 2 001 samples, fuzzy CCC), four
ways, timed in turn in each round:

- the in-process simulator (`examples/closed_loop_timing`: the Rust loop, no FMUs);
- the native master (`contour-cosim batch`: the FMUs through the C ABI, instances reset
  between runs, the campaign's columns recorded; its start, unpacking and loading the
  FMUs, reported apart);
- a campaign batch on the native engine (the same, the metrics measured by contour-cosim,
  a row per run back to Python);
- a campaign batch on fmpy (contour_fmu.campaign.runner, the FMUs from Python, the metrics
  in Python).

Targets (issue 25): native ≥ 30× fmpy, and within 2× of in-process; (issue 43) the native
campaign batch ≥ 0.8× the native master's runs per second. The ratios are the
medians of the rounds' ratios (the machine's speed drifts; each round times the four
within seconds). Then `ccc-tune` at the paper's budget (50 × 100 circle runs, both cores)
in process and with every candidate through the FMUs (`--loop`), twice each in turn
(target: ≤ 3×), and whether both found the same optimum.

    .venv/bin/python benches/native_throughput.py [--rounds 5] [--json FILE]
"""

import argparse
import json
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))

from contour_fmu import repo  # noqa: E402
from contour_fmu.engines import native  # noqa: E402
from contour_fmu.campaign import load  # noqa: E402
from contour_fmu.campaign.execute import archives_of, job_of  # noqa: E402
from contour_fmu.campaign.native_batch import run_batch as native_batch  # noqa: E402
from contour_fmu.campaign.runner import run_batch as fmpy_batch  # noqa: E402

CAMPAIGN = """
name = "throughput"
loop = "two_axis"
stop = 2.0
engine = "{engine}"
metrics = ["contour_error.max", "contour_error.mean"]
[fmus]
directory = "{fmus}"
[[paths]]
path = "circle"
feed = 31.41592653589793
[sweep]
method = "grid"
[sweep.parameters]
"plant.x.J" = {{ factors = {factors} }}
"""

# Runs per round: each way takes about a second (the two native ways, compared with each
# other, as many runs each).
RUNS = {"in_process": 400, "native": 500, "native_campaign": 500, "fmpy_campaign": 8}


def in_process(runs):
    """Seconds per run of the in-process simulator, circle, fuzzy CCC."""
    done = subprocess.run([str(repo.target_dir() / "release" / "examples" / "closed_loop_timing"),
                           str(runs)], capture_output=True, text=True, check=True)
    found = re.search(r"circle\s+Fuzzy\s+([\d.]+) µs per run", done.stdout)
    return float(found.group(1)) * 1e-6


def native_master(directory, runs):
    """(seconds per run, seconds to start) of `contour-cosim batch`: a process of one run
    and one of `runs` runs; the difference is the runs' steady cost (a campaign's child
    stays up for the worker's batches, so it starts once per worker)."""
    record = "controller.u.x,controller.u.y,controller.contourError,controller.ccc.Kp," \
             "plant.pos.x,plant.pos.y,interpolator.ref.x,interpolator.ref.y"
    spent = []
    for count in (1, runs):
        lines = Path(directory) / f"runs{count}.jsonl"
        lines.write_text("".join(json.dumps({"run": k, "start": [["interpolator", "path", "circle"]]}) + "\n"
                                 for k in range(count)))
        began = time.perf_counter()
        subprocess.run([str(native.program()), "batch", str(repo.fmu_dir() / "two_axis.ssd"), "--stop", "2",
                        "--record", record, "--runs", str(lines)], stdout=subprocess.DEVNULL, check=True)
        spent.append(time.perf_counter() - began)
    per_run = (spent[1] - spent[0]) / (runs - 1)
    return per_run, spent[0] - per_run


def campaign_batch(directory, engine, runs):
    """Seconds per run of one campaign batch in this process (metrics included)."""
    factors = [round(0.8 + 0.4 * k / max(runs - 1, 1), 9) for k in range(runs)]
    file = Path(directory) / f"{engine}.toml"
    file.write_text(CAMPAIGN.format(engine=engine, fmus=repo.fmu_dir(), factors=factors))
    c = load(file)
    job, archives = job_of(c), archives_of(c)
    batch = [(r.id, r.start_values) for r in c.runs]
    run = native_batch if engine == "native" else fmpy_batch
    run(job, batch[:1], archives)  # warm: files written or extracted, the reference path built
    began = time.perf_counter()
    rows = run(job, batch, archives)
    assert all(r["status"] == "ok" for r in rows), rows[:1]
    return (time.perf_counter() - began) / runs


def tuning(directory):
    """(seconds in process, seconds through the FMUs, same optimum) of ccc-tune at the
    paper's budget."""
    spent, found = {}, {}
    for name, extra in (("in_process", []), ("fmus", ["--loop", str(repo.fmu_dir() / "two_axis.ssd")])):
        out = Path(directory) / f"tuned-{name}.json"
        began = time.perf_counter()
        subprocess.run([str(repo.ccc_tune()), "--out", str(out), *extra], check=True,
                       capture_output=True)
        spent[name] = time.perf_counter() - began
        found[name] = json.loads(out.read_text())
    same = all(found["fmus"][k] == found["in_process"][k] for k in ("factors", "fitness_mm", "history_mm"))
    return spent["in_process"], spent["fmus"], same


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--json", type=Path, help="write the figures to this file")
    args = parser.parse_args()
    times = {name: [] for name in RUNS}
    starts = []
    with tempfile.TemporaryDirectory() as directory:
        for _ in range(args.rounds):
            times["in_process"].append(in_process(RUNS["in_process"]))
            per_run, start = native_master(directory, RUNS["native"])
            times["native"].append(per_run)
            starts.append(start)
            times["native_campaign"].append(campaign_batch(directory, "native", RUNS["native_campaign"]))
            times["fmpy_campaign"].append(campaign_batch(directory, "fmpy", RUNS["fmpy_campaign"]))
        tunes = [tuning(directory) for _ in range(2)]
    per_round = lambda a, b: statistics.median(x / y for x, y in zip(times[a], times[b]))  # noqa: E731
    figures = {
        "rounds": args.rounds, "runs_per_round": RUNS, "seconds_per_run": times,
        "runs_per_s": {k: 1 / statistics.median(v) for k, v in times.items()},
        "native_over_fmpy": per_round("fmpy_campaign", "native"),
        "native_campaign_over_fmpy": per_round("fmpy_campaign", "native_campaign"),
        "native_campaign_over_native": per_round("native", "native_campaign"),
        "native_over_in_process": per_round("native", "in_process"),
        "native_start_s": statistics.median(starts),
        "tuning_s": {"in_process": [t[0] for t in tunes], "fmus": [t[1] for t in tunes]},
        "tuning_fmus_over_in_process": statistics.median(t[1] / t[0] for t in tunes),
        "tuning_same_optimum": all(t[2] for t in tunes),
    }
    rate = figures["runs_per_s"]
    print(f"two-axis circle, 2 001 samples, fuzzy CCC; runs/s on one core, medians of {args.rounds} rounds")
    for name, label in (("in_process", "in-process simulator"), ("native", "native master (contour-cosim)"),
                        ("native_campaign", "campaign batch, native engine"),
                        ("fmpy_campaign", "campaign batch, fmpy engine")):
        print(f"  {label:32s} {rate[name]:8.1f} runs/s")
    print(f"  native / fmpy campaign       {figures['native_over_fmpy']:6.1f}x (target >= 30)")
    print(f"  native campaign / fmpy        {figures['native_campaign_over_fmpy']:6.1f}x")
    print(f"  native campaign / native master {figures['native_campaign_over_native']:6.2f}x (target >= 0.8)")
    print(f"  native time / in-process time {figures['native_over_in_process']:6.2f}x (target <= 2)")
    print(f"  contour-cosim's start (unpack and load three FMUs; once per campaign worker): "
          f"{figures['native_start_s'] * 1e3:.0f} ms")
    print(f"  ccc-tune, paper's budget, through the FMUs / in process: "
          f"{figures['tuning_fmus_over_in_process']:.2f}x (target <= 3; "
          + ", ".join(f"{f:.1f} s vs {i:.1f} s" for i, f, _ in tunes)
          + f"); same optimum: {figures['tuning_same_optimum']}")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(figures, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
