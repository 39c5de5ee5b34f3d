"""Campaign: runs on a worker a batch of a campaign's runs through one set of FMU instances
(the fmpy engine).

A worker receives the FMU archives as bytes once, through a worker plugin (which Dask
also gives a worker that joins or restarts later), and then parameter sets only, never
fmpy objects. It extracts each archive once per process, instantiates the loop's
three FMUs once per batch and resets them between runs (fmi2Reset), as fmpy advises for
loops of simulations. A run that fails (an FMU returns fmi2Error, the path never ends)
becomes a row with status "error" and the FMU's own log message; the instances are then
made anew, so the next run starts clean.

The stepping is contour_fmu.engines.master's, the Gauss-Seidel loop of
contour_fmu.engines.stepping (controller, plant, interpolator; each input refreshed from
its source just before its FMU steps): a campaign run gives exactly what
master.closed_loop gives for the same start values.
"""

import atexit
import os
import shutil
import socket
import tempfile
import time
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..engines.fmu_log import ERROR, FmuLog
from ..engines.master import free_all, set_value
from ..engines.native import RunFailed  # a run that cannot finish, whichever engine
from ..engines.stepping import Stepping
from ..loops.wiring import LOOPS
from . import metrics as campaign_metrics

ORDER = ("controller", "plant", "interpolator")


@dataclass(frozen=True)
class Job:
    """What every run of a campaign shares; small and picklable."""
    loop: str
    step: float
    stop: float | None  # None: at the end of the path, then `settle`
    settle: float
    max_stop: float
    metrics: tuple
    fmus: dict  # unit -> SHA-256 of its archive (the key of the extraction cache)
    interpolator_variables: dict  # name -> spec.Variable, for the metrics' defaults
    engine: str = "native"  # native (native_batch) or fmpy (here)
    timeout: float = 60.0  # seconds an FMU call may take (native engine)


_extracted = {}  # SHA-256 -> unzip directory, for this process's lifetime


def _scratch():
    """A temporary folder removed at exit, for a process that is not a Dask worker."""
    directory = tempfile.mkdtemp(prefix="contour-fmu-campaign-")
    atexit.register(shutil.rmtree, directory, ignore_errors=True)
    return Path(directory)


def extracted(sha256, archive, within=None):
    """The unzip directory of an FMU archive (bytes), extracted once per process into
    `within` (a Dask worker's own folder, removed with the worker) or a temporary one."""
    if sha256 not in _extracted:
        import io

        directory = Path(tempfile.mkdtemp(prefix=f"fmu-{sha256[:12]}-", dir=within or _scratch()))
        with zipfile.ZipFile(io.BytesIO(archive)) as z:
            z.extractall(directory)
        _extracted[sha256] = directory
    return _extracted[sha256]


