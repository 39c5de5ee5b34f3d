"""One page of the project's speed as ratios measured in the same `make bench` run.

Reads what the bench parts leave in <target>/bench-report/ (<target> is $CARGO_TARGET_DIR,
else target/): fmu_abi.json (benches/fmu_abi.rs), c_harness.json and
c_harness_callgrind.json (benches/c_harness/run.sh), fuzzy_vs_skfuzzy.json,
tuning_vs_pyswarms_fmu.json, pso_tables.json, native_throughput.json, campaign_scaling.json,
contour_eval_speed.json, restore_fuzz_speed.json and ccc_sample_cost.json (the Python
benches' --json), plus criterion's own estimates in <target>/criterion/. Prints the page and writes it to
<target>/bench-report/report.md. A figure that is missing, or older than the run's start
(a leftover of an earlier run), is shown as "not measured".

    .venv/bin/python benches/report.py --start   # before the benches: clears the folder
    .venv/bin/python benches/report.py           # after them: the page
"""

import argparse
import datetime
import json
import math
import os
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
TARGET = Path(os.environ.get("CARGO_TARGET_DIR") or REPO / "target")
REPORT = TARGET / "bench-report"
STAMP = REPORT / ".started"
NOT_MEASURED = "not measured"
# Issue 21: XYServoPlant through the C ABI at most this many times the bare C pass-through.
PLANT_OVER_BARE_TARGET = 2.0


def fresh(path):
    """Whether `path` exists and was written in this run (after the start stamp, if any)."""
    if not path.is_file():
        return False
    return not STAMP.exists() or path.stat().st_mtime >= STAMP.stat().st_mtime


def load(name):
    """A bench part's JSON from this run, or {}."""
    path = REPORT / name
    if not fresh(path):
        return {}
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return {}


def criterion(directory):
    """Criterion's median (s) per element (per iteration without a throughput) of the
    benchmark in <target>/criterion/<directory>, when this run measured it."""
    new = TARGET / "criterion" / directory / "new"
    if not fresh(new / "estimates.json"):
        return None
    try:
        median = json.loads((new / "estimates.json").read_text())["median"]["point_estimate"]
        throughput = json.loads((new / "benchmark.json").read_text()).get("throughput") or {}
    except (OSError, ValueError, KeyError):
        return None
    return median * 1e-9 / throughput.get("Elements", 1)


def dig(data, *keys):
    """data[k0][k1]…, or None when any is missing or not a finite number at the end."""
    for key in keys:
        if isinstance(data, dict) and key in data:
            data = data[key]
        elif isinstance(data, list) and isinstance(key, int) and -len(data) <= key < len(data):
            data = data[key]
        else:
            return None
    return data if isinstance(data, (int, float)) and math.isfinite(data) else None


def seconds(s):
    """A duration with a unit that keeps 3 significant digits readable."""
    if s is None:
        return "?"
    if s >= 1000:
        return f"{s:.0f} s"
    for unit, scale in (("s", 1), ("ms", 1e-3), ("µs", 1e-6)):
        if s >= scale:
            return f"{s / scale:.3g} {unit}"
    return f"{s * 1e9:.3g} ns"


def ratio(a, b):
    return a / b if a is not None and b not in (None, 0) else None


def line(label, value, detail="", fmt="{:.3g}x"):
    shown = fmt.format(value) if value is not None else NOT_MEASURED
    detail = f"  ({detail})" if detail and value is not None else ""
    return f"  {label:<44} {shown:>12}{detail}"


