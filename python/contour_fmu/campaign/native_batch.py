"""Campaign: runs on a worker a batch of a campaign's runs through contour-cosim, the native
master (engine = "native", the default), in a child process (contour_fmu.engines.native's
Batch).

The child steps the loop's FMUs at their own cost, measures each run where it ran and
answers its row of metrics (`contour-cosim batch --metrics`: a JSON line per run, no
trajectory); it stays up for the worker's next batches, so the FMUs are unpacked and
loaded once per worker. The metrics are contour-cosim's own, written in Rust (exact
distances to the path); the fmpy engine computes them in Python (contour_fmu.campaign.
metrics), the independent check: the two engines' rows agree within the tolerances of
docs/campaigns.md ("Metrics"), tested in tests/fmpy/test_campaign_native.py.

The child isolates the worker from the FMUs: an FMU that crashes its process (a segfault
in a foreign FMU) or a call that hangs past the campaign's `timeout` costs the run under
way, recorded as "crashed" (with the signal) or "timeout"; the next run starts a new
child.

A worker gets the FMU archives and the contour-cosim program as bytes from the campaign's
worker plugin (execute.CampaignFiles), as it gets the FMUs for fmpy; nothing needs to be
installed on it but this package.
"""

import subprocess
import tempfile
from collections import deque
import threading
import time
from pathlib import Path

import numpy as np

from ..engines import native
from ..engines.native import Batch, Ended, RunFailed
from ..loops import ssp
from ..loops.wiring import LOOPS
from .runner import ORDER, _scratch, worker_name

PROGRAM = "contour-cosim"
_prepared = {}  # job key -> folder holding loop.ssd, the FMUs and contour-cosim


def files_key(job):
    return "-".join([job.loop, *(job.fmus[unit][:12] for unit in ORDER)])


def prepare(job, archives, program, within=None):
    """The folder of the job's loop on this process: the loop's SSP file with its
    components' sources renamed to the FMU files written beside it (`archives`, unit ->
    bytes) and the contour-cosim program (bytes). Written once per process."""
    key = files_key(job)
    if key not in _prepared:
        folder = Path(tempfile.mkdtemp(prefix=f"native-{key[:24]}-", dir=within or _scratch()))
        sources = {}
        for unit in ORDER:
            name = f"{unit}-{job.fmus[unit][:12]}.fmu"
            (folder / name).write_bytes(archives[unit])
            sources[unit] = name
        (folder / "loop.ssd").write_text(ssp.with_sources(LOOPS[job.loop].structure.file, sources))
        runner = folder / PROGRAM
        runner.write_bytes(program)
        runner.chmod(0o755)
        _prepared[key] = folder
    return _prepared[key]


def check_program(folder):
    """Raises RunFailed when contour-cosim in `folder` cannot run here (another platform,
    say)."""
    try:
        done = subprocess.run([str(Path(folder) / PROGRAM), "--help"], capture_output=True,
                              timeout=60)
    except OSError as e:
        raise RunFailed(f"{worker_name()} cannot run contour-cosim: {e}") from None
    if done.returncode != 0:
        raise RunFailed(f"{worker_name()} cannot run contour-cosim (exit status "
                        f"{done.returncode}): {done.stderr.decode(errors='replace').strip()[-500:]}")


def command(job, folder, trajectory=False):
    """contour-cosim's command line for the job's runs, read from its standard input;
    with `trajectory` the runs' recorded columns come back too (a replay's)."""
    until = {} if job.stop is not None else {
        "until": "interpolator.done", "settle": job.settle, "max_stop": job.max_stop}
    args = native.arguments(folder / "loop.ssd", step=job.step, stop=job.stop,
                            metrics=list(job.metrics), timeout=job.timeout, scheme=None,
                            command="batch", executable=folder / PROGRAM,
                            record=LOOPS[job.loop].recorded if trajectory else None, **until)
    return args + ["--trajectory"] if trajectory else args


def _metrics(job, run_id, head):
    """The row's metric values from a run's result line (numbers, or "NaN", "inf")."""
    try:
        return {m: float(head["metrics"][m]) for m in job.metrics}
    except (KeyError, TypeError, ValueError) as e:
        raise RunFailed(f"contour-cosim answered run {run_id} without its metrics: {e!r}") from None


