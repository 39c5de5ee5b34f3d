"""Running a campaign's batches: on Dask (a LocalCluster of this machine, or a scheduler
given by address) or serially in this process, writing each batch's rows as it finishes.

Every batch is a task of plain data: the Job and the runs' start values. The FMU archives
go to each worker once, as bytes in a worker plugin that Dask also runs on a worker that
joins or restarts later (scattered data would die with the workers holding it). A batch lost with its worker, or raising
outside any run, is submitted once more; if that attempt is lost too, its runs are
recorded as "lost" (or "failed") with the reason, never dropped. Our LocalCluster's
scheduler is told not to retry by itself (allowed-failures = 0), so "once more" means
once; a remote scheduler applies its own allowed-failures before reporting a loss.
"""

import asyncio
import contextlib
import hashlib
import time

from ..extras import needs
from .runner import Job, extracted, run_batch
from .store import ResultStore

try:
    from distributed.diagnostics.plugin import WorkerPlugin
except ImportError:  # serial runs do not need distributed
    WorkerPlugin = object

CONNECT_TIMEOUT = "10s"
WORKER_TIMEOUT = 60  # seconds a remote scheduler may take to have a worker


class SchedulerUnreachable(RuntimeError):
    pass


def job_of(campaign):
    return Job(loop=campaign.loop, step=campaign.step, stop=campaign.stop, settle=campaign.settle,
               max_stop=campaign.max_stop, metrics=campaign.metrics,
               fmus={name: unit.sha256 for name, unit in campaign.units.items()},
               interpolator_variables=campaign.units["interpolator"].variables)


def archives_of(campaign):
    return {name: unit.path.read_bytes() for name, unit in campaign.units.items()}


def batches(runs, size):
    """Consecutive runs in lists of `size`, as (run id, start values) pairs."""
    pairs = [(r.id, r.start_values) for r in runs]
    return [pairs[i:i + size] for i in range(0, len(pairs), size)]


class FmuArchives(WorkerPlugin):
    """Extracts a campaign's FMU archives on each worker as it starts, into the worker's
    own folder (removed with the worker)."""

    def __init__(self, job, archives):
        together = hashlib.sha256("".join(sorted(job.fmus.values())).encode()).hexdigest()
        self.name = f"contour-fmu-archives-{together[:16]}"
        self.archives = {job.fmus[unit]: data for unit, data in archives.items()}

    def setup(self, worker):
        for sha256, data in self.archives.items():
            extracted(sha256, data, within=worker.local_directory)


@contextlib.contextmanager
def dask_client(scheduler=None, workers=None):
    """A distributed Client: to `scheduler` (an address), else to a new LocalCluster of
    `workers` single-threaded worker processes (default: one per core)."""
    with needs("campaign"):
        import dask
        from distributed import Client, LocalCluster

    if scheduler is not None:
        try:
            client = Client(scheduler, timeout=CONNECT_TIMEOUT)
        except (OSError, TimeoutError, ValueError) as e:
            raise SchedulerUnreachable(f"cannot reach the Dask scheduler at {scheduler} within "
                                       f"{CONNECT_TIMEOUT}: {e}") from None
        with client:
            try:
                client.wait_for_workers(1, timeout=WORKER_TIMEOUT)
            except TimeoutError:
                raise SchedulerUnreachable(f"the Dask scheduler at {scheduler} has no worker "
                                           f"(none joined within {WORKER_TIMEOUT} s)") from None
            yield client
        return
    # allowed-failures 0: we resubmit a lost batch ourselves, once. worker-saturation 1:
    # the scheduler gives a worker only the batch it runs (the client limits what it has
    # in flight as well, so work stealing has nothing to do). The rest is Dask's idle
    # CPU, which on a small machine is taken from the runs: no worker profiler (its 10 ms
    # stack sampling takes the GIL from the stepping loop), a 1 s event-loop health tick
    # instead of 20 ms, a 2 s system monitor. Idle, the client process then uses 3.6 %
    # of a core instead of 7.7 %, each worker 1.4 % instead of 3.4 %.
    with dask.config.set({"distributed.scheduler.allowed-failures": 0,
                          "distributed.scheduler.worker-saturation": 1.0,
                          "distributed.scheduler.work-stealing": False,
                          "distributed.worker.profile.enabled": False,
                          "distributed.admin.tick.interval": "1s",
                          "distributed.admin.system-monitor.interval": "2s"}):
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                          dashboard_address=":0") as cluster, Client(cluster) as client:
            yield client


