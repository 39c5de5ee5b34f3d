"""Campaign: running a campaign's batches: on Dask (a LocalCluster of this machine, or a
scheduler given by address) or serially in this process, writing each batch's rows as it
finishes.

Every batch is a task of plain data: the Job and the runs' start values. The FMU archives
go to each worker once, as bytes in a worker plugin that Dask also runs on a worker that
joins or restarts later (scattered data would die with the workers holding it). A batch lost with its worker, or raising
outside any run, is submitted once more; if that attempt is lost too, its runs are
recorded as "lost" (or "failed") with the reason, never dropped. Our LocalCluster's
scheduler is told not to retry by itself (allowed-failures = 0), so "once more" means
once; a remote scheduler applies its own allowed-failures before reporting a loss.
"""

import asyncio
import collections
import contextlib
import hashlib
import math
import time

from ..extras import needs
from . import native_batch
from .runner import Job, RunFailed, extracted, run_batch
from .store import ResultStore

try:
    from distributed.diagnostics.plugin import WorkerPlugin
except ImportError:  # serial runs do not need distributed
    WorkerPlugin = object

CONNECT_TIMEOUT = "10s"
WORKER_TIMEOUT = 60  # seconds a remote scheduler may take to have a worker


class SchedulerUnreachable(RuntimeError):
    pass


class RunnerUnavailable(RuntimeError):
    """A worker cannot run contour-cosim (the native engine); the campaign does not start."""


def job_of(campaign):
    return Job(loop=campaign.loop, step=campaign.step, stop=campaign.stop, settle=campaign.settle,
               max_stop=campaign.max_stop, metrics=campaign.metrics,
               fmus={name: unit.sha256 for name, unit in campaign.units.items()},
               interpolator_variables=campaign.units["interpolator"].variables,
               engine=campaign.engine, timeout=campaign.timeout)


def archives_of(campaign):
    return {name: unit.path.read_bytes() for name, unit in campaign.units.items()}


def program_of(campaign):
    """contour-cosim as bytes for the native engine (None for fmpy)."""
    if campaign.engine != "native":
        return None
    try:
        return native_batch.local_program()
    except RunFailed as e:
        raise RunnerUnavailable(f"engine = \"native\" needs contour-cosim: {e}") from None


def engine_batch(job):
    """The function that runs a batch of `job` on a worker, by its engine."""
    return native_batch.run_batch if job.engine == "native" else run_batch


def batch_function(campaign, batch_fn=None):
    """The engine's batch function, unless a test gives one."""
    return batch_fn if batch_fn is not None else engine_batch(job_of(campaign))


# With batch_size = "auto", a batch is about this much work (seconds of runs): Dask's
# cost per task (a few ms) and the row file per batch stay small against it.
TASK_SECONDS = 1.0
# Runs of each first batch, before any run's cost is known.
FIRST_BATCH = 2


class BatchSizer:
    """Runs per batch: the campaign's batch_size, or (auto) as many as make about
    TASK_SECONDS of work at the mean wall time of the runs so far, and never more than a
    share of what is left, so that every worker has work until the end."""

    def __init__(self, fixed, workers):
        self.fixed, self.workers = fixed, max(1, workers)
        self.seconds, self.runs = 0.0, 0

    def observe(self, rows):
        times = [r["wall_time_s"] for r in rows if math.isfinite(r["wall_time_s"])]
        self.seconds += sum(times)
        self.runs += len(times)

    def size(self, remaining):
        if self.fixed is not None:
            return self.fixed
        if self.runs == 0:
            return FIRST_BATCH
        per_run = max(self.seconds / self.runs, 1e-6)
        return max(1, min(round(TASK_SECONDS / per_run), math.ceil(remaining / (2 * self.workers))))


class Pending:
    """The runs still to submit, as (run id, start values), taken in order."""

    def __init__(self, runs):
        self.runs = collections.deque((r.id, r.start_values) for r in runs)

    def __len__(self):
        return len(self.runs)

    def take(self, size):
        return [self.runs.popleft() for _ in range(min(size, len(self.runs)))]


