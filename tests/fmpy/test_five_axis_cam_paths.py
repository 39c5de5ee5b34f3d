"""Five-axis CL data as a CAM system writes it, through the FMUs (issue 22): a pass whose
tool axis tilts through vertical, the same 0.5° beside vertical, a hemisphere raster over
its apex. The planned reference keeps every joint within its limits (checked on the
samples, by differences), and the CCC's maxima of tip and orientation error are below
those without CCC, measured from the reference (contour_fmu.checks.five_axis_truth, the
tracking errors) and from the CL data themselves (brute force here)."""

import numpy as np
import pytest

from contour_fmu.demo import cam_paths
from contour_fmu.checks.five_axis_truth import contour_errors, forward
from contour_fmu.engines.master import five_axis_closed_loop
from contour_fmu.loops.wiring import FIVE_AXIS_JOINTS
from helpers.fmu_slave import Slave

TS = 1e-3
QUANTUM = 2.0 ** -30
# PathInterpolator5X's default joint limits (docs/design/five-axis.md §5.3b).
VMAX = np.array([500, 500, 500, 3, 5], dtype=float)
AMAX = np.array([5000, 5000, 5000, 20, 30], dtype=float)
A_RANGE = (np.radians(-35), np.radians(110))

PATHS = {
    "through vertical": (cam_paths.tilting_pass(0.0), {}),
    "through vertical, A >= 0": (cam_paths.tilting_pass(0.0), {"A.min": 0.0}),
    "0.5 deg beside vertical": (cam_paths.tilting_pass(0.5), {}),
    "dome over its apex": (cam_paths.dome_raster(), {}),
}


def cl_poses(text):
    rows = [list(map(float, line.split("/")[1].split(","))) for line in text.splitlines()]
    poses = np.array(rows)
    axes = poses[:, 3:] / np.linalg.norm(poses[:, 3:], axis=1, keepdims=True)
    return poses[:, :3], axes


def cl_errors(cl_text, measured):
    """Each measured pose's distance from the CL polyline and its axis's angle from the
    slerped CL axis there, over every segment."""
    tips, axes = cl_poses(cl_text)
    ptips, paxes = forward(measured)
    a, b = tips[:-1], tips[1:]
    ab = b - a
    tip_error, orientation_error = [], []
    for p, o in zip(ptips, paxes):
        t = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.einsum("ij,ij->i", ab, ab), 0, 1)
        d = np.linalg.norm(a + t[:, None] * ab - p, axis=1)
        j = int(np.argmin(d))
        u, v, f = axes[j], axes[j + 1], t[j]
        angle = np.arccos(np.clip(np.dot(u, v), -1, 1))
        axis = u if angle < 1e-12 else (np.sin((1 - f) * angle) * u + np.sin(f * angle) * v) / np.sin(angle)
        tip_error.append(d[j])
        orientation_error.append(np.arctan2(np.linalg.norm(np.cross(o, axis)), np.dot(o, axis)))
    return np.array(tip_error), np.array(orientation_error)


def maxima(name, cl_text, runs):
    """(what, no-CCC tip max, no-CCC orientation max, CCC tip max, CCC orientation max)
    for the tracking errors (from each run's reference) and the errors from the CL data;
    `runs` maps "off" and "fuzzy" to (reference, measured). Printed as well."""
    rows = []
    for what, errors in (("tracking", lambda r, m: contour_errors(r, m)),
                         ("from the CL data", lambda r, m: cl_errors(cl_text, m))):
        (off_tip, off_axis), (on_tip, on_axis) = (
            (e.max() for e in errors(*runs[mode])) for mode in ("off", "fuzzy"))
        print(f"{name}, {what}: tip {off_tip * 1e3:.2f} -> {on_tip * 1e3:.2f} um, "
              f"orientation {off_axis * 1e6:.1f} -> {on_axis * 1e6:.1f} urad")
        rows.append((what, off_tip, off_axis, on_tip, on_axis))
    return rows


def planned_duration(fmu_dir, cl, limits):
    s = Slave(str(fmu_dir / "PathInterpolator5X.fmu"))
    s.set(path=str(cl), **limits)
    s.fmu.exitInitializationMode()
    duration = s.reals(["plannedDuration"])[0]
    s.close()
    return duration


