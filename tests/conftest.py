"""Fixtures shared by tests/reference and tests/fmpy.

The Rust library is reached through small example programs (`examples/*.rs`) that print
their results as JSON; the Python side recomputes the same quantities with an outside
library (geomdl, scikit-fuzzy, scipy, fmpy) and the test compares the two.
"""

import json
import os
import subprocess
from pathlib import Path

import pytest

from contour_fmu.repo import LIBRARY_PACKAGE

REPO = Path(__file__).resolve().parents[1]


def _cargo_example(name, *args, package=LIBRARY_PACKAGE):
    cmd = ["cargo", "run", "--quiet", "--release", "-p", package, "--example", name, "--", *map(str, args)]
    done = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True, env=os.environ.copy())
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{done.stderr}")
    return done.stdout


@pytest.fixture(scope="session")
def rust_json():
    """Run `cargo run -p PACKAGE --example NAME -- ARGS` (the library's crate unless
    `package` says otherwise) and parse its standard output as JSON."""

    def run(name, *args, package=LIBRARY_PACKAGE):
        return json.loads(_cargo_example(name, *args, package=package))

    return run
