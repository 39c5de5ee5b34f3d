"""Plumbing: where things are in a contour-fmu checkout, its root, the FMUs that `fmu-build`
writes (target/fmu), the demo's output folder (out/), the `ccc-tune` and `contour-cosim`
programs (target/release/), and which Cargo package of the workspace builds a target.

The root is, first found:
1. the folder named by the environment variable CONTOUR_FMU_REPO (an error if it is not a
   checkout);
2. the working directory or the nearest of its parents that is a checkout;
3. the checkout this package is installed from in editable mode.
A checkout is a folder holding a Cargo.toml and python/pyproject.toml of the project
"contour-fmu". Cargo's CARGO_TARGET_DIR, when set, stands for <root>/target, as for cargo.
"""

import os
import tomllib
from pathlib import Path

ENV = "CONTOUR_FMU_REPO"
PROJECT = "contour-fmu"


class RepoNotFound(RuntimeError):
    """No contour-fmu checkout could be found (see the module's docstring)."""


def is_checkout(directory):
    """Whether `directory` is the root of a contour-fmu checkout."""
    directory = Path(directory)
    if not (directory / "Cargo.toml").is_file():
        return False
    try:
        pyproject = tomllib.loads((directory / "python" / "pyproject.toml").read_text())
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        return False
    return pyproject.get("project", {}).get("name") == PROJECT


def find_root(cwd=None):
    """The checkout's root (absolute), or None when there is none (see the docstring).
    Raises RepoNotFound when CONTOUR_FMU_REPO names a folder that is not a checkout."""
    named = os.environ.get(ENV)
    if named:
        root = Path(named).expanduser().resolve()
        if not is_checkout(root):
            raise RepoNotFound(f"{ENV}={named}: not a contour-fmu checkout "
                               "(no Cargo.toml and python/pyproject.toml of contour-fmu there)")
        return root
    start = Path.cwd() if cwd is None else Path(cwd)
    start = start.resolve()
    for directory in (start, *start.parents):
        if is_checkout(directory):
            return directory
    installed = Path(__file__).resolve().parents[2]  # <root>/python/contour_fmu/repo.py
    return installed if is_checkout(installed) else None


def root():
    """find_root(), or RepoNotFound with a hint when there is no checkout."""
    found = find_root()
    if found is None:
        raise RepoNotFound(f"no contour-fmu checkout in {Path.cwd()} or above it: run from the "
                           f"checkout, set {ENV} to its folder, or give the paths explicitly")
    return found


def target_dir():
    """Cargo's target folder: $CARGO_TARGET_DIR, else <root>/target."""
    named = os.environ.get("CARGO_TARGET_DIR")
    return Path(named) if named else root() / "target"


def fmu_dir():
    """Where `cargo run --release -p fmu-build` writes the FMUs."""
    return target_dir() / "fmu"


def out_dir():
    """The demo's output folder."""
    return root() / "out"


def ccc_tune():
    """The release build of the tuner."""
    return target_dir() / "release" / "ccc-tune"


def contour_cosim():
    """The native co-simulation master that contour_fmu.engines.native runs: $CONTOUR_COSIM when
    set, else the checkout's release build."""
    named = os.environ.get("CONTOUR_COSIM")
    return Path(named) if named else target_dir() / "release" / "contour-cosim"


def contour_eval():
    """The release build of the offline evaluation (the ballbar demo's circular test)."""
    return target_dir() / "release" / "contour-eval"


# The workspace crates that hold the cargo targets the Python side runs: the library
# (the FMUs, the dump examples), the tuner (ccc-tune, the PSO examples) and the native
# master (contour-cosim).
LIBRARY_PACKAGE = "contour-fmu"
TUNER_PACKAGE = "contour-tune"
COSIM_PACKAGE = "contour-cosim"
