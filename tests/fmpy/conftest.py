"""Fixtures for the FMU tests: the packaged FMUs, built once per session by fmu-build."""

import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def target_dir():
    return Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))


@pytest.fixture(scope="session")
def fmu_dir():
    """Runs `cargo run --release -p fmu-build` (a no-op rebuild when nothing changed)."""
    done = subprocess.run(
        ["cargo", "run", "--quiet", "--release", "-p", "fmu-build"],
        cwd=REPO,
        capture_output=True,
        text=True,
    )
    if done.returncode != 0:
        raise RuntimeError(f"fmu-build failed:\n{done.stdout}\n{done.stderr}")
    return target_dir() / "fmu"


@pytest.fixture(scope="session")
def xy_plant_fmu(fmu_dir):
    return str(fmu_dir / "XYServoPlant.fmu")