class LoopInstances:
    """The loop's three FMUs, instantiated once; `run` resets them between runs."""

    def __init__(self, loop, directories):
        """directories: unit -> unzip directory."""
        from fmpy.fmi2 import FMU2Slave

        from ..engines.master import co_simulation_description

        self.loop = LOOPS[loop]
        self.log = FmuLog(least=ERROR)  # the reasons a run failed
        self.slaves, self.variables = {}, {}
        try:
            for unit in ORDER:
                md = co_simulation_description(directories[unit])
                self.variables[unit] = {v.name: v for v in md.modelVariables}
                slave = FMU2Slave(guid=md.guid, unzipDirectory=str(directories[unit]),
                                  modelIdentifier=md.coSimulation.modelIdentifier, instanceName=unit)
                slave.instantiate(callbacks=self.log.callbacks)
                self.slaves[unit] = slave
        except BaseException:
            self.free()
            raise
        vr = lambda unit, name: self.variables[unit][name].valueReference  # noqa: E731
        self.stepping = Stepping(self.slaves, self.variables, self.loop.connections)
        self.path_start = [(self.slaves[s], vr(s, o), self.slaves[d], vr(d, i))
                           for s, o, d, i in self.loop.path_start]
        # Recorded at t_k before the step: the reference and the plant's position; after
        # it, the controller's outputs (its command and estimates for the sample at t_k).
        self.before = self._grouped([c for c in self.loop.recorded if c[0] != "controller"])
        self.after = self._grouped([c for c in self.loop.recorded if c[0] == "controller"])
        self.done_vr = [vr("interpolator", "done")]
        self.fresh = True

    @staticmethod
    def _grouped(columns):
        """The columns unit by unit, in stepping order (one read per unit)."""
        return [(unit, n) for unit in ORDER for u, n in columns if u == unit]

    def free(self):
        free_all(self.slaves.values())
        self.slaves = {}

    def run(self, job, start_values):
        """One run from t = 0: returns its trace, {"time": ..., "unit.variable": ...} of
        the loop's recorded outputs, one value per step."""
        self.log.clear()
        if not self.fresh:
            for slave in self.slaves.values():
                slave.reset()
        self.fresh = False
        for unit in ORDER:
            slave = self.slaves[unit]
            if job.stop is None:
                slave.setupExperiment(startTime=0.0)
            else:
                slave.setupExperiment(startTime=0.0, stopTime=job.stop)
            slave.enterInitializationMode()
            for name, value in start_values.get(unit, {}).items():
                set_value(slave, self.variables[unit][name], value)
        for src, out, dst, inp in self.path_start:
            dst.setReal([inp], src.getReal([out]))
        for unit in ORDER:
            self.slaves[unit].exitInitializationMode()

        step = job.step
        interpolator = self.slaves["interpolator"]
        if job.stop is None:
            k, before, after = self.stepping.run(
                step, int(round(job.max_stop / step)), self.before, self.after,
                ended=lambda: interpolator.getBoolean(self.done_vr)[0],
                settle=int(round(job.settle / step)))
        else:
            k, before, after = self.stepping.run(step, int(round(job.stop / step)),
                                                 self.before, self.after)
        if k is None:
            raise RunFailed(f"the path did not end within max_stop = {job.max_stop!r} s")
        trace = {"time": np.arange(k) * step}
        for columns, values in ((self.before, before), (self.after, after)):
            table = np.array(values, dtype=float).reshape(k, len(columns))
            for i, (unit, name) in enumerate(columns):
                trace[f"{unit}.{name}"] = table[:, i]
        return trace


def worker_name():
    return f"{socket.gethostname()}:{os.getpid()}"


def run_one(job, instances, start_values):
    """(metrics, trace) of one run."""
    trace = instances.run(job, start_values)
    values = campaign_metrics.compute(job.loop, job.metrics, trace,
                                      start_values.get("interpolator", {}), job.interpolator_variables)
    return values, trace


def unpacked(job, archives=None):
    """unit -> unzip directory of the job's FMUs: extracted from `archives` (unit ->
    bytes) if not yet, else from this process's cache (filled by the worker plugin)."""
    if archives is not None:
        return {unit: extracted(job.fmus[unit], archives[unit]) for unit in ORDER}
    missing = [unit for unit in ORDER if job.fmus[unit] not in _extracted]
    if missing:
        raise RunFailed(f"{worker_name()} has no copy of the {', '.join(missing)} FMU "
                        "(the campaign's worker plugin did not run here)")
    return {unit: _extracted[job.fmus[unit]] for unit in ORDER}


def run_batch(job, runs, archives=None):
    """Rows of a batch of runs [(run id, start values)], in order: run_id, status ("ok"
    or "error"), message, wall_time_s, worker and each metric (NaN unless ok). The FMUs
    come from `archives` (unit -> bytes) or, on a Dask worker, from the plugin."""
    directories = unpacked(job, archives)
    rows, instances = [], None
    try:
        for run_id, start_values in runs:
            # Instances that cannot be made are the worker's trouble, not the run's: the
            # exception fails the batch, which is retried (elsewhere, on Dask).
            if instances is None:
                instances = LoopInstances(job.loop, directories)
            began = time.perf_counter()
            row = {"run_id": run_id, "status": "ok", "message": "", "worker": worker_name()}
            try:
                values, _ = run_one(job, instances, start_values)
                row.update(values)
            except Exception as e:  # noqa: BLE001  every failure of a run is its row's message
                logged = instances.log.failures()
                row.update({m: float("nan") for m in job.metrics})
                row["status"] = "error"
                row["message"] = "; ".join([*logged[-3:], f"{type(e).__name__}: {e}"])
                instances.free()
                instances = None
            row["wall_time_s"] = time.perf_counter() - began
            rows.append(row)
    finally:
        if instances is not None:
            instances.free()
    return rows
