"""Feed-forward and the CCC together in the shipped loops, where parts are scrapped (issue 42):
exact-stop corners, a reversal and small radii on the XY table, the bracket's blended
corners, a dome over its apex and a pass through vertical on the five-axis machine.

The shipped loops (contour_fmu/loops/*.ssd, every parameter set) set `feedForward` 1 and
`accelerationFeedForward` T_a = Ts/(1 − e^(−Ts/τ)) for the test plants' velocity loops
(τ = J/(CT·Kvp)); ContourCCC takes the acceleration at the middle of the hold
(contour_core::control::FeedForward). Every figure is the largest contour error from the
test's own references: the distance to the programmed lines and arcs in closed form
(contour_fmu.checks.gcode) where the plan keeps to the program (G61: exact stops, tolerance
0), and to the planned reference by brute force over its Catmull-Rom densification
(contour_fmu.checks.five_axis_truth) where the plan leaves the program by design (the
bracket's blends, the dome's turn of C within the pole cone). The floor is the plant FMU
driven by the ideal inverse of its drives' model with a one-sample preview
(contour_fmu.checks.feed_forward_floor).

Targets: the shipped loop within 5 % of the loop without CCC and feed-forward (that figure
frozen here as measured when the shipped loops changed), and within 1.25 × the floor or
0.6 × feed-forward alone (on the exact-stop parts the best of a sweep of its acceleration
time); with friction and a
current limit, the CCC on top of feed-forward within 1.1 × feed-forward alone.
"""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from contour_fmu.checks.feed_forward_floor import (acceleration_time, drive_parameters, floor_run,
                                                  ideal_commands)
from contour_fmu.checks.five_axis_truth import contour_errors
from contour_fmu.checks.gcode import distance, mirror_program, read_program
from contour_fmu.checks.reference_paths import polyline
from contour_fmu.demo import cam_paths
from contour_fmu.engines.master import closed_loop, five_axis_closed_loop
from contour_fmu.loops import ssp
from contour_fmu.loops.wiring import FIVE_AXIS_JOINTS, LOOPS
from contour_fmu import repo

TS = 1e-3
# A plate's corner detail in exact-stop mode: a 90° corner, a tangent R10 arc, a 117°
# corner into a spike that turns back on itself (a reversal), an R2 radius.
CORNERS = """G21 G90 G17 G61
G0 X0 Y0
G1 X40 Y0 F1800
G1 X40 Y20
G3 X30 Y30 R10
G1 X10 Y30
G1 X14.540 Y21.090 F1200
G1 X10 Y30
G1 X2 Y30 F1800
G3 X0 Y28 R2
G1 X0 Y0
M30
"""
# The same outline the other way round.
CORNERS_REVERSED = """G21 G90 G17 G61
G0 X0 Y0
G1 X0 Y28 F1800
G2 X2 Y30 R2
G1 X10 Y30
G1 X14.540 Y21.090 F1200
G1 X10 Y30
G1 X30 Y30 F1800
G2 X40 Y20 R10
G1 X40 Y0
G1 X0 Y0
M30
"""
PLANNED = {"accel": 2000.0, "jerk": 5e4, "feed": 30.0, "tolerance": 0.0}
STOP = 6.3  # s: the planned 6.0 s and the settling
# The largest true error without CCC and feed-forward when the shipped loops changed
# (mm), frozen: the 5 % target is against these.
FROZEN = {"forward": 0.129603, "reversed": 0.129604, "mirrored": 0.129603}
SWEEP = [3.2e-3, 3.5e-3, 3.6e-3, 3.65e-3, 3.7e-3, 3.75e-3, 3.8e-3, 4.0e-3]
SHIPPED = LOOPS["two_axis"].feed_forward
SHIPPED_5X = LOOPS["five_axis"].feed_forward


