"""Engine: the native master, `contour-cosim` (the Rust crate contour-cosim), from Python,
the one wrapper of the program: `run` runs a loop described by an SSP file through its
FMUs at the FMUs' own cost and returns the recorded trajectory; `Batch` keeps a
`contour-cosim batch` process for many runs (the campaigns' native engine,
contour_fmu.campaign.native_batch). Its stepping is contour_fmu.engines.master's, call for
call, so both give the same numbers bit for bit (tests/fmpy/test_native_runner.py).

`cargo build --release -p contour-cosim` builds the program (make fmus does too).
"""

import io
import json
import os
import signal
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from .. import repo
from ..loops.ssp import SHIPPED


# contour-cosim's exit status when an FMU call did not return within its timeout.
TIMEOUT_STATUS = 3
# contour-cosim batch's exit status after a run in which an FMU returned fmi2Fatal: the
# run was answered, and the next needs a new process.
FATAL_STATUS = 4
# Seconds a batch process that was told to stop may take to end before it is killed.
END_WAIT = 30.0


class RunFailed(RuntimeError):
    """contour-cosim refused the loop or a run failed (the message is its own), or a run
    cannot finish (a campaign's row then carries the message)."""


class Timeout(RunFailed):
    """An FMU call did not return within the timeout."""


class Crashed(RunFailed):
    """The process running the FMUs died of a signal (a segfault in an FMU, say)."""

    def __init__(self, signal_number, message):
        super().__init__(message)
        self.signal = signal_number


def signal_name(number):
    """SIGSEGV for 11, say ("signal N" for a number that names none)."""
    try:
        return signal.Signals(number).name
    except ValueError:
        return f"signal {number}"


def program():
    """The contour-cosim program; RunFailed says how to build it when it is missing."""
    path = repo.contour_cosim()
    if not path.is_file():
        raise RunFailed(f"{path} is missing: cargo build --release -p {repo.COSIM_PACKAGE}")
    return path


def text(value):
    """A start value as contour-cosim's --start reads it (exact for floats: repr)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    return str(value)


def arguments(ssd, parameter_set=None, start=None, step=None, stop=None, scheme="gauss-seidel",
              record=None, timeout=None, until=None, settle=None, max_stop=None, command="run",
              executable=None, metrics=None):
    """The command line of one run (see `run`), or with `command` = "batch" of a batch
    process (see `Batch`; `metrics`, a list of the campaigns' metric names, are then
    measured by the process and answered instead of the trajectory); `executable` is
    contour-cosim (default: `program()`), `scheme` None leaves the program's default."""
    args = [str(executable or program()), command, str(ssd)]
    if scheme is not None:
        args += ["--scheme", scheme]
    if parameter_set is not None:
        args += ["--parameter-set", parameter_set]
    for unit, values in (start or {}).items():
        for name, value in values.items():
            args += ["--start", f"{unit}.{name}={text(value)}"]
    for option, value in (("--step", step), ("--stop", stop), ("--until", until),
                          ("--settle", settle), ("--max-stop", max_stop), ("--timeout", timeout)):
        if value is not None:
            args += [option, value if isinstance(value, str) else repr(float(value))]
    if record is not None:
        args += ["--record", ",".join(f"{unit}.{name}" for unit, name in record)]
    if metrics is not None:
        args += ["--metrics", ",".join(metrics)]
    return args


def pythonfmu_environment():
    """What a pythonfmu FMU needs in contour-cosim's process, from this Python: its
    libpython loaded first (pythonfmu's binary takes Python's symbols from the process,
    which in fmpy is Python itself) and this Python's packages on the path (the FMU's
    script imports pythonfmu)."""
    import site
    import sysconfig

    library = Path(sysconfig.get_config_var("LIBDIR")) / sysconfig.get_config_var("LDLIBRARY")
    if not library.is_file():
        raise RunFailed(f"{library} is missing: this Python has no shared libpython, which a "
                        f"pythonfmu FMU needs outside Python")
    return {"LD_PRELOAD": str(library), "PYTHONPATH": os.pathsep.join(site.getsitepackages())}


def run(ssd, env=None, **options):
    """Runs the loop of the SSP file `ssd` once: `parameter_set` (a name in the file),
    `start` ({unit: {variable: value}}, after the parameter set), `step` and `stop` (s;
    default: the file's default experiment), `scheme` ("gauss-seidel" or "jacobi"), `record`
    ([(unit, variable)]; default: every output), `timeout` (s per FMU call), or `until`
    ("unit.variable", a Boolean) with `settle` and `max_stop` instead of `stop`. Returns a
    structured array, one row per t_k from t_0 to the end: "time" and "unit.variable"
    columns. `env` holds further environment variables for the program (e.g.
    `pythonfmu_environment()`)."""
    done = subprocess.run(arguments(ssd, **options), capture_output=True, text=True,
                          env=None if env is None else {**os.environ, **env})
    if done.returncode < 0:
        number = -done.returncode
        raise Crashed(number, f"contour-cosim was killed by {signal_name(number)} "
                              f"(an FMU crashed the process)")
    if done.returncode == TIMEOUT_STATUS:
        raise Timeout(done.stderr.strip())
    if done.returncode != 0:
        raise RunFailed(done.stderr.strip())
    header, _, body = done.stdout.partition("\n")
    names = header.split(",")
    table = np.loadtxt(io.StringIO(body), delimiter=",", ndmin=2)
    return np.rec.fromarrays(table.T, names=names) if len(table) else None


