"""The Rust five-axis kinematics (contour-core/src/kinematics.rs) against scipy's rotations.

Python side, written from the machine description in the docs of contour-core/src/kinematics.rs and
docs/design/five-axis.md §5.1, not from the Rust formulas: the workpiece sits on a C platter that
turns about the z direction through the C pivot c; the platter rides on an A cradle that
tilts about the x direction through the A pivot a. A rotation by R about an axis through
the point p moves x to R·(x − p) + p, so the table carries a workpiece point w to

    P = T(w) = about(a, Rx(A)) ∘ about(c, Rz(C)) (w),

the rotations built with `scipy.spatial.transform.Rotation` (rotation vectors A·e_x and
C·e_z; the product is cross-checked against scipy's extrinsic Euler angles). The tool tip
at machine position P = (X, Y, Z) touches the workpiece at w = T⁻¹(P); the tool axis, the
machine's +z, is seen from the workpiece as R_T⁻¹·e_z.

Rust side: `examples/five_axis_dump.rs kinematics SEED N` prints pseudo-random joints
(X, Y, Z in ±200 mm, A in [0, 1.5] rad, C in ±7 rad) with pivots whose every component is
nonzero (so the components the kinematics must ignore, a_x and c_z, are set too), the
forward pose, the inverse of that pose (previous C = true C ± 0.5 rad) and the analytic
Jacobian. Checked: the pose to 1e-12, the joints back from the inverse (C on the true
turn, not modulo 2π), the vertical tool (A = 0: the previous C is held), the Jacobian
against central differences of the scipy map. Near-vertical tools (A = 1e-2 .. 1e-8 rad)
are held to the same accuracy in an expected-failure test: the inverse is not yet that
accurate there.
"""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

SEED = 20240611
COUNT = 400
EZ = np.array([0.0, 0.0, 1.0])


def table(a_angle, c_angle, a_pivot, c_pivot):
    """The table as a rigid motion workpiece -> machine: (rotation, translation)."""
    tilt = Rotation.from_rotvec(a_angle * np.array([1.0, 0.0, 0.0]))
    turn = Rotation.from_rotvec(c_angle * EZ)
    a, c = np.asarray(a_pivot, float), np.asarray(c_pivot, float)
    # w -> turn(w - c) + c, then x -> tilt(x - a) + a.
    rotation = tilt * turn
    translation = tilt.apply(c - turn.apply(c) - a) + a
    return rotation, translation


def forward(q, a_pivot, c_pivot):
    """Tool tip and tool axis in the workpiece frame for joints q = (X, Y, Z, A, C)."""
    rotation, translation = table(q[3], q[4], a_pivot, c_pivot)
    back = rotation.inv()
    return back.apply(np.asarray(q[:3], float) - translation), back.apply(EZ)


def pose_vector(q, a_pivot, c_pivot):
    tip, axis = forward(q, a_pivot, c_pivot)
    return np.concatenate([tip, axis])


def unpack(case):
    return (np.array(case["joints"]), np.array(case["a_pivot"]), np.array(case["c_pivot"]))


def length_scale(case):
    """The largest coordinate (mm) of the case: rounding in the tip scales with it."""
    values = np.concatenate([case["joints"][:3], case["tip"], case["a_pivot"], case["c_pivot"]])
    return max(1.0, np.abs(values).max())


@pytest.fixture(scope="module")
def dump(rust_json):
    run = rust_json("five_axis_dump", "kinematics", SEED, COUNT)
    assert run["seed"] == SEED and len(run["cases"]) == COUNT
    return run


def test_cases_cover_the_requested_ranges(dump):
    q = np.array([c["joints"] for c in dump["cases"]])
    assert np.abs(q[:, :3]).max() <= 200.0 and np.abs(q[:, :3]).max() > 190.0
    assert q[:, 3].min() >= 0.0 and q[:, 3].max() <= 1.5 and q[:, 3].max() > 1.45
    assert np.abs(q[:, 4]).max() <= 7.0 and q[:, 4].min() < -6.5 and q[:, 4].max() > 6.5
    # Several C values beyond ±π, so the unwrapping is exercised.
    assert (np.abs(q[:, 4]) > np.pi).sum() > COUNT // 4
    pivots = np.array([c["a_pivot"] + c["c_pivot"] for c in dump["cases"]])
    assert np.abs(pivots).min() >= 5.0


def test_euler_angles_and_rotation_vectors_agree():
    # The workpiece-from-machine rotation two ways with scipy: the inverse of the table
    # motion built from rotation vectors, and extrinsic Euler angles (first −A about x,
    # then −C about z). Guards the Python model's own composition order.
    rng = np.random.default_rng(3)
    for a_angle, c_angle in zip(rng.uniform(0.0, 1.5, 50), rng.uniform(-7.0, 7.0, 50)):
        rotation, _ = table(a_angle, c_angle, np.zeros(3), np.zeros(3))
        euler = Rotation.from_euler("xz", [-a_angle, -c_angle])
        assert np.abs(rotation.inv().as_matrix() - euler.as_matrix()).max() < 1e-15
        # The tool axis in closed form: tilted by A away from the z axis, turned by C.
        axis = rotation.inv().apply(EZ)
        expect = [np.sin(c_angle) * np.sin(a_angle), np.cos(c_angle) * np.sin(a_angle), np.cos(a_angle)]
        assert np.abs(axis - expect).max() < 1e-15


