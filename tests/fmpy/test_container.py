"""Issue 4: the closed loop PathInterpolator2D -> ContourCCC2D <- XYServoPlant packed into
ONE FMU with fmpy's container (fmpy.container_fmu), simulated with fmpy.simulate_fmu and
compared with the Python master (contour_fmu.engines.master) on the same three FMUs.

Coupling scheme of fmpy's container: JACOBI (parallel), not Gauss-Seidel.
How it was established:
- the runtime (container_fmu.so, fmpy's native/container-fmu, Container::doFixedStep)
  calls doStep on every component with the inputs as they are, and only afterwards copies
  all connections (outputs at t_k+1 -> inputs); exitInitializationMode copies them once
  (outputs at t_0). So every component steps over [t_k, t_k+1) on its inputs from t_k,
  whatever the component order and whether "parallelDoStep" is set; the order only says
  in which sequence the instances are called, no value is exchanged in between;
- observed: the container's trajectory equals master.closed_loop(scheme="jacobi") bit for
  bit, while it differs from scheme="gauss-seidel" in the same component order by far more
  (about 1e-3 mm on pos.x with the current FMUs); and reversing the component order in
  container.json gives the identical trajectory, which a Gauss-Seidel scheme could not;
- "parallelDoStep": true is not implemented by fmpy 0.3.32's binary: doStep panics ("not
  yet implemented") and aborts the process (test_container_parallel_do_step, subprocess).

Sampling: simulate_fmu records the outputs once after initialization (t_0) and then after
every doStep, so row k is the state at t_k: rows 0..N-1 pair with master's `before`, rows
1..N with `after`. simulate_fmu's default output interval would be 2 ms here (it doubles
the step until there are at most 1000 steps), so the tests pass output_interval=1 ms.
With 2 ms the container takes two internal 1 ms steps per doStep, which is checked too.
Agreement is exact (0.0 mm) in both cases; the asserted bound is the 1e-9 mm of the issue.
"""

import json
import subprocess
import sys

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.validation import validate_fmu

from contour_fmu.engines.container_build import build_container
from contour_fmu.engines.master import closed_loop

STEP, STOP = 1e-3, 2.0
N = int(round(STOP / STEP))
TOL = 1e-9  # mm
POSITIONS = ("plant.pos.x", "plant.pos.y")
COMPARED = POSITIONS + ("controller.u.x", "controller.u.y", "controller.contourError",
                        "interpolator.ref.x", "interpolator.ref.y")


def circle_error(x, y):
    """Distance (mm) of the points from the paper's circle x = 10 cos(pi t) - 10, y = 10 sin(pi t)."""
    return np.abs(np.hypot(np.asarray(x) + 10.0, y) - 10.0)


@pytest.fixture(scope="module")
def container(fmus, tmp_path_factory):
    return build_container(fmus, tmp_path_factory.mktemp("container"), step=STEP, stop=STOP)


def simulate(fmu, start_values=None, output_interval=STEP):
    return simulate_fmu(str(fmu), stop_time=STOP, output_interval=output_interval,
                        start_values=dict(start_values or {}))


def max_diff(result, before, after, columns=COMPARED, every=1):
    """Largest |container - master| per column over t_0..t_N (row k of `result` is t_k*every)."""
    diffs = {}
    for c in columns:
        master = np.concatenate([before[c][:1], after[c]])[::every]
        assert len(result[c]) == len(master)
        diffs[c] = float(np.abs(result[c] - master).max())
    return diffs


def test_container_validates(container):
    assert validate_fmu(str(container)) == []