def replay(job, archives, run_id, start_values, within=None):
    """(metrics, trace) of one run alone, through contour-cosim as a batch runs it: the
    row's metrics and the fmpy runner's trace of the recorded columns (the controller's
    outputs once the units stepped, row k + 1; the rest before the step, row k). Raises
    RunFailed with the run's message when it fails."""
    folder = prepare(job, archives, local_program(), within)
    batch = Batch(command(job, folder, trajectory=True), folder)
    try:
        head, table = batch.run(run_id, start_values, ORDER)
    finally:
        batch.close()
    if head["status"] != "ok":
        raise RunFailed(head["message"])
    steps = head["steps"]
    trace = {"time": np.arange(steps) * job.step}
    for i, column in enumerate(batch.columns):
        trace[column] = table[1:, i] if column.startswith("controller.") else table[:-1, i]
    return _metrics(job, run_id, head), trace


def _row(run_id, status, message, began, metrics, values=None):
    row = {"run_id": run_id, "status": status, "message": message, "worker": worker_name(),
           "wall_time_s": time.perf_counter() - began}
    row.update(values if values is not None else {m: float("nan") for m in metrics})
    return row


_children = {}  # command line -> Batch, for this process's lifetime
# A worker with several threads runs batches at once: one batch at a time talks to the
# child (a pipe carries one conversation).
_lock = threading.Lock()


def _child(key, folder):
    """The child running the command line `key` (a tuple), started when there is none."""
    if key not in _children:
        # One child at a time: another campaign's is not needed any more.
        for other in _children.values():
            other.close()
        _children.clear()
        _children[key] = Batch(list(key), folder)
    return _children[key]


def _ended_row(run_id, ended, began, metrics):
    """The row of the run a child's end took: crashed, timeout; anything else raises."""
    status, said = ended.args
    if status < 0:
        return _row(run_id, "crashed", f"the FMUs' process was killed by "
                    f"{native.signal_name(-status)} (signal {-status})", began, metrics)
    if status == native.TIMEOUT_STATUS:
        last = said.splitlines()[-1] if said else "an FMU call did not return in time"
        return _row(run_id, "timeout", last.removeprefix("contour-cosim: "), began, metrics)
    raise RunFailed(f"contour-cosim stopped (exit status {status}): {said[-2000:]}")


# Run lines sent ahead of the answer read: the child starts the next run while Python
# makes the row of the last.
AHEAD = 2


def _rows(job, folder, runs):
    """The rows of `runs`, in order, through this process's child (made anew after a
    crash, a timeout or an fmi2Fatal). The runs a child took but did not answer before it
    ended, after the one under way, go to the next child."""
    key = tuple(command(job, folder))
    waiting, sent = deque(runs), deque()
    began = time.perf_counter()
    replaced_after_fatal = False
    while waiting or sent:
        try:
            child = _child(key, folder)
            while waiting and len(sent) < AHEAD:
                run = waiting.popleft()
                sent.append(run)
                if not child.send(*run, ORDER):
                    break  # it has ended: receiving says how
            run_id, _ = sent[0]
            head, _ = child.receive(run_id)
        except Ended as ended:
            _children.pop(key, None)
            waiting.extendleft(reversed(sent))
            sent.clear()
            # After an fmi2Fatal the child answered that run, then ended: the next run
            # goes to a new child, once.
            if ended.args[0] == native.FATAL_STATUS and not replaced_after_fatal:
                replaced_after_fatal = True
                continue
            run_id, _ = waiting.popleft()
            yield _ended_row(run_id, ended, began, job.metrics)
        except RunFailed:
            _children.pop(key, None)
            raise
        else:
            sent.popleft()
            if head["status"] != "ok":
                yield _row(run_id, "error", head["message"], began, job.metrics)
            else:
                yield _row(run_id, "ok", "", began, job.metrics, _metrics(job, run_id, head))
        replaced_after_fatal = False
        began = time.perf_counter()


def run_batch(job, runs, archives=None):
    """Rows of a batch of runs [(run id, start values)], in order, as runner.run_batch
    gives them, with two more statuses: "crashed" and "timeout". The loop's files come
    from `archives` (unit -> bytes) and this checkout's contour-cosim or, on a Dask
    worker, from the plugin."""
    key = files_key(job)
    if archives is not None:
        folder = _prepared.get(key) or prepare(job, archives, local_program())
    elif key in _prepared:
        folder = _prepared[key]
    else:
        raise RunFailed(f"{worker_name()} has no copy of the campaign's FMUs and contour-cosim "
                        "(the campaign's worker plugin did not run here)")
    with _lock:
        return list(_rows(job, folder, runs))


def local_program():
    """contour-cosim of this checkout, as bytes (what the plugin sends the workers)."""
    return Path(native.program()).read_bytes()
