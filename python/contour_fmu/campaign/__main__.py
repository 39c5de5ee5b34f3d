"""Campaign: the command line, python -m contour_fmu.campaign run | replay (see --help),
also `contour-fmu campaign`. Needs the campaign extra (--help does not)."""

import argparse
import sys
import time
from pathlib import Path

from ..extras import MissingExtra, require

PROG = "python -m contour_fmu.campaign"


def parse_args(argv, prog=PROG):
    parser = argparse.ArgumentParser(prog=prog,
                                     description="Closed-loop co-simulation campaigns of the "
                                                 "contour-fmu FMUs on Dask (docs/campaigns.md).")
    commands = parser.add_subparsers(dest="command", required=True)
    run = commands.add_parser("run", help="run a campaign file's runs, write rows, summary and plots")
    run.add_argument("file", type=Path, help="the campaign file (TOML)")
    run.add_argument("--out", type=Path, required=True, help="the output folder")
    where = run.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="a running Dask scheduler, e.g. tcp://10.0.0.5:8786 (default: a "
                            "LocalCluster on this machine)")
    where.add_argument("--serial", action="store_true",
                       help="run in this process, without Dask (same rows)")
    run.add_argument("--workers", type=int, metavar="N",
                     help="LocalCluster worker processes (default: one per core)")
    run.add_argument("--resume", action="store_true",
                     help="finish the campaign in --out: skip the runs it has rows for")
    run.add_argument("--fmu-dir", type=Path, help="take the loop's FMUs from this folder")
    run.add_argument("--no-progress", action="store_true", help="no progress bar")
    replay = commands.add_parser("replay", help="run one run of a campaign alone, write its time series")
    replay.add_argument("file", type=Path, help="the campaign file (TOML)")
    replay.add_argument("--run", type=int, required=True, metavar="ID", help="the run's id (run_id)")
    replay.add_argument("--out", type=Path, default=Path("."), help="where run<ID>.csv goes")
    replay.add_argument("--fmu-dir", type=Path, help="take the loop's FMUs from this folder")
    args = parser.parse_args(argv)
    if args.command == "run" and args.workers is not None:
        if args.workers < 1:
            parser.error(f"--workers {args.workers}: expected at least 1")
        if args.scheduler or args.serial:
            parser.error("--workers sizes the LocalCluster; it does not go with --scheduler or --serial")
    return args


def command_run(args):
    from . import report
    from .execute import execute
    from .spec import load

    campaign = load(args.file, args.fmu_dir)
    began = time.perf_counter()
    store = execute(campaign, args.out, scheduler=args.scheduler, workers=args.workers,
                    resume=args.resume, serial=args.serial, show_progress=not args.no_progress)
    elapsed = time.perf_counter() - began
    table = store.consolidate()
    report.write(campaign, table, args.out)
    statuses = table.column("status").to_pylist()
    print(f"{len(statuses)} of {len(campaign.runs)} runs recorded ({statuses.count('ok')} ok) "
          f"in {elapsed:.1f} s; rows in {args.out / 'results.parquet'}, summary in "
          f"{args.out / 'summary.md'}")
    return 0 if statuses.count("ok") == len(campaign.runs) else 1


def command_replay(args):
    from ..output_files import write_csv
    from .execute import archives_of, job_of
    from .metrics import errors
    from .spec import load

    campaign = load(args.file, args.fmu_dir)
    run = campaign.run(args.run)
    job = job_of(campaign)
    # On the campaign's engine, so the printed metrics are the row's.
    replay = _replay_native if job.engine == "native" else _replay_fmpy
    try:
        values, trace = replay(job, archives_of(campaign), run)
    except Exception as e:  # noqa: BLE001  a failed run's reason, as its row gives it
        print(f"run {run.id} failed: {type(e).__name__}: {e}", file=sys.stderr)
        return 1
    interpolator = run.start_values.get("interpolator", {})
    columns = dict(trace)
    for quantity, per_sample in errors(job.loop, trace, interpolator, job.interpolator_variables).items():
        columns[quantity] = per_sample
    args.out.mkdir(parents=True, exist_ok=True)
    target = args.out / f"run{run.id}.csv"
    write_csv(target, columns)
    swept = ", ".join(f"{k} = {v!r}" for k, v in run.swept.items())
    print(f"run {run.id}: variant {run.variant!r}, path {run.path!r}{', ' + swept if swept else ''}")
    for metric, value in values.items():
        print(f"  {metric} = {value!r}")
    print(f"time series in {target}")
    return 0


def _replay_fmpy(job, archives, run):
    from .runner import LoopInstances, run_one, unpacked

    instances = LoopInstances(job.loop, unpacked(job, archives))
    try:
        return run_one(job, instances, run.start_values)
    except Exception:
        for line in instances.log.failures():
            print(line, file=sys.stderr)
        raise
    finally:
        instances.free()


def _replay_native(job, archives, run):
    from . import native_batch

    return native_batch.replay(job, archives, run.id, run.start_values)


def main(argv=None, prog=PROG):
    args = parse_args(argv, prog)
    try:
        require("campaign")  # before any run, not when the plots are drawn at the end
    except MissingExtra as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    from .execute import RunnerUnavailable, SchedulerUnreachable
    from .spec import CampaignError
    from .store import OutputInUse

    try:
        return command_run(args) if args.command == "run" else command_replay(args)
    except (CampaignError, OutputInUse, SchedulerUnreachable, RunnerUnavailable) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