def page():
    abi = load("fmu_abi.json")
    fuzzy = load("fuzzy_vs_skfuzzy.json")
    tuning = load("tuning_vs_pyswarms_fmu.json")
    pso = load("pso_tables.json")
    campaign = load("campaign_scaling.json")
    throughput = load("native_throughput.json")
    harness = load("c_harness.json")
    evaluation = load("contour_eval_speed.json")
    instructions = load("c_harness_callgrind.json").get("instructions_per_sample") or {}
    med = lambda name: dig(abi, "median_s_per_sample", name)  # noqa: E731

    now = datetime.datetime.now(datetime.timezone.utc)
    lines = [f"# contour-fmu speed, {now:%Y-%m-%d %H:%M} UTC: ratios from one run of `make bench`", ""]
    if STAMP.exists():
        wall = time.time() - STAMP.stat().st_mtime
        lines.append(f"(benches ran {wall / 60:.1f} min on {os.cpu_count()} cores; "
                     "absolute times are this machine's, the ratios are the result)")
    else:
        lines.append("(no start stamp: the figures may come from different runs)")

    def paired(key):
        a, b = dig(abi, "paired", key, "a_s_per_sample"), dig(abi, "paired", key, "b_s_per_sample")
        return dig(abi, "paired", key, "ratio"), f"{seconds(a)} vs {seconds(b)} per sample"

    lines.append("\nController sample through the C ABI vs PassThrough (same calls, same value counts)")
    for label, key in (("ContourCCC2D sample / pass-through", "ccc_2d_over_pass_through"),
                       ("ContourCCC5X sample / pass-through", "ccc_5x_over_pass_through")):
        lines.append(line(label, *paired(key)))

    lines.append("\nA sample from a C importer (benches/c_harness: fmi2SetReal of all Real inputs, fmi2DoStep,")
    lines.append("fmi2GetReal of all Real outputs; dlopen'ed FMU binaries) / a bare C pass-through FMU;")
    lines.append("importer loop: the lagging circle's inputs computed each sample; calls only: precomputed")
    bare = harness.get("baseline", "bare")
    for model, target in (("XYServoPlant", PLANT_OVER_BARE_TARGET), ("ContourCCC2D", None)):
        for loop, name in (("importer_loop", "importer loop"), ("calls_only", "calls only")):
            ns = dig(harness, "models", model, loop, "median_ns_per_sample")
            bare_ns = dig(harness, "models", bare, loop, "median_ns_per_sample")
            r = dig(harness, "ratios_over_baseline", loop, model)
            verdict = ""
            if target is not None and loop == "importer_loop" and r is not None:
                verdict = f"; target <= {target:g}x: " + ("met" if r <= target else "MISSED")
            lines.append(line(f"{model} / bare, {name}", r,
                              f"{ns:.1f} vs {bare_ns:.1f} ns per sample{verdict}" if ns and bare_ns else ""))
    cost = load("ccc_sample_cost.json")
    base, goal = cost.get("baseline_rev", "the baseline"), cost.get("target_ratio", 8)
    after = dig(cost, "over_bare", "after", "importer_loop")
    detail = ""
    if after:
        detail = (f"{base}: {dig(cost, 'over_bare', 'before', 'importer_loop'):.2f}x; target <= {goal:g}x: "
                  + ("met" if after <= goal else "MISSED")
                  + f"; outputs identical: {'yes' if cost.get('identical_outputs') else 'NO'}")
    lines.append(line(f"ContourCCC2D / bare, importer loop, beside {base}", after, detail))
    lines.append(line(f"ContourCCC2D calls only, this build / {base}",
                      dig(cost, "calls_only_after_over_before"), "", "{:.3f}x"))
    lines.append(line("ContourCCC2D, program estimator / bare, importer loop",
                      dig(cost, "over_bare", "program", "importer_loop"),
                      f"calls {dig(cost, 'program_over_free_curve') or 0:.2f}x the free-curve estimator's"))
    counted = [f"{name} {int(count):,}" for name, count in instructions.items()
               if isinstance(count, (int, float))]
    lines.append("  instructions per sample, calls only (callgrind): "
                 + (", ".join(counted) if counted else NOT_MEASURED))

    lines.append("\nFuzzy inference (3 outputs), scikit-fuzzy / Rust, time per inference")
    rust = dig(fuzzy, "rust_s_per_eval")
    runs = fuzzy.get("skfuzzy") or [{}]
    for k, run in enumerate(runs):
        points = run.get("universe_points")
        sk, dev = dig(fuzzy, "skfuzzy", k, "s_per_eval"), dig(fuzzy, "skfuzzy", k, "max_abs_deviation")
        agreement = f"; max |Rust - skfuzzy| {dev:.2g}" if dev is not None else ""
        lines.append(line(f"universe of {points} points" if points else "scikit-fuzzy / Rust", ratio(sk, rust),
                          f"{seconds(sk)} vs {seconds(rust)}{agreement}", "{:,.0f}x"))

    lines.append("\nTuning: improved PSO (ccc-tune) vs pyswarms driving the FMUs through fmpy")
    full, evals = dig(tuning, "evaluations_full"), dig(tuning, "pyswarms_evaluations")
    lines.append(line("wall time, same evaluations, pyswarms / ours", dig(tuning, "wall_ratio"),
                      f"{full} evaluations: {seconds(dig(tuning, 'ccc_tune_full_s'))} vs "
                      f"{seconds(dig(tuning, 'pyswarms_scaled_s'))}, pyswarms timed on {evals} and scaled",
                      "{:,.0f}x"))
    ours_q, theirs_q = dig(tuning, "ccc_tune_small_best_mm"), dig(tuning, "pyswarms_best_mm")
    quality = (f"{evals} evaluations each: {ours_q * 1e3:.3g} vs {theirs_q * 1e3:.3g} µm, scored through fmpy"
               if ours_q and theirs_q else "")
    lines.append(line("best mean |contour error|, pyswarms / ours", dig(tuning, "quality_ratio"), quality,
                      "{:.3f}"))

    lines.append("\nContourCCC5X cost per sample, 100 k / 1 k path segments")
    lines.append(line("through the C ABI (fmu_abi)", *paired("path_100k_over_1k"), "{:.3f}"))
    p100k, p1k = criterion("five_axis/path_100k"), criterion("five_axis/path_1k")
    lines.append(line("in process (five_axis, criterion medians)", ratio(p100k, p1k), f"{seconds(p100k)} vs {seconds(p1k)}", "{:.3f}"))

    lines.append("\nCo-simulation through the FMUs, two-axis circle (2 001 samples, fuzzy CCC), runs/s on one core")
    rates = throughput.get("runs_per_s") or {}
    fmpy_rate = rates.get("fmpy_campaign")
    native_over = dig(throughput, "native_over_fmpy")
    lines.append(line("native master (contour-cosim) / campaign runner on fmpy", native_over,
                      (f"{rates.get('native', 0):.4g} vs {fmpy_rate:.3g} runs/s; target >= 30x: "
                       + ("met" if native_over >= 30 else "MISSED")) if native_over and fmpy_rate else "",
                      "{:.1f}x"))
    over_in_process = dig(throughput, "native_over_in_process")
    lines.append(line("time per run, native master / in-process simulator", over_in_process,
                      (f"in process {rates.get('in_process', 0):.4g} runs/s; target <= 2x: "
                       + ("met" if over_in_process <= 2 else "MISSED")) if over_in_process else "",
                      "{:.2f}x"))
    tune_ratio = dig(throughput, "tuning_fmus_over_in_process")
    same = throughput.get("tuning_same_optimum")
    lines.append(line("ccc-tune at the paper's budget, --loop / in process", tune_ratio,
                      (f"target <= 3x: " + ("met" if tune_ratio <= 3 else "MISSED")
                       + f"; same optimum: {'yes' if same else 'NO'}") if tune_ratio else "", "{:.2f}x"))
    lines.append(line("campaign batch, native engine / fmpy engine (each with its metrics)",
                      dig(throughput, "native_campaign_over_fmpy"),
                      f"{rates.get('native_campaign', 0):.4g} runs/s" if rates else "", "{:.1f}x"))
    batch_over = dig(throughput, "native_campaign_over_native")
    lines.append(line("campaign batch, native engine (metrics in contour-cosim) / native master",
                      batch_over, ("target >= 0.8x: " + ("met" if batch_over >= 0.8 else "MISSED"))
                      if batch_over else "", "{:.2f}x"))

    engine = campaign.get("engine", "fmpy")
    lines.append(f"\nCampaigns on a Dask LocalCluster ({engine} engine, two-axis circle runs, medians of paired rounds)")
    one, two = dig(campaign, "one_worker_runs_per_s"), dig(campaign, "two_workers_runs_per_s")
    scaling = dig(campaign, "scaling_two_over_one")
    lines.append(line("runs/s, 2 workers / 1 worker", scaling,
                      (f"{two:.4g} vs {one:.4g} runs/s; target >= 1.7x: " + ("met" if scaling >= 1.7 else "MISSED"))
                      if one and two and scaling else ""))
    overhead, plain = dig(campaign, "overhead_per_run_s"), dig(campaign, "plain_runs_per_s")
    lines.append(line("time per run, 1 worker / plain process",
                      None if dig(campaign, "overhead_fraction") is None else 1 + campaign["overhead_fraction"],
                      f"{seconds(overhead)} more per run; plain {plain:.4g} runs/s" if overhead and plain else "",
                      "{:.3f}"))
    million = campaign.get("million_runs") or {}
    if million:
        lines.append(f"  costs: {seconds(campaign['per_task_s'])} per task, {seconds(campaign['per_file_s'])} "
                     f"per row file, {seconds(campaign['per_row_s'])} per row; a 1 M-run campaign: "
                     f"{million['tasks']} tasks, {million['hours_2_local_workers']:.2f} h on 2 local workers, "
                     f"{million['hours_64_workers'] * 60:.1f} min on 64 workers")

    samples = evaluation.get("samples")
    lines.append(f"\ncontour-eval on a five-axis run ({samples:,} samples, {evaluation.get('reference_points', 0):,} CL points), "
                 "medians" if samples else "\ncontour-eval on a five-axis run")
    base = evaluation.get("baseline_rev", "the baseline")
    over = dig(evaluation, "over_baseline")
    same = evaluation.get("identical_outputs")
    lines.append(line(f"this build / {base}", over,
                      (f"{seconds(dig(evaluation, 'median_s', 'this build'))} vs "
                       f"{seconds(dig(evaluation, 'median_s', f'baseline {base}'))}; target <= 0.45x: "
                       + ("met" if over <= 0.45 else "MISSED")
                       + f"; outputs identical: {'yes' if same else 'NO'}") if over else "", "{:.3f}x"))
    lines.append(line(f"this build on one thread (--threads 1) / {base}", dig(evaluation, "one_thread_over_baseline"),
                      "", "{:.3f}x"))

    restoring = load("restore_fuzz_speed.json")
    base = restoring.get("baseline_rev", "the baseline")
    lines.append(f"\nFuzzing restored states (deserialize_state, {restoring.get('seconds', '?')} s from each "
                 "build's seeds, medians)")
    over = dig(restoring, "ratio")
    lines.append(line(f"executions a second, this build / {base}", over,
                      (f"{dig(restoring, 'exec_per_s', 'this build'):.0f} vs "
                       f"{dig(restoring, 'exec_per_s', base):.0f} exec/s; target >= 10x: "
                       + ("met" if over >= 10 else "MISSED")) if over else "", "{:.1f}x"))

    small = [("fuzzy eval", criterion("fuzzy_evaluate_three_outputs")),
             ("2-axis sample", criterion("controller_sample_fuzzy")),
             ("5-axis sample", criterion("five_axis/sample_fuzzy")),
             ("2 s closed loop in process", criterion("sim_paper_circle_2s_metrics_fuzzy")),
             ("FiveAxisPlant round through the ABI", med("five_axis_plant_round"))]
    lines.append("\nMedians (criterion, fuzzy mode; per sample, per evaluation or per run)")
    lines.append("  " + "; ".join(f"{name} {seconds(s) if s is not None else NOT_MEASURED}"
                                  for name, s in small[:3]))
    lines.append("  " + "; ".join(f"{name} {seconds(s) if s is not None else NOT_MEASURED}"
                                  for name, s in small[3:]))
    functions = pso.get("benchmarks") or {}
    shown = [f"{name} {ratio(dig(f, 'pyswarms'), dig(f, 'improved')):.3g}" for name, f in functions.items()
             if ratio(dig(f, "pyswarms"), dig(f, "improved")) is not None]
    lines.append("PSO on test functions (D = 5, 30 x 200), mean final fitness pyswarms / improved: "
                 + (", ".join(shown) if shown else NOT_MEASURED))
    claim = pso.get("claim") or {}
    if claim:
        wins = sum(c.get("wins", 0) for c in claim.values())
        seeds = sum(c.get("seeds", 0) for c in claim.values())
        lines.append(f"PSO claim at m = T = 20: improved beats standard PSO on {wins}/{seeds} seeds "
                     f"over {len(claim)} cases (per case in the pso_tables output)")
    else:
        lines.append(f"PSO claim at m = T = 20: {NOT_MEASURED}")
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--start", action="store_true",
                        help="start a run: clear the report folder and stamp the start time")
    args = parser.parse_args()
    if args.start:
        REPORT.mkdir(parents=True, exist_ok=True)
        for old in REPORT.iterdir():
            if old.is_file():
                old.unlink()
        STAMP.touch()
        return 0
    text = page()
    print(text, end="")
    try:
        REPORT.mkdir(parents=True, exist_ok=True)
        (REPORT / "report.md").write_text(text)
    except OSError as e:
        print(f"cannot write {REPORT / 'report.md'}: {e}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
