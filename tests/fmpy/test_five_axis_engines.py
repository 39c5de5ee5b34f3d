"""The five-axis loop PathInterpolator5X -> ContourCCC5X <- FiveAxisPlant in the three outside
engines of the two-axis loop: libcosim and ecos (subprocesses running
contour_fmu.engines.libcosim / .ecos with --loop five_axis) and fmpy's container
FMU (contour_fmu.engines.container_build, loop="five_axis"). Each is compared with
contour_fmu.engines.master.five_axis_closed_loop(scheme="jacobi") on the same FMUs, as
test_libcosim_closed_loop, test_ecospy_closed_loop and test_container do for the two-axis
loop: all three engines step every FMU on the inputs from t_k and exchange values at the
step boundaries, so one Jacobi run of the master is the reference for all of them.

Time alignment, as there: libcosim's sample n and ecos' post-step sample n are the state at
t_n, the master's after[n - 1]; the container's row k (simulate_fmu records t_0 too) is the
state at t_k, before[0] then after[k - 1].

The plant starts at the path's start in every engine through its pos0.* parameters, read
from the master's interpolator at t_0: no engine can connect an output onto a fixed
parameter once, as the master's FIVE_AXIS_PATH_START does.
"""

import json
import subprocess
import sys

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.validation import validate_fmu

from contour_fmu.engines.container_build import build_container
from contour_fmu.engines.master import five_axis_closed_loop
from contour_fmu.loops.wiring import FIVE_AXIS_JOINTS, FIVE_AXIS_PATH_START

PATH = "tilted_helix"
STEP_NS, STEPS = 1_000_000, 500  # 1 ms for 0.5 s
STEP, STOP = STEP_NS * 1e-9, STEPS * STEP_NS * 1e-9
TOL = 1e-9  # mm, rad, mm/s, rad/s
POSITIONS = tuple(f"plant.pos.{j}" for j in FIVE_AXIS_JOINTS)
COMPARED = (POSITIONS + tuple(f"interpolator.ref.{j}" for j in FIVE_AXIS_JOINTS)
            + tuple(f"controller.u.{j}" for j in FIVE_AXIS_JOINTS) + ("controller.contourError.tip",))


@pytest.fixture(scope="module")
def jacobi(fmus):
    """The master's Jacobi run: (before, after)."""
    return five_axis_closed_loop(fmus, path=PATH, stop=STOP, step=STEP, scheme="jacobi")


@pytest.fixture(scope="module")
def gauss_seidel(fmus):
    """The master's Gauss-Seidel run, a different trajectory the comparison must tell apart."""
    return five_axis_closed_loop(fmus, path=PATH, stop=STOP, step=STEP, scheme="gauss-seidel")


@pytest.fixture(scope="module")
def path_start(jacobi):
    """The plant's pos0.* = the interpolator's ref.* at t_0, as "plant.pos0.X" -> value."""
    before, _ = jacobi
    return {f"{dst}.{inp}": float(before[f"{src}.{out}"][0]) for src, out, dst, inp in FIVE_AXIS_PATH_START}


def run_engine(module, fmus, step, path_start):
    """Runs `python -m contour_fmu.<module> --loop five_axis` on the tilted helix; its JSON."""
    assignments = [f"interpolator.path={PATH}"] + [f"{k}={v!r}" for k, v in path_start.items()]
    done = subprocess.run(
        [sys.executable, "-m", f"contour_fmu.{module}", "--loop", "five_axis", str(fmus), step,
         str(STEPS), *assignments],
        capture_output=True, text=True, timeout=120,
    )
    assert done.returncode == 0, f"{module} failed ({done.returncode}):\n{done.stderr[-3000:]}"
    return json.loads(done.stdout.strip().splitlines()[-1])


def assert_matches_jacobi(engine, series, jacobi_rows, gauss_seidel_rows):
    """`series` (column -> samples) equals the Jacobi master's rows to TOL on COMPARED, is
    farther from the Gauss-Seidel master's rows and from itself shifted by one step, and
    shows a loop that moved."""
    series = {c: np.asarray(v) for c, v in series.items()}
    diffs = {c: float(np.abs(series[c] - jacobi_rows[c]).max()) for c in series}
    print(f"{engine} vs jacobi master, max |diff| (mm, rad, mm/s, rad/s):", diffs)
    for c in COMPARED:
        assert diffs[c] <= TOL, (c, diffs[c])
    gs = max(float(np.abs(series[c] - gauss_seidel_rows[c]).max()) for c in POSITIONS)
    shifted = max(float(np.abs(series[c][1:] - jacobi_rows[c][:-1]).max()) for c in POSITIONS)
    print(f"{engine}: vs gauss-seidel master {gs:.3g}, vs itself one step later {shifted:.3g}")
    assert gs > 1e3 * TOL
    assert shifted > 1e3 * TOL
    # The run is not trivial: the tool travelled and the table turned.
    assert np.ptp(series["plant.pos.X"]) > 10.0
    assert np.ptp(series["plant.pos.C"]) > 0.5


def test_libcosim_five_axis_loop_matches_jacobi_master(fmus, jacobi, gauss_seidel, path_start):
    result = run_engine("engines.libcosim", fmus, str(STEP_NS), path_start)
    assert result["time_ns"] == STEPS * STEP_NS
    assert result["steps"] == list(range(1, STEPS + 1))
    assert result["time_ns_points"] == [n * STEP_NS for n in range(1, STEPS + 1)]
    _, after = jacobi
    np.testing.assert_allclose(after["time"], np.array(result["time_ns_points"]) * 1e-9, rtol=0, atol=1e-12)
    assert_matches_jacobi("libcosim", result["series"], after, gauss_seidel[1])
    last = result["last"]
    for c in POSITIONS:
        assert last[c] == result["series"][c][-1]
    assert last["interpolator.done"] is False  # 0.5 s is a part of the helix


def test_ecos_five_axis_loop_matches_jacobi_master(fmus, jacobi, gauss_seidel, path_start):
    result = run_engine("engines.ecos", fmus, repr(STEP), path_start)
    before, after = jacobi
    np.testing.assert_allclose(result["time"], after["time"], rtol=0, atol=1e-10)
    # After init, the outputs are the master's at t_0: the plant stands at the path's start.
    for name, value in result["initial"].items():
        assert value == before[name][0], (name, value, before[name][0])
    assert_matches_jacobi("ecos", result["series"], after, gauss_seidel[1])


def test_container_five_axis_loop_matches_jacobi_master(fmus, jacobi, gauss_seidel, path_start, tmp_path):
    container = build_container(fmus, tmp_path, step=STEP, stop=STOP, loop="five_axis")
    assert validate_fmu(str(container)) == []
    result = simulate_fmu(str(container), stop_time=STOP, output_interval=STEP,
                          start_values={"interpolator.path": PATH, **path_start})
    assert len(result) == STEPS + 1
    np.testing.assert_allclose(result["time"], np.arange(STEPS + 1) * STEP, rtol=0, atol=1e-12)

    def rows(run):
        """t_0..t_N of a master run, as the container records them."""
        before, after = run
        return {c: np.concatenate([before[c][:1], after[c]]) for c in after.dtype.names}

    master = rows(jacobi)
    series = {c: result[c] for c in master if c != "time"}
    assert_matches_jacobi("container", series, master, rows(gauss_seidel))
