"""Issue 4: the closed loop PathInterpolator2D -> ContourCCC2D <- XYServoPlant in libcosim
(libcosimpy: three CosimLocalSlave, six connect_real_variables, 1 ms fixed step), run in a
subprocess (contour_fmu.engines.libcosim) and compared with
contour_fmu.engines.master.closed_loop(scheme="jacobi").

libcosim's fixed-step algorithm steps all slaves from t_k on the inputs they hold and then
transfers outputs to inputs at the step boundary t_k+1: the Jacobi scheme of the master.
Time alignment: libcosim counts integer nanoseconds; its time-series observer samples after
each step, sample n (step number n, n = 1..N) at n * 1_000_000 ns being the state at t_n,
which is master's after[n - 1].

Agreement is not bit for bit (about 4e-14 mm on the positions): libcosim calls doStep with
t_k = k * 1e6 / 1e9 and h = t_k+1 - t_k, time points converted from integer ns, so h differs
from 1e-3 in its last bits at some steps, and the plant's exact discretisation depends on h.
Replaying the Jacobi loop with those t_k and h reproduces libcosim exactly (checked by hand;
the master always passes k * step and step)."""

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from contour_fmu.engines.master import closed_loop
from contour_fmu.checks.reference_paths import paper_circle_distance as circle_error

STEP_NS, STEPS = 1_000_000, 2000  # 1 ms for 2 s
STEP, STOP = STEP_NS * 1e-9, STEPS * STEP_NS * 1e-9
POSITIONS = ("plant.pos.x", "plant.pos.y")
TOL = 1e-6  # mm


def run_libcosim(fmus, assignments=()):
    done = subprocess.run(
        [sys.executable, "-m", "contour_fmu.engines.libcosim", str(fmus), str(STEP_NS), str(STEPS),
         *assignments],
        capture_output=True, text=True, timeout=120,
    )
    assert done.returncode == 0, f"libcosim run failed ({done.returncode}):\n{done.stderr[-3000:]}"
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("ccc", [True, False], ids=["fuzzy-ccc", "no-ccc"])
def test_libcosim_closed_loop_matches_jacobi_master(fmus, ccc):
    result = run_libcosim(fmus, [] if ccc else ["controller.ccc.enable=false"])

    # the run reached 2 s, one sample per step, at exact integer-ns step boundaries
    assert result["time_ns"] == STEPS * STEP_NS
    assert result["steps"] == list(range(1, STEPS + 1))
    assert result["time_ns_points"] == [n * STEP_NS for n in range(1, STEPS + 1)]

    _, after = closed_loop(fmus, stop=STOP, step=STEP, scheme="jacobi",
                           controller={} if ccc else {"ccc.enable": False})
    assert len(after) == STEPS
    np.testing.assert_allclose(after["time"], np.array(result["time_ns_points"]) * 1e-9, rtol=0, atol=1e-12)
    series = {k: np.array(v) for k, v in result["series"].items()}
    diffs = {c: float(np.abs(series[c] - after[c]).max()) for c in series}
    print(f"libcosim vs jacobi master (ccc={ccc}), max |diff| (mm or mm/s):", diffs)
    for c in POSITIONS:
        assert diffs[c] <= TOL, (c, diffs[c])
    # one step of misalignment would be about feed * step = 0.03 mm off
    shifted = max(float(np.abs(series[c][1:] - after[c][:-1]).max()) for c in POSITIONS)
    assert shifted > 1e3 * TOL

    # the run completed the circle: reference back at its start, interpolator done, the
    # tool on the circle and, lagging by its following error (~1.1 mm at 31.4 mm/s and
    # Kv 28.5/s), close to the end having swept nearly 2 pi around the centre (-10, 0)
    last = result["last"]
    assert last["interpolator.done"] is True
    assert math.hypot(last["interpolator.ref.x"], last["interpolator.ref.y"]) < 1e-9
    x, y = series["plant.pos.x"], series["plant.pos.y"]
    assert (last["plant.pos.x"], last["plant.pos.y"]) == (x[-1], y[-1])
    assert math.hypot(x[-1], y[-1]) < 1.5
    swept = np.unwrap(np.arctan2(y, x + 10.0))[-1]  # from angle 0 at the start (0, 0)
    assert 2 * math.pi - 0.2 < swept <= 2 * math.pi
    error = circle_error(x, y).max()
    print(f"max contour error (ccc={ccc}): {error * 1e3:.3f} um")
    if ccc:
        assert error < 5e-3
    else:
        assert error > 30e-3
