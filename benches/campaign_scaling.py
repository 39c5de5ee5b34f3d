"""Campaign throughput: runs per second on a LocalCluster of 1 and of 2 workers, their
ratio, and the cost per run of the campaign machinery (Dask tasks, batching, Parquet
rows) against the same runs as one batch in a plain process (one set of instances, reset
between runs, no Dask, nothing written); with the per-task, per-row and per-file costs
this gives, what a campaign of a million runs costs (docs/campaigns.md).

The campaign: the two-axis loop on the paper's circle to the end of the path (2 s, 2 000
steps), RUNS plants from a grid of x.J and y.Kvp, true contour error max and mean, on the
native engine with batches sized by work (the defaults), or on fmpy with 4 runs per
batch. Every part is warmed first (files written, the circle's reference built in each
process), so the figures are steady-state rates; starting the cluster is reported apart.
The machine's speed drifts (shared cores), so each round times the three one after the
other, and the ratios are the medians of the rounds' ratios.

    .venv/bin/python benches/campaign_scaling.py [--engine native] [--runs N] [--rounds 7] [--json FILE]
"""

import argparse
import contextlib
import json
import math
import multiprocessing
import statistics
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))

from contour_fmu import repo  # noqa: E402
from contour_fmu.campaign import load  # noqa: E402
from contour_fmu.campaign.execute import (TASK_SECONDS, archives_of, dask_client,  # noqa: E402
                                          engine_batch, job_of, run_on_dask)
from contour_fmu.campaign.store import ResultStore  # noqa: E402

CAMPAIGN = """
name = "bench"
loop = "two_axis"
stop = "end_of_path"
metrics = ["contour_error.max", "contour_error.mean"]
engine = "{engine}"
batch_size = {batch_size}
[fmus]
directory = "{fmus}"
[[paths]]
path = "circle"
feed = 31.41592653589793
[sweep]
method = "grid"
[sweep.parameters]
"plant.x.J" = {{ factors = {j} }}
"plant.y.Kvp" = {{ factors = [0.9, 1.1] }}
"""


