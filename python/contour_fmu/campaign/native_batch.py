"""Runs on a worker: a batch of a campaign's runs through contour-cosim, the native master
(engine = "native", the default), in a child process.

The child steps the loop's FMUs at their own cost and streams each run's trajectory back
(`contour-cosim batch`: a JSON line per run, then its rows as f64); the metrics are
computed here by the same code as for the fmpy engine, on the same trajectory, so both
engines give the same rows. The child isolates the worker from the FMUs: an FMU that
crashes its process (a segfault in a foreign FMU) or a call that hangs past the campaign's
`timeout` costs the run under way, recorded as "crashed" (with the signal) or "timeout";
the batch goes on in a new child with the runs after it.

A worker gets the FMU archives and the contour-cosim program as bytes from the campaign's
worker plugin (execute.CampaignFiles), as it gets the FMUs for fmpy; nothing needs to be
installed on it but this package.
"""

import json
import shutil
import signal
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

from .. import native, ssp
from ..loops import LOOPS
from . import metrics as campaign_metrics
from .runner import ORDER, RunFailed, _scratch, worker_name

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


def text(value):
    """A start value as contour-cosim's --start reads it (exact for floats: repr)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    return str(value)


def command(job, folder, runs_file):
    """contour-cosim's command line for a batch of the job."""
    columns = _columns(job.loop)
    args = [str(folder / PROGRAM), "batch", str(folder / "loop.ssd"), "--step", repr(job.step),
            "--record", ",".join(f"{u}.{n}" for u, n in columns), "--timeout", repr(job.timeout),
            "--runs", str(runs_file)]
    if job.stop is None:
        args += ["--until", "interpolator.done", "--settle", repr(job.settle),
                 "--max-stop", repr(job.max_stop)]
    else:
        args += ["--stop", repr(job.stop)]
    return args


def _columns(loop):
    """The recorded columns, unit by unit in stepping order (as the fmpy runner reads them)."""
    return [(unit, n) for unit in ORDER for u, n in LOOPS[loop].recorded if u == unit]


def _read_exactly(stream, size):
    data = stream.read(size)
    return data if data is not None and len(data) == size else None


def _trace(job, table, steps):
    """The fmpy runner's trace from the rows t_0..t_k: the controller's outputs once the
    units stepped (row k+1), the rest before the step (row k)."""
    trace = {"time": np.arange(steps) * job.step}
    for i, (unit, name) in enumerate(_columns(job.loop)):
        column = table[:, i]
        trace[f"{unit}.{name}"] = column[1:] if unit == "controller" else column[:-1]
    return trace


def _row(run_id, status, message, began, metrics, values=None):
    row = {"run_id": run_id, "status": status, "message": message, "worker": worker_name(),
           "wall_time_s": time.perf_counter() - began}
    row.update(values if values is not None else {m: float("nan") for m in metrics})
    return row


def _signal_name(number):
    try:
        return signal.Signals(number).name
    except ValueError:
        return f"signal {number}"


def _one_child(job, folder, runs, scratch):
    """Rows of `runs` from one contour-cosim process, up to the first run it did not finish
    (a crash or a timeout, which gets its row); returns (rows, runs not started)."""
    runs_file = scratch / "runs.jsonl"
    with open(runs_file, "w") as f:
        for run_id, start_values in runs:
            starts = [[unit, name, text(value)] for unit in ORDER
                      for name, value in start_values.get(unit, {}).items()]
            f.write(json.dumps({"run": run_id, "start": starts}) + "\n")
    errors = open(scratch / "stderr.txt", "w+b")
    child = subprocess.Popen(command(job, folder, runs_file), stdout=subprocess.PIPE, stderr=errors)
    rows, index = [], 0
    try:
        began = time.perf_counter()
        header = child.stdout.readline()
        width = len(json.loads(header)["columns"]) if header else 0
        while index < len(runs):
            line = child.stdout.readline()
            if not line:
                break
            head = json.loads(line)
            run_id, start_values = runs[index]
            if head["run"] != run_id:
                raise RunFailed(f"contour-cosim answered run {head['run']} for run {run_id}")
            if head["status"] == "ok":
                steps = head["steps"]
                data = _read_exactly(child.stdout, (steps + 1) * width * 8)
                if data is None:
                    break
                table = np.frombuffer(data, dtype="<f8").reshape(steps + 1, width)
                try:
                    values = campaign_metrics.compute(
                        job.loop, job.metrics, _trace(job, table, steps),
                        start_values.get("interpolator", {}), job.interpolator_variables)
                    rows.append(_row(run_id, "ok", "", began, job.metrics, values))
                except Exception as e:  # noqa: BLE001  every failure of a run is its row's message
                    rows.append(_row(run_id, "error", f"{type(e).__name__}: {e}", began, job.metrics))
            else:
                rows.append(_row(run_id, "error", head["message"], began, job.metrics))
            index += 1
            began = time.perf_counter()
    finally:
        child.stdout.close()
        status = child.wait()
        errors.seek(0)
        said = errors.read().decode(errors="replace").strip()
        errors.close()
    if index < len(runs):
        run_id = runs[index][0]
        if status < 0:
            rows.append(_row(run_id, "crashed", f"the FMUs' process was killed by "
                             f"{_signal_name(-status)} (signal {-status})", began, job.metrics))
        elif status == native.TIMEOUT_STATUS:
            rows.append(_row(run_id, "timeout", said.removeprefix("contour-cosim: "), began,
                             job.metrics))
        else:
            raise RunFailed(f"contour-cosim stopped (exit status {status}): {said[-2000:]}")
        index += 1
    return rows, runs[index:]


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
    scratch = Path(tempfile.mkdtemp(prefix="batch-", dir=folder))
    rows = []
    try:
        while runs:
            done, runs = _one_child(job, folder, runs, scratch)
            rows.extend(done)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return rows


def local_program():
    """contour-cosim of this checkout, as bytes (what the plugin sends the workers)."""
    return Path(native.program()).read_bytes()
