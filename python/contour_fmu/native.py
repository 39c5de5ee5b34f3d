"""The native master, `contour-cosim` (the Rust crate contour-cosim), from Python: runs a
loop described by an SSP file through its FMUs at the FMUs' own cost and returns the
recorded trajectory. Its stepping is contour_fmu.master's, call for call, so both give the
same numbers bit for bit (tests/fmpy/test_native_runner.py).

`cargo build --release -p contour-cosim` builds the program (make fmus does too).
"""

import io
import os
import signal
import subprocess
from pathlib import Path

import numpy as np

from . import repo
from .ssp import SHIPPED


# contour-cosim's exit status when an FMU call did not return within its timeout.
TIMEOUT_STATUS = 3


class RunFailed(RuntimeError):
    """contour-cosim refused the loop or a run failed; the message is its own."""


class Timeout(RunFailed):
    """An FMU call did not return within the timeout."""


class Crashed(RunFailed):
    """The process running the FMUs died of a signal (a segfault in an FMU, say)."""

    def __init__(self, signal_number, message):
        super().__init__(message)
        self.signal = signal_number


def program():
    """The contour-cosim program; RunFailed says how to build it when it is missing."""
    path = repo.contour_cosim()
    if not path.is_file():
        raise RunFailed(f"{path} is missing: cargo build --release -p {repo.COSIM_PACKAGE}")
    return path


def arguments(ssd, parameter_set=None, start=None, step=None, stop=None, scheme="gauss-seidel",
              record=None, timeout=None, until=None, settle=None, max_stop=None):
    """The command line of one run (see `run`)."""
    args = [str(program()), "run", str(ssd), "--scheme", scheme]
    if parameter_set is not None:
        args += ["--parameter-set", parameter_set]
    for unit, values in (start or {}).items():
        for name, value in values.items():
            text = ("true" if value else "false") if isinstance(value, bool) else (
                repr(value) if isinstance(value, float) else str(value))
            args += ["--start", f"{unit}.{name}={text}"]
    for option, value in (("--step", step), ("--stop", stop), ("--until", until),
                          ("--settle", settle), ("--max-stop", max_stop), ("--timeout", timeout)):
        if value is not None:
            args += [option, value if isinstance(value, str) else repr(float(value))]
    if record is not None:
        args += ["--record", ",".join(f"{unit}.{name}" for unit, name in record)]
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
        raise Crashed(number, f"contour-cosim was killed by {signal.Signals(number).name} "
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
    """(before, after) as contour_fmu.master.Master.run returns them, from the rows of
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