def campaign(directory, runs, engine):
    levels = [round(0.8 + 0.4 * k / max(runs // 2 - 1, 1), 9) for k in range(runs // 2)]
    path = Path(directory) / f"bench{runs}.toml"
    path.write_text(CAMPAIGN.format(fmus=repo.fmu_dir(), j=levels, engine=engine,
                                    batch_size='"auto"' if engine == "native" else 4))
    return load(path)


_plain = {}


def plain_setup(path):
    """In the plain process: the campaign, its files, warmed by one run."""
    c = load(path)
    job, archives = job_of(c), archives_of(c)
    runs = [(r.id, r.start_values) for r in c.runs]
    engine_batch(job)(job, runs[:1], archives)  # warm: files, the reference path
    _plain.update(job=job, archives=archives, runs=runs)


def plain_loop():
    """Seconds for every run in the plain process as one batch: one set of instances,
    reset between runs, no Dask, nothing written."""
    job, archives, runs = _plain["job"], _plain["archives"], _plain["runs"]
    began = time.perf_counter()
    engine_batch(job)(job, runs, archives)
    return time.perf_counter() - began


def on_cluster(c, client, directory, cpu=None, tasks=None):
    """Seconds for the campaign's runs on `client`'s workers (rows written as usual);
    adds this process's CPU seconds (client, scheduler, Parquet) to `cpu` and the number
    of tasks to `tasks`."""
    began, used = time.perf_counter(), time.process_time()
    store = ResultStore(directory, c)
    submitted = run_on_dask(c, store, client)
    store.close()
    if cpu is not None:
        cpu.append(time.process_time() - used)
    if tasks is not None:
        tasks.append(submitted)
    return time.perf_counter() - began


def store_costs(c, directory, files=40, rows=500):
    """(seconds per row file, seconds per row) of the client's ResultStore.write, merges
    included: `files` files of one row, then `files` of `rows` rows."""
    metrics = {m: 0.5 for m in c.metrics}
    row = lambda i: {"run_id": i % len(c.runs), "status": "ok", "message": "", "attempts": 1,  # noqa: E731
                     "wall_time_s": 0.01, "worker": "host:1", **metrics}
    spent = []
    for size, name in ((1, "one"), (rows, "many")):
        store = ResultStore(Path(directory) / f"store-{name}", c)
        began = time.perf_counter()
        for f in range(files):
            store.write([row(f * size + i) for i in range(size)])
        spent.append((time.perf_counter() - began) / files)
        store.close()
    per_file = spent[0]
    return per_file, max(spent[1] - per_file, 0.0) / rows


def million(per_run, per_task, per_file, per_row, scaling, workers=(2, 64)):
    """Projected hours of a 1 M-run campaign: work and tasks spread over the workers
    (2 local ones at the measured scaling; a cluster at perfect scaling), rows and files
    written by the client in one process, which bounds the cluster from below."""
    runs = 1_000_000
    tasks = math.ceil(runs * per_run / TASK_SECONDS)
    work = runs * per_run + tasks * per_task
    files = tasks  # one row file per task before merging
    client = files * per_file + runs * per_row
    local = work / scaling
    cluster = max(work / workers[1], client)
    return {"tasks": tasks, "work_s": work, "client_s": client,
            f"hours_{workers[0]}_local_workers": local / 3600,
            f"hours_{workers[1]}_workers": cluster / 3600}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--engine", choices=("native", "fmpy"), default="native")
    parser.add_argument("--runs", type=int, help="runs per round, even (default: native 2000, fmpy 48)")
    parser.add_argument("--rounds", type=int, default=7,
                        help="rounds; each times the plain loop, 1 worker and 2 workers in turn")
    parser.add_argument("--json", type=Path, help="write the figures to this file")
    args = parser.parse_args()
    args.runs = args.runs or (2000 if args.engine == "native" else 48)
    times = {"plain": [], "one": [], "two": []}
    client_cpu, tasks = [], []
    with tempfile.TemporaryDirectory() as directory, contextlib.ExitStack() as stack:
        c, warm = campaign(directory, args.runs, args.engine), campaign(directory, 4, args.engine)
        # The plain loop runs in a process of its own: this one hosts the schedulers.
        plain = stack.enter_context(ProcessPoolExecutor(
            1, mp_context=multiprocessing.get_context("spawn"), initializer=plain_setup,
            initargs=(c.source,)))
        plain.submit(time.sleep, 0).result()
        clients, starts = {}, {}
        for name, workers in (("one", 1), ("two", 2)):
            began = time.perf_counter()
            clients[name] = stack.enter_context(dask_client(workers=workers))
            starts[name] = time.perf_counter() - began
            on_cluster(warm, clients[name], Path(directory) / f"warm-{name}")
        for r in range(args.rounds):
            times["plain"].append(plain.submit(plain_loop).result())
            for name in ("one", "two"):
                times[name].append(on_cluster(c, clients[name], Path(directory) / f"{name}-{r}",
                                              client_cpu if name == "two" else None,
                                              tasks if name == "one" else None))
        per_file, per_row = store_costs(c, directory)
    n = len(c.runs)
    median = {k: statistics.median(v) for k, v in times.items()}
    # Ratios per round (the three ran within seconds of each other), then their median.
    scaling = statistics.median(o / t for o, t in zip(times["one"], times["two"]))
    overhead = statistics.median((o - p) / p for o, p in zip(times["one"], times["plain"]))
    figures = {
        "runs_per_round": n, "rounds": args.rounds, "steps_per_run": 2000,
        "plain_runs_per_s": n / median["plain"], "one_worker_runs_per_s": n / median["one"],
        "two_workers_runs_per_s": n / median["two"],
        "scaling_two_over_one": scaling, "overhead_fraction": overhead,
        "overhead_per_run_s": overhead * median["plain"] / n,
        "cluster_start_s": [starts["one"], starts["two"]], "seconds": times,
        "client_cpu_fraction_two_workers": statistics.median(
            u / t for u, t in zip(client_cpu, times["two"])),
        "engine": args.engine, "tasks_per_round_one_worker": tasks,
        "per_task_s": statistics.median((o - p) / k for o, p, k in zip(times["one"], times["plain"], tasks)),
        "per_file_s": per_file, "per_row_s": per_row,
    }
    figures["million_runs"] = million(median["plain"] / n, max(figures["per_task_s"], 0.0), per_file,
                                      per_row, scaling)
    batching = "batches sized by work" if args.engine == "native" else "4 runs per batch"
    print(f"{args.rounds} rounds of {n} runs of the two-axis loop on the circle (2 000 steps each), "
          f"{args.engine} engine, {batching}; medians")
    print(f"  plain process, one batch {figures['plain_runs_per_s']:6.2f} runs/s")
    print(f"  LocalCluster, 1 worker   {figures['one_worker_runs_per_s']:6.2f} runs/s")
    print(f"  LocalCluster, 2 workers  {figures['two_workers_runs_per_s']:6.2f} runs/s")
    print(f"  scaling 2 / 1 workers    {scaling:6.2f}x  (per round: "
          + ", ".join(f"{o / t:.2f}" for o, t in zip(times["one"], times["two"])) + ")")
    print(f"  overhead per run, 1 worker vs plain loop: {figures['overhead_per_run_s'] * 1e3:.1f} ms "
          f"({100 * overhead:.1f} %)")
    print(f"  CPU of the client process (scheduler, client, Parquet) with 2 workers: "
          f"{100 * figures['client_cpu_fraction_two_workers']:.1f} % of one core")
    print(f"  cluster start (not in the rates): {starts['one']:.1f} s and {starts['two']:.1f} s")
    m = figures["million_runs"]
    print(f"  costs: {figures['per_task_s'] * 1e3:.1f} ms per task ({statistics.median(tasks)} tasks a round), "
          f"{per_file * 1e3:.1f} ms per row file, {per_row * 1e6:.1f} µs per row")
    print(f"  1 M runs: {m['tasks']} tasks; {m['hours_2_local_workers']:.2f} h on 2 local workers, "
          f"{m['hours_64_workers']:.3f} h on 64 workers (client's writing alone {m['client_s'] / 3600:.3f} h)")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(figures, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