class CampaignFiles(WorkerPlugin):
    """Gives each worker, as it starts, what its engine needs, in the worker's own folder
    (removed with the worker): the FMU archives extracted (fmpy), or the FMUs, the loop's
    SSP file and contour-cosim (native), which it then checks it can run: a worker that
    cannot fails the plugin, and the campaign does not start."""

    def __init__(self, job, archives, program):
        together = hashlib.sha256("".join([job.engine, *sorted(job.fmus.values())]).encode()).hexdigest()
        self.name = f"contour-fmu-files-{together[:16]}"
        self.job, self.archives, self.program = job, archives, program

    def setup(self, worker):
        if self.job.engine == "native":
            native_batch.check_program(native_batch.prepare(self.job, self.archives, self.program,
                                                            within=worker.local_directory))
        else:
            for unit, data in self.archives.items():
                extracted(self.job.fmus[unit], data, within=worker.local_directory)


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


def run_serial(campaign, store, progress=None, batch_fn=None):
    """Every pending batch in this process, in order, with the Dask loop's rules: a batch
    raising outside any run is tried once more, then recorded as failed."""
    job, archives = job_of(campaign), archives_of(campaign)
    batch_fn = batch_function(campaign, batch_fn)
    pending, sizer = Pending(pending_runs(campaign, store)), BatchSizer(campaign.batch_size, 1)
    while pending:
        batch = pending.take(sizer.size(len(pending)))
        for attempt in (1, 2):
            rows, again = _settle(batch, attempt, lambda: batch_fn(job, batch, archives),
                                  campaign.metrics)
            sizer.observe(rows)
            _write(store, progress, rows)
            if not again:
                break


def run_on_dask(campaign, store, client, progress=None, batch_fn=None):
    """Every pending batch as a task on `client`'s workers; rows written as tasks finish.
    No more batches are in flight than the workers have threads, so a worker's death
    loses only what it was running, on any scheduler; the next batch is submitted before
    the finished one's rows are written, so a worker does not wait for the disk. Returns
    the number of tasks submitted."""
    with needs("campaign"):
        from distributed import as_completed

    job = job_of(campaign)
    batch_fn = batch_function(campaign, batch_fn)
    plugin = CampaignFiles(job, archives_of(campaign), program_of(campaign))
    try:
        client.register_plugin(plugin)
    except RunFailed as e:  # raised by a worker's setup: it cannot run contour-cosim
        raise RunnerUnavailable(f"{e}; give the workers a contour-cosim built for their "
                                f"platform, or choose engine = \"fmpy\"") from None
    tag = f"{campaign.digest[:8]}-{time.time_ns()}"
    pending = Pending(pending_runs(campaign, store))
    sizer = BatchSizer(campaign.batch_size, sum(client.nthreads().values()))
    retries, submitted = [], {}
    running = as_completed(loop=client.loop)

    def top_up():
        capacity = max(1, sum(client.nthreads().values()))
        while (retries or pending) and running.count() < capacity:
            batch, attempt = retries.pop() if retries else (pending.take(sizer.size(len(pending))), 1)
            future = client.submit(batch_fn, job, batch, pure=False,
                                   key=f"campaign-{tag}-run{batch[0][0]}-attempt{attempt}")
            submitted[future.key] = (batch, attempt)
            running.add(future)

    tasks = 0
    try:
        top_up()
        tasks = len(submitted)
        while running.count() or retries or pending:
            future = next(running)
            batch, attempt = submitted.pop(future.key)
            rows, again = _settle(batch, attempt, future.result, campaign.metrics)
            future.release()
            sizer.observe(rows)
            if again:
                retries.append((batch, 2))
            before = len(submitted)
            top_up()
            tasks += len(submitted) - before
            _write(store, progress, rows)
    finally:
        try:
            client.unregister_worker_plugin(plugin.name)
        except Exception:  # noqa: BLE001  a scheduler already gone keeps nothing
            pass
    return tasks


def execute(campaign, out, *, scheduler=None, workers=None, resume=False, serial=False,
            show_progress=True, batch_fn=None):
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
