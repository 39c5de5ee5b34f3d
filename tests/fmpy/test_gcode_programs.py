"""G-code beyond the XY table's, through the FMUs (issue 41): a profile under cutter radius
compensation (G41 D1) on the XY table, and a three-axis program (a thread-milling helix, a
ramp, a G18 arc) on the five-axis machine with its tool axis vertical. Each is judged
against the test's own geometry (the tool centre's offset path written out by hand, the
helices as fine chords computed here), and the CCC's largest true error is below the one
without it."""

import numpy as np
import pytest

from contour_fmu.checks.five_axis_truth import forward
from contour_fmu.engines.master import closed_loop, five_axis_closed_loop
from contour_fmu.loops.wiring import FIVE_AXIS_JOINTS
from helpers.fmu_slave import Slave
from test_five_axis_cam_paths import planned_duration as planned_duration_5x
from test_two_axis_fmus import ESTIMATOR, distance_to_pieces
from test_two_axis_planner import planned_duration

LIMITS = {"accel": 2000.0, "jerk": 1e5}

# A 30 x 20 rectangle with a rounded corner (r 10), programmed as the part's edge, the
# tool inside it going counter-clockwise (G41), tool 1 of radius 3 mm.
PROFILE = ("%\nG21 G90 G17\nG0 X15 Y10\nG41 D1 G1 X15 Y0 F600\nG1 X30\nG1 Y10\n"
           "G3 X20 Y20 I-10 J0\nG1 X0\nG1 Y0\nG1 X15\nG40 G1 X15 Y10\nM30\n%\n")
TOOLS = "1:3"
# The tool centre's path, by hand: the entry toward (15, 0) would end 3 mm left of its
# direction, at (18, 0), but the corner with the bottom side is concave, so it stops where
# it meets that side's offset y = 3, at (17.1, 3); every corner of the rectangle is
# concave (the offsets meet 3 mm in), the rounded corner runs on r 7; the last side ends at
# its offset end (15, 3) and the exit goes back to (15, 10).
CENTRE = [
    ("line", (15.0, 10.0), (17.1, 3.0)),
    ("line", (17.1, 3.0), (27.0, 3.0)),
    ("line", (27.0, 3.0), (27.0, 10.0)),
    ("arc", (20.0, 10.0), 7.0, 0.0, np.pi / 2),
    ("line", (20.0, 17.0), (3.0, 17.0)),
    ("line", (3.0, 17.0), (3.0, 3.0)),
    ("line", (3.0, 3.0), (15.0, 3.0)),
    ("line", (15.0, 3.0), (15.0, 10.0)),
]


def test_a_compensated_profile_runs_on_the_tool_centre_path_and_the_ccc_beats_none(
        fmu_dir, tmp_path):
    part = tmp_path / "profile.ngc"
    part.write_text(PROFILE)
    interpolator = {**LIMITS, "toolRadii": TOOLS}
    stop = round(planned_duration(fmu_dir, path=str(part), **interpolator) + 0.3, 3)
    controller = {"estimator": ESTIMATOR["program"], "path": str(part), "toolRadii": TOOLS}
    maxima = {}
    for name, extra in [("ccc", {}), ("no ccc", {"ccc.enable": False})]:
        before, after = closed_loop(fmu_dir, path=str(part), stop=stop,
                                    interpolator=interpolator,
                                    controller={**controller, **extra})
        reference = np.stack([before["interpolator.ref.x"], before["interpolator.ref.y"]], 1)
        measured = np.stack([before["plant.pos.x"], before["plant.pos.y"]], axis=1)
        # The planned reference on the tool centre's path (exact stops: tolerance 0).
        planned, _ = distance_to_pieces(CENTRE, reference)
        assert planned.max() < 1e-9, planned.max()
        assert np.allclose(reference[-1], (15.0, 10.0), atol=1e-9), reference[-1]
        true, side = distance_to_pieces(CENTRE, measured)
        # The controller's estimate is the exact distance to the same path (the command of
        # the step from t_k is computed from pos(t_k)), on the side the test finds.
        estimate = after["controller.contourError"]
        assert np.abs(np.abs(estimate) - true).max() < 1e-9, name
        signed = side != 0
        # (Off the corners and the rests: exact stops at every corner with tolerance 0.)
        assert signed.sum() > 1000, signed.sum()
        assert np.array_equal(np.sign(estimate[signed]), side[signed]), name
        maxima[name] = true.max()
    print(f"compensated profile, max true error: {maxima['no ccc'] * 1e3:.2f} um without "
          f"CCC, {maxima['ccc'] * 1e3:.2f} um with")
    assert maxima["ccc"] < maxima["no ccc"], maxima


def test_a_compensated_profile_without_its_tool_is_refused_naming_the_line(fmu_dir, tmp_path):
    part = tmp_path / "profile.ngc"
    part.write_text(PROFILE)
    for model in ("PathInterpolator2D", "ContourCCC2D", "PathInterpolator5X"):
        s = Slave(str(fmu_dir / f"{model}.fmu"))
        parameters = {"path": str(part)}
        if model == "ContourCCC2D":
            parameters["estimator"] = ESTIMATOR["program"]
        s.set(**parameters)
        with pytest.raises(Exception):
            s.fmu.exitInitializationMode()
        messages = " ".join(s.log.errors())
        assert "profile.ngc:4" in messages and "D1 is not in the tool table" in messages, \
            (model, messages)
        s.close()
        s = Slave(str(fmu_dir / f"{model}.fmu"))
        s.set(toolRadii="1:three", **{k: v for k, v in parameters.items() if k != "path"})
        with pytest.raises(Exception):
            s.fmu.exitInitializationMode()
        assert "parameter 'toolRadii'" in " ".join(s.log.errors()), model
        s.close()


