"""Campaign throughput: runs per second on a LocalCluster of 1 and of 2 workers, their
ratio, and the cost per run of the campaign machinery (Dask tasks, batching, Parquet
rows) against the same runs in a plain Python loop (one set of instances, reset between
runs, no Dask, nothing written).

The campaign: the two-axis loop on the paper's circle to the end of the path (2 s, 2 000
steps), RUNS plants from a grid of x.J and y.Kvp, true contour error max and mean, four
runs per batch (the default). Every part is warmed first (FMUs extracted, the circle's reference
built in each process), so the figures are steady-state rates; starting the cluster is
reported apart. The machine's speed drifts (shared cores), so each round times the three
one after the other, and the ratios are the medians of the rounds' ratios.

    .venv/bin/python benches/campaign_scaling.py [--runs 48] [--rounds 7] [--json FILE]
"""

import argparse
import contextlib
import json
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
from contour_fmu.campaign.execute import (archives_of, dask_client, job_of,  # noqa: E402
                                          run_on_dask)
from contour_fmu.campaign.runner import LoopInstances, run_one, unpacked  # noqa: E402
from contour_fmu.campaign.store import ResultStore  # noqa: E402

CAMPAIGN = """
name = "bench"
loop = "two_axis"
stop = "end_of_path"
metrics = ["contour_error.max", "contour_error.mean"]
batch_size = 4
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


def campaign(directory, runs):
    levels = [round(0.8 + 0.4 * k / max(runs // 2 - 1, 1), 6) for k in range(runs // 2)]
    path = Path(directory) / f"bench{runs}.toml"
    path.write_text(CAMPAIGN.format(fmus=repo.fmu_dir(), j=levels))
    return load(path)


_plain = {}


def plain_setup(path):
    """In the plain process: the campaign and one set of instances, warmed."""
    c = load(path)
    job = job_of(c)
    instances = LoopInstances(job.loop, unpacked(job, archives_of(c)))
    run_one(job, instances, c.runs[0].start_values)  # warm: the reference path
    _plain.update(campaign=c, job=job, instances=instances)


def plain_loop():
    """Seconds for every run in the plain process: one set of instances, reset between
    runs, no Dask, nothing written."""
    c, job, instances = _plain["campaign"], _plain["job"], _plain["instances"]
    began = time.perf_counter()
    for run in c.runs:
        run_one(job, instances, run.start_values)
    return time.perf_counter() - began


def on_cluster(c, client, directory, cpu=None):
    """Seconds for the campaign's runs on `client`'s workers (rows written as usual);
    adds this process's CPU seconds (client, scheduler, Parquet) to `cpu`."""
    began, used = time.perf_counter(), time.process_time()
    run_on_dask(c, ResultStore(directory, c), client)
    if cpu is not None:
        cpu.append(time.process_time() - used)
    return time.perf_counter() - began


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=48, help="runs per round (even)")
    parser.add_argument("--rounds", type=int, default=7,
                        help="rounds; each times the plain loop, 1 worker and 2 workers in turn")
    parser.add_argument("--json", type=Path, help="write the figures to this file")
    args = parser.parse_args()
    times = {"plain": [], "one": [], "two": []}
    client_cpu = []
    with tempfile.TemporaryDirectory() as directory, contextlib.ExitStack() as stack:
        c, warm = campaign(directory, args.runs), campaign(directory, 4)
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
                                              client_cpu if name == "two" else None))
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
    }
    print(f"{args.rounds} rounds of {n} runs of the two-axis loop on the circle (2 000 steps each), "
          "4 runs per batch (the default); medians")
    print(f"  plain Python loop        {figures['plain_runs_per_s']:6.2f} runs/s")
    print(f"  LocalCluster, 1 worker   {figures['one_worker_runs_per_s']:6.2f} runs/s")
    print(f"  LocalCluster, 2 workers  {figures['two_workers_runs_per_s']:6.2f} runs/s")
    print(f"  scaling 2 / 1 workers    {scaling:6.2f}x  (per round: "
          + ", ".join(f"{o / t:.2f}" for o, t in zip(times["one"], times["two"])) + ")")
    print(f"  overhead per run, 1 worker vs plain loop: {figures['overhead_per_run_s'] * 1e3:.1f} ms "
          f"({100 * overhead:.1f} %)")
    print(f"  CPU of the client process (scheduler, client, Parquet) with 2 workers: "
          f"{100 * figures['client_cpu_fraction_two_workers']:.1f} % of one core")
    print(f"  cluster start (not in the rates): {starts['one']:.1f} s and {starts['two']:.1f} s")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(figures, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