def test_the_shipped_acceleration_time_is_the_test_plants_hold_corrected_time_constant(fmu_dir):
    for loop, plant, axes in (("two_axis", "XYServoPlant", "xy"),
                              ("five_axis", "FiveAxisPlant", FIVE_AXIS_JOINTS)):
        drives = drive_parameters(fmu_dir / f"{plant}.fmu", axes)
        times = [acceleration_time(d, TS) for d in drives.values()]
        shipped = LOOPS[loop].feed_forward
        assert shipped["feedForward"] == 1.0
        # One time for every axis: the rotary axes' differs by 0.03 % (1/314 s against
        # the linear axes' 3.186 ms).
        assert all(abs(shipped["accelerationFeedForward"] - t) <= 5e-4 * t for t in times)
    # Each parameter set of both loops, mm and SI, carries it (the masters apply a set).
    for build in ("", "si/"):
        for name in ("two_axis", "five_axis"):
            structure = ssp.read(ssp.SHIPPED / f"{build}{name}.ssd")
            for values in structure.parameter_sets.values():
                assert values["controller"] == LOOPS[name].feed_forward


def _corners(fmu_dir, tmp_path, which="forward"):
    """The corners part (`which`: forward, reversed, mirrored) written to a file: (the
    interpolator's start values, the true error of positions, run(controller, plant,
    limits, stop, step) -> the plant's positions), ContourCCC2D measuring against the
    program."""
    text = {"forward": CORNERS, "reversed": CORNERS_REVERSED,
            "mirrored": mirror_program(CORNERS)}[which]
    file = tmp_path / f"corners_{which}.ngc"
    file.write_text(text)
    pieces = read_program(text)
    interpolator = {"path": str(file), **PLANNED}
    estimator = {"estimator": 4, "path": str(file), "tolerance": 0.0}

    def true_error(positions):
        return distance(pieces, positions)[0].max()

    def run(controller, plant=None, limits=None, stop=STOP, step=TS):
        before, _ = closed_loop(fmu_dir, stop=stop, step=step, plant=plant,
                                interpolator={**interpolator, **(limits or {})},
                                controller={**estimator, **controller})
        return np.column_stack([before["plant.pos.x"], before["plant.pos.y"]])
    return interpolator, true_error, run


def _program_runs(fmu_dir, tmp_path, which):
    interpolator, true_error, run = _corners(fmu_dir, tmp_path, which)
    figures = {label: true_error(run(c)) for label, c in LOOPS["two_axis"].variants()}
    figures["swept"] = {t: true_error(run({"ccc.enable": False, "feedForward": 1.0,
                                           "accelerationFeedForward": t})) for t in SWEEP}
    _, floor = floor_run(fmu_dir, "two_axis", interpolator, STOP)
    figures["floor"] = true_error(floor)
    return figures


@pytest.mark.parametrize("which", ["forward", "reversed", "mirrored"])
def test_at_exact_stop_corners_the_shipped_loop_is_at_the_floor(fmu_dir, tmp_path, which):
    figures = _program_runs(fmu_dir, tmp_path, which)
    none, ccc = figures["no CCC"], figures["fuzzy CCC"]
    alone, shipped = figures["feed-forward"], figures["fuzzy CCC + feed-forward (shipped)"]
    best = min(figures["swept"].values())
    print(f"corners {which}: no CCC {none * 1e3:.3f} um, CCC {ccc * 1e3:.3f}, feed-forward "
          f"{alone * 1e3:.3f} (best swept {best * 1e3:.3f} at "
          f"{min(figures['swept'], key=figures['swept'].get) * 1e3:.3f} ms), shipped "
          f"{shipped * 1e3:.3f}, floor {figures['floor'] * 1e3:.3f}")
    assert abs(none - FROZEN[which]) <= 1e-3 * FROZEN[which], none
    assert shipped <= 0.05 * FROZEN[which]
    assert shipped <= max(1.25 * figures["floor"], 0.6 * best)
    # The ideal inverse with its preview beats the causal feed-forward it approximates.
    # (It is no bound on the contour error: a slightly short acceleration time, 3.70 ms,
    # reaches 0.19 um here because it overshoots the exact stops less; the shipped time is
    # the drives', not one tuned to this part.)
    assert figures["floor"] <= alone


