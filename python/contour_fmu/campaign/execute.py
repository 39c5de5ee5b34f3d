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

import contextlib
import time

from .runner import Job, extracted, run_batch
from .store import ResultStore

try:
    from distributed.diagnostics.plugin import WorkerPlugin
except ImportError:  # serial runs do not need distributed
    WorkerPlugin = object

CONNECT_TIMEOUT = "10s"


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
    """Extracts a campaign's FMU archives on each worker as it starts."""

    def __init__(self, job, archives):
        self.name = f"contour-fmu-archives-{'-'.join(sorted(job.fmus.values()))[:64]}"
        self.archives = {job.fmus[unit]: data for unit, data in archives.items()}

    def setup(self, worker):
        for sha256, data in self.archives.items():
            extracted(sha256, data)


@contextlib.contextmanager
def dask_client(scheduler=None, workers=None):
    """A distributed Client: to `scheduler` (an address), else to a new LocalCluster of
    `workers` single-threaded worker processes (default: one per core)."""
    import dask
    from distributed import Client, LocalCluster

    if scheduler is not None:
        try:
            client = Client(scheduler, timeout=CONNECT_TIMEOUT)
        except (OSError, TimeoutError) as e:
            raise SchedulerUnreachable(f"cannot reach the Dask scheduler at {scheduler} within "
                                       f"{CONNECT_TIMEOUT}: {e}") from None
        with client:
            yield client
        return
    # allowed-failures 0: we resubmit a lost batch ourselves, once. worker-saturation 1: a
    # worker holds only the batch it runs, so its death loses that batch alone (and long
    # batches are not queued behind each other while another worker idles). No worker
    # profiler: its 10 ms stack sampling takes the GIL from the stepping loop.
    with dask.config.set({"distributed.scheduler.allowed-failures": 0,
                          "distributed.scheduler.worker-saturation": 1.0,
                          "distributed.worker.profile.enabled": False}):
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


def run_serial(campaign, store, progress=None, batch_fn=run_batch):
    """Every pending batch in this process, in order."""
    job, archives = job_of(campaign), archives_of(campaign)
    for batch in batches(pending_runs(campaign, store), campaign.batch_size):
        rows = batch_fn(job, batch, archives)
        store.write([{**row, "attempts": 1} for row in rows])
        if progress is not None:
            progress.update(len(rows))


def run_on_dask(campaign, store, client, progress=None, batch_fn=run_batch):
    """Every pending batch as a task on `client`'s workers; rows written as tasks finish."""
    from distributed import as_completed
    from distributed.scheduler import KilledWorker

    job = job_of(campaign)
    client.register_plugin(FmuArchives(job, archives_of(campaign)))
    tag = f"{campaign.digest[:8]}-{time.time_ns()}"
    submitted = {}

    def submit(batch, attempt):
        future = client.submit(batch_fn, job, batch, pure=False,
                               key=f"campaign-{tag}-run{batch[0][0]}-attempt{attempt}")
        submitted[future.key] = (batch, attempt)
        return future

    pending = as_completed([submit(b, 1) for b in batches(pending_runs(campaign, store),
                                                          campaign.batch_size)])
    for future in pending:
        batch, attempt = submitted.pop(future.key)
        try:
            rows = [{**row, "attempts": attempt} for row in future.result()]
        except KilledWorker as e:
            if attempt == 1:
                pending.add(submit(batch, 2))
                continue
            rows = _failure_rows(batch, "lost", f"the batch's worker died twice: {e}", attempt,
                                 campaign.metrics)
        except Exception as e:  # noqa: BLE001  a batch that raised outside any run
            if attempt == 1:
                pending.add(submit(batch, 2))
                continue
            rows = _failure_rows(batch, "failed", f"{type(e).__name__}: {e}", attempt,
                                 campaign.metrics)
        finally:
            future.release()
        store.write(rows)
        if progress is not None:
            progress.update(len(rows))


def execute(campaign, out, *, scheduler=None, workers=None, resume=False, serial=False,
            show_progress=True, batch_fn=run_batch):
    """Runs the campaign's pending runs into OUT; returns the store. Connects to the
    scheduler (or starts the LocalCluster) before any run."""
    from tqdm import tqdm

    store = ResultStore(out, campaign, resume=resume)  # refuses a folder in use, writes nothing
    total = len(campaign.runs)
    todo = len(pending_runs(campaign, store))
    where = contextlib.nullcontext() if serial or todo == 0 else dask_client(scheduler, workers)
    with where as client, tqdm(total=total, initial=total - todo, unit="run", desc=campaign.name,
                               disable=not show_progress, smoothing=0.1) as progress:
        if client is None:
            run_serial(campaign, store, progress, batch_fn)
        else:
            run_on_dask(campaign, store, client, progress, batch_fn)
    return store