def pending_runs(campaign, store):
    finished = store.finished()
    return [r for r in campaign.runs if r.id not in finished]


def _failure_rows(batch, status, message, attempts, metrics):
    return [{"run_id": run_id, "status": status, "message": message, "attempts": attempts,
             "wall_time_s": float("nan"), "worker": "", **{m: float("nan") for m in metrics}}
            for run_id, _ in batch]


def _settle(batch, attempt, run, metrics):
    """(rows to write, whether to try again) of one attempt of a batch: `run()` gives its
    rows or raises. A first attempt that is lost or fails is tried again; a second is
    recorded as lost or failed, with the reason."""
    with needs("campaign"):
        from distributed.scheduler import KilledWorker

    try:
        return [{**row, "attempts": attempt} for row in run()], False
    except KilledWorker as e:
        status, message = "lost", f"the batch's worker died twice: {e}"
    except (Exception, asyncio.CancelledError) as e:  # noqa: BLE001  recorded in the rows
        status, message = "failed", f"{type(e).__name__}: {e}"
    if attempt == 1:
        return [], True
    return _failure_rows(batch, status, message, attempt, metrics), False


def _write(store, progress, rows):
    if rows:
        store.write(rows)
        if progress is not None:
            progress.update(len(rows))


def run_serial(campaign, store, progress=None, batch_fn=run_batch):
    """Every pending batch in this process, in order, with the Dask loop's rules: a batch
    raising outside any run is tried once more, then recorded as failed."""
    job, archives = job_of(campaign), archives_of(campaign)
    for batch in batches(pending_runs(campaign, store), campaign.batch_size):
        for attempt in (1, 2):
            rows, again = _settle(batch, attempt, lambda: batch_fn(job, batch, archives),
                                  campaign.metrics)
            _write(store, progress, rows)
            if not again:
                break


def run_on_dask(campaign, store, client, progress=None, batch_fn=run_batch):
    """Every pending batch as a task on `client`'s workers; rows written as tasks finish.
    No more batches are in flight than the workers have threads, so a worker's death
    loses only what it was running, on any scheduler; the next batch is submitted before
    the finished one's rows are written, so a worker does not wait for the disk."""
    with needs("campaign"):
        from distributed import as_completed

    job = job_of(campaign)
    plugin = FmuArchives(job, archives_of(campaign))
    client.register_plugin(plugin)
    tag = f"{campaign.digest[:8]}-{time.time_ns()}"
    waiting = [(b, 1) for b in reversed(batches(pending_runs(campaign, store), campaign.batch_size))]
    submitted = {}
    running = as_completed(loop=client.loop)

    def top_up():
        capacity = max(1, sum(client.nthreads().values()))
        while waiting and running.count() < capacity:
            batch, attempt = waiting.pop()
            future = client.submit(batch_fn, job, batch, pure=False,
                                   key=f"campaign-{tag}-run{batch[0][0]}-attempt{attempt}")
            submitted[future.key] = (batch, attempt)
            running.add(future)

    try:
        top_up()
        while running.count() or waiting:
            future = next(running)
            batch, attempt = submitted.pop(future.key)
            rows, again = _settle(batch, attempt, future.result, campaign.metrics)
            future.release()
            if again:
                waiting.append((batch, 2))
            top_up()
            _write(store, progress, rows)
    finally:
        try:
            client.unregister_worker_plugin(plugin.name)
        except Exception:  # noqa: BLE001  a scheduler already gone keeps nothing
            pass


def execute(campaign, out, *, scheduler=None, workers=None, resume=False, serial=False,
            show_progress=True, batch_fn=run_batch):
    """Runs the campaign's pending runs into OUT; returns the store. Connects to the
    scheduler (or starts the LocalCluster) before any run."""
    with needs("campaign"):
        from tqdm import tqdm

    store = ResultStore(out, campaign, resume=resume)  # refuses a folder in use, writes nothing
    total = len(campaign.runs)
    todo = len(pending_runs(campaign, store))
    where = contextlib.nullcontext() if serial or todo == 0 else dask_client(scheduler, workers)
    try:
        with where as client, tqdm(total=total, initial=total - todo, unit="run", desc=campaign.name,
                                   disable=not show_progress, smoothing=0.1) as progress:
            if client is None:
                run_serial(campaign, store, progress, batch_fn)
            else:
                run_on_dask(campaign, store, client, progress, batch_fn)
    finally:
        store.close()
    return store