def test_with_friction_and_a_current_limit_the_ccc_does_not_spoil_feed_forward(fmu_dir, tmp_path):
    """Coulomb 0.5 N·m, stiction 0.8 N·m and a 42 A current limit on each axis, the part at
    4000 mm/s²: feed-forward cannot know the friction and the drive saturates while it
    accelerates at speed; the CCC stays within 1.1 × feed-forward alone (here it halves
    it)."""
    friction = {f"{a}.{n}": v for a in "xy" for n, v in
                (("coulomb", 0.5), ("stiction", 0.8), ("stribeckVelocity", 1.0),
                 ("currentMax", 42.0))}
    _, true_error, run = _corners(fmu_dir, tmp_path)
    faster = {"accel": 4000.0, "jerk": 1e5}
    unlimited = {k: v for k, v in friction.items() if not k.endswith("currentMax")}
    alone = true_error(run({"ccc.enable": False, **SHIPPED}, friction, faster))
    both = true_error(run(dict(SHIPPED), friction, faster))
    unsaturated = true_error(run({"ccc.enable": False, **SHIPPED}, unlimited, faster))
    print(f"friction and 42 A: feed-forward {alone * 1e3:.3f} um (without the limit "
          f"{unsaturated * 1e3:.3f}), with the CCC {both * 1e3:.3f}")
    assert alone != unsaturated  # the limit was reached
    assert both <= 1.1 * alone


def _planar(xy):
    return np.column_stack([xy, np.zeros((len(xy), 3))])


def test_on_the_bracket_against_its_planned_geometry(fmu_dir):
    """examples/parts/bracket.ngc at the part demo's limits (accel 2000, jerk 1e5,
    tolerance 0.02): blended corners, an exact stop, an R0.8 radius."""
    program = repo.find_root() / "examples" / "parts" / "bracket.ngc"
    interpolator = {"path": str(program), "accel": 2000.0, "jerk": 1e5, "tolerance": 0.02,
                    "feed": 30.0}
    estimator = {"estimator": 4, "path": str(program), "tolerance": 0.02}
    stop = 7.0

    def planned_error(reference, positions):
        return contour_errors(_planar(reference), _planar(positions), ahead=25)[0].max()

    figures = {}
    for label, controller in LOOPS["two_axis"].variants():
        before, _ = closed_loop(fmu_dir, stop=stop, interpolator=interpolator,
                                controller={**estimator, **controller})
        reference = np.column_stack([before["interpolator.ref.x"], before["interpolator.ref.y"]])
        figures[label] = planned_error(
            reference, np.column_stack([before["plant.pos.x"], before["plant.pos.y"]]))
    reference, floor = floor_run(fmu_dir, "two_axis", interpolator, stop)
    figures["floor"] = planned_error(reference, floor)
    print("bracket, against the planned geometry (um):",
          {k: round(v * 1e3, 3) for k, v in figures.items()})
    shipped = figures["fuzzy CCC + feed-forward (shipped)"]
    assert shipped <= 0.05 * figures["no CCC"]
    assert shipped <= 1.25 * figures["floor"]


@pytest.mark.parametrize("path", ["dome", "through vertical"])
def test_over_the_apex_and_through_vertical_the_shipped_five_axis_loop_is_at_the_floor(
        fmu_dir, tmp_path, path):
    """The dome raster over its apex (the whole program, 11.2 s at 50 mm/s) and the pass
    whose tool axis tilts through vertical, against the planned reference (which turns C
    within the pole cone by design): tip and orientation."""
    text = cam_paths.dome_raster() if path == "dome" else cam_paths.tilting_pass(0.0)
    stop = 11.3 if path == "dome" else 1.5
    cl = tmp_path / "path.cl"
    cl.write_text(text)
    interpolator = {"path": str(cl), "feed": 50.0}
    figures = {}
    for label, controller in LOOPS["five_axis"].variants("five-axis CCC"):
        before, _ = five_axis_closed_loop(fmu_dir, path=str(cl), stop=stop,
                                          interpolator={"feed": 50.0}, controller=controller)
        reference = np.column_stack([before[f"interpolator.ref.{j}"] for j in FIVE_AXIS_JOINTS])
        measured = np.column_stack([before[f"plant.pos.{j}"] for j in FIVE_AXIS_JOINTS])
        tip, orientation = contour_errors(reference, measured, ahead=25)
        figures[label] = (tip.max(), orientation.max())
    reference, floor = floor_run(fmu_dir, "five_axis", interpolator, stop)
    tip, orientation = contour_errors(reference, floor, ahead=25)
    figures["floor"] = (tip.max(), orientation.max())
    print(f"{path} (um, urad):", {k: (round(t * 1e3, 3), round(o * 1e6, 2))
                                  for k, (t, o) in figures.items()})
    none, ccc = figures["no CCC"], figures["five-axis CCC"]
    shipped = figures["five-axis CCC + feed-forward (shipped)"]
    alone = figures["feed-forward"]
    for i in (0, 1):  # tip, orientation
        assert shipped[i] <= 0.05 * none[i]
        assert shipped[i] <= max(1.25 * figures["floor"][i], 0.6 * alone[i])
        # Through vertical the CCC alone was best before (2.5 um); no longer.
        assert shipped[i] < ccc[i]