# Thread milling as Fusion 360's post writes it, a ramp and a G18 arc, on the five-axis
# machine (F 600 mm/min; the tool axis stays vertical).
THREE_AXIS = ("%\nO1001 (THREAD M12X1.75)\n(T1 D=6. CR=0. - ZMIN=-10. - THREAD MILL)\n"
              "N10 G90 G94 G17\nN15 G21\nN20 G28 G91 Z0.\nN25 G90\nN30 T1 M6\nN35 S5000 M3\n"
              "N40 G54\nN45 G0 X20. Y20.\nN50 G43 Z15. H1\nN55 G0 Z5.\nN60 G1 Z-10. F600.\n"
              "N65 G1 X21.5\nN70 G3 X23. I0.75 J0.\nN75 G3 X23. Y20. Z-8.25 I-3. J0.\n"
              "N80 G3 X23. Y20. Z-6.5 I-3. J0.\nN85 G3 X21.5 Y20. I-0.75 J0.\n"
              "N90 G1 X35. Y20. Z-3.\nN95 G18 G3 X45. Z-13. I0. K-10.\nN100 G17 G0 Z15.\n"
              "M30\n%\n")


def three_axis_path():
    """The program's tool path as dense points (chords of < 0.1 nm sag on the arcs)."""
    # The rapids before the first cut only position the tool: the path starts at Z5.
    points = [(20.0, 20.0, 5.0), (20.0, 20.0, -10.0), (21.5, 20.0, -10.0)]

    def arc(centre, radius, a0, sweep, z0, z1, plane="xy", n=20000):
        t = np.linspace(0.0, 1.0, n + 1)[1:]
        a = a0 + sweep * t
        u, v = centre[0] + radius * np.cos(a), centre[1] + radius * np.sin(a)
        w = z0 + (z1 - z0) * t
        if plane == "xy":
            return list(zip(u, v, w))
        # G18: (u, v) = (Z, X), w = Y.
        return list(zip(v, w, u))

    points += arc((22.25, 20.0), 0.75, np.pi, np.pi, -10.0, -10.0)
    points += arc((20.0, 20.0), 3.0, 0.0, 2 * np.pi, -10.0, -8.25)
    points += arc((20.0, 20.0), 3.0, 0.0, 2 * np.pi, -8.25, -6.5)
    points += arc((22.25, 20.0), 0.75, 0.0, np.pi, -6.5, -6.5)
    points.append((35.0, 20.0, -3.0))
    # G18 G3 from (X35, Z-3) about (X35, Z-13): in (Z, X) from angle 0 a quarter turn
    # counter-clockwise (seen from +Y) to (X45, Z-13).
    points += arc((-13.0, 35.0), 10.0, 0.0, np.pi / 2, 20.0, 20.0, plane="zx")
    points.append((45.0, 20.0, 15.0))
    return np.array(points)


def distance_to_polyline(polyline, points):
    a, b = polyline[:-1], polyline[1:]
    ab = b - a
    length2 = np.einsum("ij,ij->i", ab, ab)
    length2[length2 == 0.0] = 1.0
    best = np.empty(len(points))
    for k, p in enumerate(points):
        t = np.clip(np.einsum("ij,ij->i", p - a, ab) / length2, 0.0, 1.0)
        best[k] = np.min(np.linalg.norm(a + t[:, None] * ab - p, axis=1))
    return best


def test_a_three_axis_program_runs_on_the_five_axis_machine_and_the_ccc_beats_none(
        fmu_dir, tmp_path):
    part = tmp_path / "thread.nc"
    part.write_text(THREE_AXIS)
    stop = round(planned_duration_5x(fmu_dir, part, {}) + 0.2, 3)
    path = three_axis_path()
    maxima = {}
    for mode, controller in (("no ccc", {"ccc.enable": False}), ("ccc", {})):
        before, _ = five_axis_closed_loop(fmu_dir, path=str(part), stop=stop,
                                          controller=controller)
        reference = np.column_stack([before[f"interpolator.ref.{j}"] for j in FIVE_AXIS_JOINTS])
        measured = np.column_stack([before[f"plant.pos.{j}"] for j in FIVE_AXIS_JOINTS])
        # The tool axis stays vertical: A at 0 and C where it started.
        assert np.abs(reference[:, 3]).max() < 1e-12
        assert np.ptp(reference[:, 4]) < 1e-12
        tips, _ = forward(reference)
        # Every planned tip within the plan's tolerance (5 um) and the arcs' chord sag.
        planned = distance_to_polyline(path, tips[::5])
        assert planned.max() <= 0.005 + 0.0005 + 1e-6, planned.max()
        assert np.allclose(tips[-1], path[-1], atol=1e-9), tips[-1]
        measured_tips, _ = forward(measured)
        maxima[mode] = distance_to_polyline(path, measured_tips[::2]).max()
    print(f"three-axis program on five axes, max true tip error: {maxima['no ccc'] * 1e3:.2f} "
          f"um without CCC, {maxima['ccc'] * 1e3:.2f} um with")
    assert maxima["ccc"] < maxima["no ccc"], maxima
