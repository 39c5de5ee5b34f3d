"""Plumbing: the package's extras (the optional dependencies in python/pyproject.toml), the
modules each one brings, and the error that names the extra to install when one is missing.

The core (fmpy, numpy, attrs) runs loops (ssp, wiring), engines.master, .stepping,
.fmu_log, .native and .container_build, checks.five_axis_truth and checks.gcode, tuned,
repo, output_files, the campaign file (campaign.spec) and runner, and the command line
`contour-fmu` up to its commands. The extras:

- reference (geomdl, scipy): checks.reference_paths, the built-in paths and the true
  contour error;
- plots (matplotlib): the plots of the demos and the campaigns; the demos need plots and
  reference;
- campaign (dask, distributed, pyarrow, tqdm, scipy, and plots and reference): running,
  replaying and reporting campaigns (campaign.execute, .store, .report, the command line);
- engines (libcosimpy, ecospy): engines.libcosim, engines.ecos.
"""

import contextlib
import importlib.util

# extra -> the top-level modules it installs (its distributions' names are the same).
EXTRAS = {
    "reference": ("geomdl", "scipy"),
    "plots": ("matplotlib",),
    "campaign": ("dask", "distributed", "pyarrow", "tqdm", "scipy"),
    "engines": ("libcosimpy", "ecospy"),
}
# extra -> the extras it includes.
INCLUDES = {"campaign": ("plots", "reference")}


class MissingExtra(ImportError):
    """A module of an extra is not installed; the message names the extra to install."""


def modules(*extras):
    """The top-level modules that `extras` install, with those of the extras they include."""
    found = []
    for extra in extras:
        for module in (*EXTRAS[extra], *modules(*INCLUDES.get(extra, ()))):
            if module not in found:
                found.append(module)
    return tuple(found)


@contextlib.contextmanager
def needs(*extras):
    """Turns a ModuleNotFoundError for a module of `extras` into a MissingExtra that names
    them: `with needs("campaign"): import pyarrow`."""
    try:
        yield
    except ModuleNotFoundError as e:
        missing = (e.name or "").split(".")[0]
        if missing not in modules(*extras):
            raise
        names = ",".join(extras)
        which = f"{' and '.join(extras)} extra{'s' if len(extras) > 1 else ''}"
        raise MissingExtra(f"no module named {missing!r}: install contour-fmu's {which}, "
                           f"pip install 'contour-fmu[{names}]' (in a checkout: "
                           f"pip install -e './python[{names}]')", name=missing) from e


def require(*extras):
    """Raises MissingExtra unless every module of `extras` is installed (found, not
    imported)."""
    with needs(*extras):
        for module in modules(*extras):
            if importlib.util.find_spec(module) is None:
                raise ModuleNotFoundError(f"No module named {module!r}", name=module)