def test_the_shipped_two_axis_loop_plans_its_reference_and_does_not_overshoot_its_end(
        fmu_dir):
    """Feed-forward keeps the tool at the reference's speed, so a reference that stops
    from full feed at once (the paper's constant feed, `accel` 0) is overshot: the
    look-ahead sees the stop one period ahead and commands the drive to stop within one
    hold (a braking command of T_a·feed/Ts, 186 mm/s at 50 mm/s, that a real drive could
    not follow), which still leaves tens of µm; without the look-ahead it is about feed·τ,
    160 µm. Every parameter set of the shipped two-axis loop plans its path (`accel`
    2000 mm/s², mm and SI). On the open trident at 50 mm/s, against the path rebuilt
    with geomdl, largest error over the whole run and its stop: planned with the shipped
    controller far below the CCC alone, unplanned with feed-forward the overshoot."""
    for build, scale in (("", 1.0), ("si/", 1e-3)):
        structure = ssp.read(ssp.SHIPPED / f"{build}two_axis.ssd")
        assert all(values["interpolator"]["accel"] == 2000.0 * scale
                   for values in structure.parameter_sets.values())
    tree = cKDTree(polyline("trident"))
    figures = {}
    past_end = {}
    for accel in (0.0, 2000.0):
        for label, controller in LOOPS["two_axis"].variants():
            before, _ = closed_loop(fmu_dir, path="trident", feed=50.0, stop=7.0,
                                    controller=controller, interpolator={"accel": accel})
            points = np.column_stack([before["plant.pos.x"], before["plant.pos.y"]])
            error = tree.query(points)[0]
            figures[label, accel] = error.max()
            reference = np.column_stack([before["interpolator.ref.x"], before["interpolator.ref.y"]])
            ended = np.all(reference == reference[-1], axis=1)  # the reference at its end
            past_end[label, accel] = error[ended].max()
    print({k: round(v * 1e3, 3) for k, v in figures.items()})
    shipped = "fuzzy CCC + feed-forward (shipped)"
    assert figures[shipped, 2000.0] < 0.1 * figures["fuzzy CCC", 2000.0]
    print("past the end (um):", {k: round(v * 1e3, 3) for k, v in past_end.items()})
    # Unplanned, the stop is overshot, with the CCC or without; planned, not.
    for label in ("feed-forward", shipped):
        assert past_end[label, 0.0] > 0.01
        assert past_end[label, 2000.0] < 1e-3
    without = {**LOOPS["two_axis"].feed_forward, "feedForwardLookAhead": False}
    before, _ = closed_loop(fmu_dir, path="trident", feed=50.0, stop=7.0, controller=without,
                            interpolator={"accel": 0.0})
    points = np.column_stack([before["plant.pos.x"], before["plant.pos.y"]])
    reference = np.column_stack([before["interpolator.ref.x"], before["interpolator.ref.y"]])
    ended = np.all(reference == reference[-1], axis=1)
    assert tree.query(points[ended])[0].max() > 0.5 * 50.0 * 3.186e-3