def test_container_matches_jacobi_master(container, fmus):
    result = simulate(container)
    assert len(result) == N + 1
    np.testing.assert_allclose(result["time"], np.arange(N + 1) * STEP, rtol=0, atol=1e-12)

    before, after = closed_loop(fmus, stop=STOP, step=STEP, scheme="jacobi")
    jacobi = max_diff(result, before, after)
    print("container vs jacobi master, max |diff| (mm or mm/s):", jacobi)
    assert all(d <= TOL for d in jacobi.values()), jacobi

    # The comparison can tell the schemes apart: Gauss-Seidel in the container's component
    # order (interpolator, controller, plant) is a different trajectory.
    before, after = closed_loop(fmus, stop=STOP, step=STEP, scheme="gauss-seidel")
    gauss_seidel = max_diff(result, before, after, POSITIONS)
    print("container vs gauss-seidel master, max |diff| (mm):", gauss_seidel)
    assert max(gauss_seidel.values()) > 1e-6


def test_container_component_order_does_not_matter(container, fmus, tmp_path):
    reversed_order = build_container(fmus, tmp_path, step=STEP, stop=STOP,
                                     order=("plant", "controller", "interpolator"))
    a, b = simulate(container), simulate(reversed_order)
    for c in COMPARED:
        np.testing.assert_array_equal(a[c], b[c], err_msg=c)


def test_container_two_internal_steps_per_communication_step(container, fmus):
    """A 2 ms communication step: the container takes two of its fixed 1 ms steps."""
    result = simulate(container, output_interval=2 * STEP)
    assert len(result) == N // 2 + 1
    before, after = closed_loop(fmus, stop=STOP, step=STEP, scheme="jacobi")
    diffs = max_diff(result, before, after, every=2)
    assert all(d <= TOL for d in diffs.values()), diffs


def test_container_contour_error_with_and_without_ccc(container):
    """Through the container's parameter controller.ccc.enable: the fuzzy CCC keeps the
    tool within 5 um of the circle, the uncoupled axes leave it more than 30 um off."""
    errors = {}
    for enable in (True, False):
        result = simulate(container, {"controller.ccc.enable": enable})
        errors[enable] = circle_error(result["plant.pos.x"], result["plant.pos.y"]).max()
        # the contour gains the controller reports show that the parameter reached it
        assert (np.abs(result["controller.ccc.Kp"]).max() > 0) == enable
    print(f"max contour error: fuzzy CCC {errors[True] * 1e3:.3f} um, "
          f"no CCC {errors[False] * 1e3:.3f} um")
    assert errors[True] < 5e-3
    assert errors[False] > 30e-3
    # and the run did follow the whole circle: the reference is back at its start
    result = simulate(container)
    assert bool(result["interpolator.done"][-1])
    assert abs(result["interpolator.ref.x"][-1]) < 1e-9 and abs(result["interpolator.ref.y"][-1]) < 1e-9


PARALLEL_RUN = """
import json
import numpy as np
from fmpy import simulate_fmu
from contour_fmu.engines.container_build import build_container
fmu = build_container({fmus!r}, {work!r}, parallel_do_step=True)
r = simulate_fmu(str(fmu), stop_time={stop!r}, output_interval={step!r})
print(json.dumps({{c: r[c].tolist() for c in ("plant.pos.x", "plant.pos.y")}}))
"""


def test_container_parallel_do_step(container, fmus, tmp_path):
    """parallelDoStep=true would step the components on a thread pool: still Jacobi, so the
    same trajectory. fmpy 0.3.32's runtime aborts instead (a Rust panic, "not yet
    implemented", in fmi2DoStep), hence the subprocess and the xfail."""
    code = PARALLEL_RUN.format(fmus=str(fmus), work=str(tmp_path), stop=STOP, step=STEP)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    if done.returncode != 0:
        if "not yet implemented" in done.stderr:
            pytest.xfail("fmpy's container runtime does not implement parallelDoStep")
        pytest.fail(done.stderr[-2000:])
    parallel = json.loads(done.stdout.strip().splitlines()[-1])
    sequential = simulate(container)
    for c in POSITIONS:
        assert np.abs(np.array(parallel[c]) - sequential[c]).max() <= TOL
