"""Every model's whole life cycle through the C ABI under valgrind's full memcheck:
instantiate, initialise, step, get / serialise / free / deserialise / set / free the FMU
state, terminate, free (examples/lifecycle.rs). A short run here; the long one (10 000
cycles) is `make leak-check`. Leaks and uninitialised values both count: any memcheck
error fails the run (docs/design/testing.md §6)."""

import shutil
import subprocess

import pytest

from helpers.checkout import REPO, target_dir

CYCLES = 20


@pytest.mark.skipif(shutil.which("valgrind") is None, reason="valgrind is not installed")
def test_life_cycles_of_every_model_leak_nothing():
    subprocess.run(["cargo", "build", "--quiet", "--release", "--example", "lifecycle"],
                   cwd=REPO, check=True)
    program = target_dir() / "release" / "examples" / "lifecycle"
    done = subprocess.run(
        ["valgrind", "--leak-check=full", "--show-leak-kinds=definite,indirect,possible",
         "--errors-for-leak-kinds=definite,indirect,possible", "--undef-value-errors=yes",
         "--track-origins=yes", "--error-exitcode=1", str(program), str(CYCLES)],
        capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr[-4000:]
    assert "ERROR SUMMARY: 0 errors" in done.stderr, done.stderr[-2000:]
    # One line per packaged model (one committed model description each).
    models = len(list((REPO / "modelDescription").glob("*.xml")))
    assert models >= 8
    assert done.stdout.count(f": {CYCLES} cycles") == models, done.stdout
