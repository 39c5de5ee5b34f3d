"""The Rust closed loop (contour-core/src/sim/) against an independent scipy model of the same loop.

Python side, written from docs/design/two-axis.md §4.2/4.5 and not from the Rust code: each axis in motor
coordinates (angle theta, speed omega, drive integrator z),

    omega_cmd = v * 2 pi / lead
    i         = Kvp (omega_cmd - omega) + Kvi z,    z' = omega_cmd - omega
    J omega'  = CT i - B omega,                     theta' = omega
    x         = theta * lead / (2 pi)

integrated by scipy's `solve_ivp` (DOP853, rtol = atol = 1e-12) over each sample interval
with the velocity command held, and a P position loop v = Kpp (r - x) per axis (Kpp =
28.5 1/s) closed every Ts = 1 ms on the paper's circle x = 10 cos(pi t) - 10,
y = 10 sin(pi t), sampled analytically at t_k = k Ts for 2 s. The Rust side (plant in
screw coordinates, exact matrix-exponential discretisation; the built-in `circle` at
10 pi mm/s) comes from `examples/closed_loop_dump.rs`.

A third case adds a fixed-gain PI cross-coupled correction (Kp = 100, Ki = 5000) along
the exact circle normal. The Rust controller uses the free-curve estimator, which on a
circle returns the exact radial error, so the two loops must again coincide.
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

TS = 1e-3
KPP = 28.5
CENTRE = np.array([-10.0, 0.0])
RADIUS = 10.0
STEPS = 2000  # samples k = 0 .. 2000 (t = 0 .. 2 s)

PAPER_AXIS = dict(J=0.015, B=1.2, CT=0.57, lead=10.0, Kvp=8.26, Kvi=661.0)


def axes(plant):
    y = dict(PAPER_AXIS)
    if plant == "mismatched":
        y["J"] *= 1.5
    return [dict(PAPER_AXIS), y]


def reference(t):
    a = math.pi * t
    return np.array([10.0 * math.cos(a) - 10.0, 10.0 * math.sin(a)])


def rhs(params, v):
    """Right-hand side of both axes, state (theta, omega, z) per axis, commands v held."""

    def f(_t, s):
        out = np.empty(6)
        for a, p in enumerate(params):
            theta, omega, z = s[3 * a : 3 * a + 3]
            omega_cmd = v[a] * 2.0 * math.pi / p["lead"]
            current = p["Kvp"] * (omega_cmd - omega) + p["Kvi"] * z
            out[3 * a] = omega
            out[3 * a + 1] = (p["CT"] * current - p["B"] * omega) / p["J"]
            out[3 * a + 2] = omega_cmd - omega
        return out

    return f


def scipy_loop(plant, ccc_gains=None):
    """Closed loop in scipy: the actual positions at t_k and the commands."""
    params = axes(plant)
    state = np.zeros(6)
    integral = 0.0
    actual, commands = [], []
    for k in range(STEPS + 1):
        t = k * TS
        pos = np.array([state[3 * a] * params[a]["lead"] / (2.0 * math.pi) for a in range(2)])
        v = KPP * (reference(t) - pos)
        if ccc_gains is not None:
            radial = pos - CENTRE
            rho = np.linalg.norm(radial)
            eps = rho - RADIUS  # counter-clockwise circle: positive outside (right of travel)
            normal = -radial / rho
            integral += eps * TS
            v = v + normal * (ccc_gains[0] * eps + ccc_gains[1] * integral)
        actual.append(pos)
        commands.append(v)
        if k < STEPS:
            sol = solve_ivp(rhs(params, v), (t, t + TS), state, method="DOP853", rtol=1e-12, atol=1e-12)
            assert sol.success
            state = sol.y[:, -1]
    return np.array(actual), np.array(commands)


def contour_error(points):
    """Signed distance to the circle (positive outside), computed here from the geometry."""
    return np.hypot(points[:, 0] - CENTRE[0], points[:, 1] - CENTRE[1]) - RADIUS


def rust_run(rust_json, plant, mode):
    run = rust_json("closed_loop_dump", "circle", plant, mode)
    assert run["ts"] == TS and abs(run["feed"] - 10.0 * math.pi) < 1e-12
    assert all(g["kp"] == KPP and g["ki"] == 0.0 and g["kd"] == 0.0 for g in run["axis"])
    assert run["metrics"]["divergence"] is None
    trace = run["trace"]
    assert len(trace["t"]) == STEPS + 1
    return run, trace


@pytest.mark.parametrize("plant", ["paper", "mismatched"])
def test_uncoupled_loop_matches_scipy(rust_json, plant):
    run, trace = rust_run(rust_json, plant, "off")
    if plant == "mismatched":
        assert run["plant"]["y"]["inertia"] == pytest.approx(1.5 * PAPER_AXIS["J"], rel=1e-15)
    t = np.array(trace["t"])
    assert np.allclose(t, np.arange(STEPS + 1) * TS, rtol=0, atol=1e-15)
    # The interpolator reproduces the paper's time law.
    ref = np.array([reference(tk) for tk in t])
    assert np.abs(np.array(trace["reference"]) - ref).max() < 1e-9

    actual, commands = scipy_loop(plant)
    rust_actual = np.array(trace["actual"])
    deviation = np.abs(rust_actual - actual).max()
    assert deviation < 1e-6, f"max position deviation {deviation} mm"
    assert np.abs(np.array(trace["u"]) - commands).max() < 1e-4  # Kpp * 1e-6 plus margin

    err = contour_error(actual)
    assert np.abs(np.array(trace["true_error"]) - err).max() < 1e-6
    max_err = np.abs(err).max()
    assert 0.03 < max_err < 0.07, f"max contour error {max_err} mm"
    assert run["metrics"]["max_abs_error"] == pytest.approx(max_err, abs=1e-6)
    assert run["metrics"]["mean_abs_error"] == pytest.approx(np.abs(err).mean(), abs=1e-6)
    # The lag puts the table inside the circle: negative (left of travel) in steady state.
    assert (err[200:] < 0).all()
    print(f"{plant}: max |scipy - rust| = {deviation:.3e} mm, max contour error {max_err * 1e3:.2f} um")


def test_fixed_gain_ccc_matches_scipy(rust_json):
    run, trace = rust_run(rust_json, "paper", "fixed")
    actual, _ = scipy_loop("paper", ccc_gains=(100.0, 5000.0))
    deviation = np.abs(np.array(trace["actual"]) - actual).max()
    assert deviation < 1e-6, f"max position deviation {deviation} mm"
    err = np.abs(contour_error(actual))
    # docs/design/two-axis.md §4.2: the PI CCC leaves ~0.08 um once the start-up transient is over.
    assert err[200:].max() < 0.5e-3
    assert err.max() < 0.2 * 0.03
    assert run["metrics"]["max_abs_error"] == pytest.approx(err.max(), abs=1e-6)
    print(f"fixed CCC: max |scipy - rust| = {deviation:.3e} mm, settled max {err[200:].max() * 1e3:.3f} um")