def test_forward_pose_matches_scipy(dump):
    worst_tip = worst_axis = 0.0
    for case in dump["cases"] + dump["vertical"] + dump["near_vertical"]:
        q, a, c = unpack(case)
        tip, axis = forward(q, a, c)
        worst_tip = max(worst_tip, np.abs(np.array(case["tip"]) - tip).max())
        worst_axis = max(worst_axis, np.abs(np.array(case["axis"]) - axis).max())
        assert abs(np.linalg.norm(case["axis"]) - 1.0) < 1e-15
    assert worst_tip <= 1e-12, f"tip deviation {worst_tip:.3e} mm"
    assert worst_axis <= 1e-12, f"axis deviation {worst_axis:.3e}"
    print(f"forward: max |tip - scipy| = {worst_tip:.2e} mm, max |axis - scipy| = {worst_axis:.2e}")


def inverse_errors(case, key="inverse"):
    """(joint-A/C error rad, joint-XYZ error relative to the case's length scale,
    pose round-trip tip error mm, axis error) of the Rust inverse."""
    q, a, c = unpack(case)
    back = np.array(case[key])
    angles = np.abs(back[3:] - q[3:]).max()
    linear = np.abs(back[:3] - q[:3]).max() / length_scale(case)
    tip, axis = forward(back, a, c)
    return angles, linear, np.abs(tip - case["tip"]).max(), np.abs(axis - case["axis"]).max()


def test_inverse_returns_the_joints(dump):
    worst = np.zeros(4)
    worst_mm = 0.0
    for case in dump["cases"]:
        assert case["inverse"] is not None
        # C comes back on the true turn (|noise| < π), not merely modulo 2π, and A on the
        # A ≥ 0 branch: the joints themselves, not just an equivalent set.
        errors = inverse_errors(case)
        worst = np.maximum(worst, errors)
        worst_mm = max(worst_mm, np.abs(np.array(case["inverse"])[:3] - case["joints"][:3]).max())
        # The axis need not be unit: scaled by 3.7 it gives the same joints.
        scaled = np.array(case["inverse_scaled_axis"])
        assert np.abs(scaled - np.array(case["inverse"])).max() <= 1e-12 * length_scale(case)
    angles, linear, tip, axis = worst
    assert angles <= 1e-12, f"A/C back to {angles:.3e} rad"
    assert linear <= 1e-12, f"X/Y/Z back to {linear:.3e} of the length scale"
    # forward(inverse(pose)) = pose.
    assert tip <= 1e-12 and axis <= 1e-12, (tip, axis)
    print(
        f"inverse: max A/C error {angles:.2e} rad, X/Y/Z {linear:.2e} relative ({worst_mm:.2e} mm), "
        f"round-trip tip {tip:.2e} mm, axis {axis:.2e}"
    )


def test_vertical_tool_holds_the_previous_c(dump):
    for case in dump["vertical"]:
        q, a, c = unpack(case)
        assert q[3] == 0.0
        back = np.array(case["inverse"])
        assert back[3] == 0.0
        assert back[4] == case["previous_c"]
        tip, axis = forward(back, a, c)
        assert np.abs(tip - case["tip"]).max() <= 1e-12
        assert np.abs(axis - EZ).max() <= 1e-15
        # C no longer moves the tool axis: the Jacobian loses exactly that rank.
        jac = np.array(case["jacobian"])
        assert np.abs(jac[3:, 4]).max() == 0.0
        assert np.linalg.matrix_rank(jac, tol=1e-9) == 4


def test_inverse_is_accurate_near_the_vertical(dump):
    # Same criteria as for the random cases, for A = 1e-2 .. 1e-8 rad (sin A still above
    # the inverse's vertical threshold 1e-9, so C is taken from the tool axis).
    failures = []
    for case in dump["near_vertical"]:
        angles, linear, tip, axis = inverse_errors(case)
        if max(angles, linear, tip, axis) > 1e-12:
            failures.append(
                f"A={case['joints'][3]:.0e}: A/C {angles:.1e} rad, XYZ {linear:.1e} rel, "
                f"round-trip axis {axis:.1e}"
            )
    assert not failures, "; ".join(failures)


def central_differences(q, a, c):
    """∂(tip, axis)/∂q of the scipy forward map, 6 × 5."""
    jac = np.empty((6, 5))
    for k in range(5):
        # Linear joints enter linearly: a large step only shrinks the rounding. The angles
        # balance truncation (h²) against rounding (eps·|tip|/h).
        h = 1e-3 if k < 3 else 1e-5
        qp, qm = q.copy(), q.copy()
        qp[k] += h
        qm[k] -= h
        jac[:, k] = (pose_vector(qp, a, c) - pose_vector(qm, a, c)) / (2.0 * h)
    return jac


def test_jacobian_matches_central_differences(dump):
    worst = 0.0
    for case in dump["cases"] + dump["near_vertical"]:
        q, a, c = unpack(case)
        jac = np.array(case["jacobian"])
        fd = central_differences(q, a, c)
        worst = max(worst, (np.abs(jac - fd) / np.maximum(1.0, np.abs(fd))).max())
        # The structure the physics fixes: the tool axis depends on A and C only, and
        # C turns about the workpiece z axis, so it never changes the tip's z.
        assert np.abs(jac[3:, :3]).max() == 0.0
        assert jac[2, 4] == 0.0 and jac[5, 4] == 0.0
    assert worst <= 1e-6, f"Jacobian vs central differences: {worst:.3e} relative"
    ranks = [np.linalg.matrix_rank(np.array(c["jacobian"]), tol=1e-9) for c in dump["cases"]]
    assert min(ranks) == 5
    print(f"jacobian: max relative deviation from central differences {worst:.2e}")