@pytest.mark.parametrize("model, axes, look_ahead", [("ContourCCC2D", "xy", False),
                                                     ("ContourCCC2D", "xy", True),
                                                     ("ContourCCC5X", FIVE_AXIS_JOINTS, None)])
def test_the_feed_forward_memory_continues_in_a_fresh_instance(fmu_dir, model, axes, look_ahead):
    """The acceleration's slope is part of the saved state: a state saved with the shipped
    feed-forward and restored into a fresh instance gives the same commands bit for bit,
    and its first command is the law by hand with the slope it never saw itself. The
    inputs: a reference whose acceleration ramps (constant jerk) on every axis, the
    position 10 ms behind it. With the look-ahead (ContourCCC2D's shipped setting) the
    acceleration term is the interpolator's mean over the hold, `ahead`, which on the ramp
    is the same value: the law by hand is the same."""
    from helpers.fmu_slave import Slave

    def inputs(k):
        t = k * TS
        values = {}
        for i, a in enumerate(axes):
            scale = 1.0 if a in "xyXYZ" else 1e-3
            values.update({f"ref.{a}": scale * (10.0 + i + 5e3 * t ** 3 / 6),
                           f"pos.{a}": scale * (10.0 + i + 5e3 * (t - 0.01) ** 3 / 6),
                           f"vref.{a}": scale * 5e3 * t ** 2 / 2,
                           f"aref.{a}": scale * 5e3 * t})
            if look_ahead is not None:
                values[f"ahead.{a}"] = scale * 5e3 * ((t + TS) ** 2 - t ** 2) / 2 / TS
        return values

    def steps(slave, k0, k1):
        outputs = [f"u.{a}" for a in axes]
        rows = []
        for k in range(k0, k1):
            slave.set(**inputs(k))
            slave.fmu.doStep(currentCommunicationPoint=k * TS, communicationStepSize=TS)
            rows.append(slave.reals(outputs))
        return np.array(rows)

    settings = {"ccc.enable": False, **LOOPS["two_axis"].feed_forward}
    if look_ahead is None:
        del settings["feedForwardLookAhead"]
    else:
        settings["feedForwardLookAhead"] = look_ahead
    first = Slave(str(fmu_dir / f"{model}.fmu"))
    first.set(**settings)
    first.fmu.exitInitializationMode()
    steps(first, 0, 30)
    state = first.fmu.getFMUstate()
    saved = first.fmu.serializeFMUstate(state)
    first.fmu.freeFMUstate(state)
    expected = steps(first, 30, 60)
    first.close()

    fresh = Slave(str(fmu_dir / f"{model}.fmu"), name="fresh")
    fresh.set(**settings)
    fresh.fmu.exitInitializationMode()
    restored = fresh.fmu.deSerializeFMUstate(saved)
    fresh.fmu.setFMUstate(restored)
    fresh.fmu.freeFMUstate(restored)
    assert np.array_equal(steps(fresh, 30, 60), expected)
    fresh.close()
    # The law by hand (the CCC off): the position loop's Kp·e, the velocity, and the
    # acceleration at the middle of the hold, aref + jerk·Ts/2 (the slope from the
    # memory restored: the fresh instance never saw step 29's aref).
    time = settings["accelerationFeedForward"]
    for i, a in enumerate(axes):
        k, scale = 30, (1.0 if a in "xyXYZ" else 1e-3)
        given = inputs(k)
        want = (28.5 * (given[f"ref.{a}"] - given[f"pos.{a}"]) + given[f"vref.{a}"]
                + time * (given[f"aref.{a}"] + scale * 5e3 * TS / 2))
        assert abs(expected[0][i] - want) <= 1e-12 * max(1.0, abs(want)), a