@pytest.mark.parametrize("name", list(PATHS))
def test_cam_paths_keep_the_limits_and_the_ccc_does_better_than_none(fmu_dir, tmp_path, name):
    text, limits = PATHS[name]
    cl = tmp_path / "part.cl"
    cl.write_text(text)
    duration = planned_duration(fmu_dir, cl, limits)
    assert duration > 0.5, duration
    runs = {}
    for mode, controller in (("off", {"ccc.enable": False}), ("fuzzy", {})):
        before, _ = five_axis_closed_loop(fmu_dir, path=str(cl), feed=50.0,
                                          stop=duration + 0.1, controller=controller,
                                          interpolator=limits)
        reference = np.column_stack([before[f"interpolator.ref.{j}"] for j in FIVE_AXIS_JOINTS])
        measured = np.column_stack([before[f"plant.pos.{j}"] for j in FIVE_AXIS_JOINTS])
        runs[mode] = (reference, measured)
    reference = runs["off"][0]
    # The reference is the same whatever the controller, and rests at the end.
    assert np.array_equal(reference, runs["fuzzy"][0])
    assert np.array_equal(reference[-1], reference[-2])
    # Every joint within its travel, speed and acceleration, by differences of the samples
    # (the filter's quantum is the only slack).
    a_min = limits.get("A.min", A_RANGE[0])
    assert reference[:, 3].min() >= a_min - QUANTUM and reference[:, 3].max() <= A_RANGE[1]
    velocity = np.abs(np.diff(reference, axis=0)) / TS
    acceleration = np.abs(np.diff(reference, 2, axis=0)) / TS ** 2
    assert np.all(velocity <= VMAX * (1 + 1e-9) + 2 * QUANTUM / TS), velocity.max(axis=0)
    assert np.all(acceleration <= AMAX * (1 + 1e-6) + 4 * QUANTUM / TS ** 2), \
        acceleration.max(axis=0)
    # The planned tip within the tolerance of the CL path, the axis within its tolerance.
    planned_tip, planned_axis = cl_errors(text, reference)
    assert planned_tip.max() <= 0.005 * (1 + 1e-6), planned_tip.max()
    assert planned_axis.max() <= 2e-3 * (1 + 1e-6), planned_axis.max()
    # The CCC beats no CCC, on the tracking errors and on the errors from the CL data.
    for what, off_tip, off_axis, on_tip, on_axis in maxima(name, text, runs):
        assert on_tip < off_tip and on_axis < off_axis, (what, off_tip, on_tip, off_axis, on_axis)
    if name == "through vertical":
        # The branch switches: C does not turn, A goes from +30° to −30°.
        assert np.ptp(reference[:, 4]) < 1e-9
        assert abs(reference[0, 3] + reference[-1, 3]) < 1e-9
    if name == "through vertical, A >= 0":
        assert abs(np.ptp(reference[:, 4]) - np.pi) < 1e-6


def test_a_path_beyond_the_a_travel_is_refused_naming_the_cl_line(fmu_dir, tmp_path):
    cl = tmp_path / "steep.cl"
    cl.write_text("$$ a tool tilted 120 degrees\n" + cam_paths.tilting_pass(0.0, tilt_deg=120.0))
    s = Slave(str(fmu_dir / "PathInterpolator5X.fmu"))
    s.set(path=str(cl))
    with pytest.raises(Exception):
        s.fmu.exitInitializationMode()
    messages = " ".join(s.log.errors())
    # The first GOTO (line 2) tilts 120°: beyond A.max = 110° and A.min = −35°.
    assert "steep.cl:2" in messages, messages
    assert "A would have to be 120.000°" in messages, messages
    assert "outside its travel -35.000° … 110.000°" in messages, messages
    s.close()


@pytest.mark.parametrize("name", ["through vertical", "0.5 deg beside vertical"])
def test_on_a_reference_beyond_the_joints_limits_the_ccc_is_no_worse(fmu_dir, tmp_path, name):
    """At constant feed (accel = 0) the reference flips C by pi in one sample at the pole,
    or swings it at 100 rad/s beside it: far beyond C's 5 rad/s, which ContourCCC5X's
    commands keep. The CCC's maxima stay within 1.1x those without it (plus 1 um and
    10 urad), from the reference and from the CL data (docs/design/five-axis.md §5.4b)."""
    text, _ = PATHS[name]
    cl = tmp_path / "part.cl"
    cl.write_text(text)
    runs = {}
    for mode, controller in (("off", {"ccc.enable": False}), ("fuzzy", {})):
        before, _ = five_axis_closed_loop(fmu_dir, path=str(cl), feed=50.0, stop=1.6,
                                          controller=controller, interpolator={"accel": 0.0})
        reference = np.column_stack([before[f"interpolator.ref.{j}"] for j in FIVE_AXIS_JOINTS])
        measured = np.column_stack([before[f"plant.pos.{j}"] for j in FIVE_AXIS_JOINTS])
        command = np.column_stack([before[f"controller.u.{j}"] for j in FIVE_AXIS_JOINTS])
        # Every command within its joint's speed, whatever the reference asks.
        assert np.all(np.abs(command) <= VMAX * (1 + 1e-12)), np.abs(command).max(axis=0)
        runs[mode] = (reference, measured)
    # C jumps, or swings, at more than ten times its speed.
    assert np.abs(np.diff(runs["off"][0][:, 4])).max() / TS > 10 * VMAX[4]
    for what, off_tip, off_axis, on_tip, on_axis in maxima(f"{name}, constant feed", text, runs):
        assert on_tip <= 1.1 * off_tip + 1e-3, (what, off_tip, on_tip)
        assert on_axis <= 1.1 * off_axis + 10e-6, (what, off_axis, on_axis)
