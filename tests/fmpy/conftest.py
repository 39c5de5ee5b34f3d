"""Fixtures for the FMU tests: the packaged FMUs, built once per session by fmu-build."""

import shutil
import subprocess

import pytest

from contour_fmu.engines import native
from contour_fmu.loops.wiring import LOOPS
from contour_fmu.repo import COSIM_PACKAGE
from helpers.checkout import REPO, target_dir


@pytest.fixture(scope="session")
def fmu_dir():
    """Runs `cargo run --release -p fmu-build` (a no-op rebuild when nothing changed), and
    builds contour-cosim, which the campaigns' default engine runs."""
    for command in (["cargo", "run", "--quiet", "--release", "-p", "fmu-build"],
                    ["cargo", "build", "--quiet", "--release", "-p", COSIM_PACKAGE]):
        done = subprocess.run(command, cwd=REPO, capture_output=True, text=True)
        if done.returncode != 0:
            raise RuntimeError(f"{' '.join(command)} failed:\n{done.stdout}\n{done.stderr}")
    return target_dir() / "fmu"


@pytest.fixture(scope="session")
def cosim(fmu_dir):
    """The contour-cosim program (built with the FMUs)."""
    return native.program()


@pytest.fixture(scope="session")
def xy_plant_fmu(fmu_dir):
    return str(fmu_dir / "XYServoPlant.fmu")


@pytest.fixture(scope="module")
def fmus(fmu_dir, tmp_path_factory):
    """A private copy of the FMUs of both closed loops, so that an outside engine (libcosim,
    ecos, the container) and the fmpy master run the same build even if fmu-build rewrites
    target/fmu meanwhile."""
    directory = tmp_path_factory.mktemp("fmus")
    for loop in LOOPS.values():
        for file in loop.units.values():
            shutil.copy2(fmu_dir / file, directory / file)
    return directory