def test_the_ideal_inverse_of_the_test_drive_is_the_hold_corrected_law(fmu_dir):
    """The floor's inverse (scipy's matrix exponential of the full three-state drive,
    whose PI zero is at 80.02 against the mechanical pole's 80 rad/s) against the law
    ContourCCC applies, v + T_a·a_mid: on a constant-jerk ramp they agree to 5e-4 of the
    acceleration term (2e-4 measured: the zero 2.5e-4 off the pole)."""
    drive = drive_parameters(fmu_dir / "XYServoPlant.fmu", "x")["x"]
    jerk, steps = 5e4, 60
    t = np.arange(steps + 1) * TS
    velocity = jerk * t ** 2 / 2
    ideal = ideal_commands(velocity, drive, TS)
    law = velocity[:-1] + acceleration_time(drive, TS) * jerk * (t[:-1] + TS / 2)
    term = acceleration_time(drive, TS) * jerk * t[-1]
    print(f"largest |ideal - law| {np.abs(ideal - law).max():.3g} mm/s of {term:.3g}")
    assert np.abs(ideal - law).max() <= 5e-4 * term
    # T_a itself: τ + Ts/2 + Ts²/(12τ) − Ts⁴/(720τ³), the next term 1e-10 s.
    tau = drive["J"] / (drive["CT"] * drive["Kvp"])
    series = tau + TS / 2 + TS ** 2 / (12 * tau) - TS ** 4 / (720 * tau ** 3)
    assert abs(acceleration_time(drive, TS) - series) < 2e-10


@pytest.mark.parametrize("divisor", [2, 4])
def test_a_communication_step_shorter_than_ts_gives_the_same_loop(fmu_dir, tmp_path, divisor):
    """The controllers and the interpolator sample every Ts = 1 ms whatever the step; a
    master that steps at Ts/2 or Ts/4 (docs/usage.md: a step that divides Ts) runs the
    shipped loop on the corners part as at Ts, at the shared instants, to the plant's
    rounding: the feed-forward reads the acceleration's slope between the points where it
    samples, not between steps that see the interpolator's staircase."""
    _, _, run = _corners(fmu_dir, tmp_path)
    runs = {step: run(dict(SHIPPED), stop=2.0, step=step)[::round(TS / step)]
            for step in (TS, TS / divisor)}
    assert len(runs[TS]) == len(runs[TS / divisor])
    difference = np.abs(runs[TS] - runs[TS / divisor]).max()
    print(f"Ts/{divisor}: largest difference {difference:.3g} mm")
    assert difference < 1e-9


def test_on_cam_output_with_tiny_arcs_the_look_ahead_reaches_the_floor(fmu_dir):
    """CamBam's engraving (tests/data/cam/cambam/enclosure-labels.nc: 195 arcs of radius
    0.075–9.3 mm, G64), planned as the shipped loop plans it (accel 2000, jerk 10⁵,
    tolerance 0.02), its first 10 s. The plan's jerk switches every few samples; the
    acceleration extrapolated from the samples before misses each switch inside a hold
    by up to jerk·Ts/2, the look-ahead does not. Largest error against the planned
    reference by brute force over its Catmull-Rom densification: the shipped loop within
    1.1 × the floor, half of what it is without the look-ahead."""
    program = str(repo.root() / "tests" / "data" / "cam" / "cambam" / "enclosure-labels.nc")
    interpolator = {"path": program, "feed": 30.0, "accel": 2000.0, "jerk": 1e5,
                    "tolerance": 0.02}
    estimator = {"estimator": 4, "path": program, "tolerance": 0.02}
    stop = 10.0

    def largest(reference, positions):
        pad = lambda xy: np.column_stack([xy, np.zeros((len(xy), 3))])
        return contour_errors(pad(reference), pad(positions), ahead=25)[0].max()

    figures = {}
    for label, controller in (("shipped", SHIPPED),
                              ("without look-ahead", {**SHIPPED, "feedForwardLookAhead": False})):
        before, _ = closed_loop(fmu_dir, stop=stop, interpolator=interpolator,
                                controller={**estimator, **controller})
        figures[label] = largest(
            np.column_stack([before["interpolator.ref.x"], before["interpolator.ref.y"]]),
            np.column_stack([before["plant.pos.x"], before["plant.pos.y"]]))
    figures["floor"] = largest(*floor_run(fmu_dir, "two_axis", interpolator, stop))
    print("CamBam engraving (um):", {k: round(v * 1e3, 4) for k, v in figures.items()})
    assert figures["shipped"] <= 1.1 * figures["floor"]
    assert figures["shipped"] <= 0.6 * figures["without look-ahead"]