def as_before_after(rows, step):
    """(before, after) as contour_fmu.engines.master.Master.run returns them, from the rows of
    `run`: before[k] at t_k, after[k] once every FMU has stepped to t_k+1."""
    before, after = rows[:-1].copy(), rows[1:].copy()
    before["time"] = np.arange(len(before)) * step
    after["time"] = np.arange(len(after)) * step + step
    return before, after


def shipped(name, fmu_dir):
    """The shipped loop `name` (two_axis, five_axis) as it sits beside the FMUs of
    `fmu_dir` (make fmus copies it there)."""
    file = Path(fmu_dir) / f"{name}.ssd"
    if not file.is_file():
        raise RunFailed(f"{file} is missing: make fmus copies {SHIPPED / (name + '.ssd')} there")
    return file


class Ended(Exception):
    """A batch process ended before it answered a run: (exit status, its stderr)."""


class Batch:
    """A `contour-cosim batch` process, kept for many runs (its FMUs unpacked and loaded
    once): a run line in, the run's result out. `args` is its command line
    (`arguments(..., command="batch")`), `scratch` a folder for its standard error. A
    process that answers out of turn or garbled is killed: it is never read again. With
    metrics the process answers no trajectory (`trajectory` False)."""

    def __init__(self, args, scratch):
        self.errors = tempfile.TemporaryFile(dir=scratch)
        self.process = subprocess.Popen(args, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                        stderr=self.errors)
        header = self.process.stdout.readline()
        if not header:
            self.ended()
        try:
            said = json.loads(header)
            self.columns = list(said["columns"])
            self.width = len(self.columns)
            self.trajectory = bool(said.get("trajectory", True))
        except (ValueError, KeyError, TypeError):
            self.garbled(f"a first line that is not its columns: {header[:200]!r}")

    def ended(self, kill=False):
        """Raises Ended with the exit status and what the process said."""
        if kill:
            self.process.kill()
        for stream in (self.process.stdin, self.process.stdout):
            try:
                stream.close()
            except OSError:  # a broken pipe: the process is gone
                pass
        try:
            status = self.process.wait(timeout=END_WAIT)
        except subprocess.TimeoutExpired:
            self.process.kill()
            status = self.process.wait()
        self.errors.seek(0)
        said = self.errors.read().decode(errors="replace").strip()
        self.errors.close()
        raise Ended(status, said)

    def garbled(self, what):
        """Kills the process and raises RunFailed: its answers can no longer be trusted."""
        try:
            self.ended(kill=True)
        except Ended:
            pass
        raise RunFailed(f"contour-cosim answered {what}")

    def run(self, run_id, start_values, order=None):
        """(head, table): the result line of the run with `start_values` ({unit: {variable:
        value}}, set unit by unit in `order`, default the dict's) and, when ok and the
        process answers trajectories, its rows t_0..t_k (else None)."""
        if not self.send(run_id, start_values, order):
            self.ended()
        return self.receive(run_id)

    def send(self, run_id, start_values, order=None):
        """Writes the run's line (see `run`); False when the process no longer reads (it
        has ended: `receive` says how). A caller may send runs ahead of their answers."""
        starts = [[unit, name, text(value)] for unit in (order or start_values)
                  for name, value in start_values.get(unit, {}).items()]
        try:
            self.process.stdin.write((json.dumps({"run": run_id, "start": starts}) + "\n").encode())
            self.process.stdin.flush()
        except OSError:
            return False
        return True

    def receive(self, run_id):
        """(head, table) of the oldest run sent and not yet received, `run_id` (see `run`);
        Ended when the process ended first, RunFailed when it answers another run."""
        line = self.process.stdout.readline()
        if not line:
            self.ended()
        try:
            head = json.loads(line)
            answered, ok, steps = head["run"], head["status"] == "ok", int(head["steps"])
        except (ValueError, KeyError, TypeError):
            self.garbled(f"a line that is not a run's result: {line[:200]!r}")
        if answered != run_id:
            self.garbled(f"run {answered} for run {run_id}")
        if not ok or not self.trajectory:
            return head, None
        size = (steps + 1) * self.width * 8
        data = self.process.stdout.read(size)
        if data is None or len(data) != size:
            self.ended()
        return head, np.frombuffer(data, dtype="<f8").reshape(steps + 1, self.width)

    def close(self):
        try:
            self.ended()
        except Ended:
            pass
