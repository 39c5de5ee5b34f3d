"""PathInterpolator2D and ContourCCC2D through fmpy: validation, multi-rate sampling,
state save/restore, bad input, the closed loop on the paper's three paths, and the FMI
cross-check files."""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_csv, read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu

from contour_fmu.demo import paper
from contour_fmu.engines.fmu_log import FmuLog
from contour_fmu.engines.master import Master, Unit, closed_loop
from contour_fmu.checks.reference_paths import ContourReference
from helpers.fmu_slave import Slave

CONTROLLER_OUTPUTS = ["u.x", "u.y", "contourError", "err.x", "err.y", "ccc.Kp", "ccc.Ki", "ccc.Kd"]


@pytest.fixture
def controller(fmu_dir):
    s = Slave(str(fmu_dir / "ContourCCC2D.fmu"))
    yield s
    s.close()


@pytest.fixture
def interpolator(fmu_dir):
    s = Slave(str(fmu_dir / "PathInterpolator2D.fmu"))
    yield s
    s.close()


@pytest.mark.parametrize("model", ["PathInterpolator2D", "ContourCCC2D"])
def test_validates_without_problems(fmu_dir, model):
    assert validate_fmu(str(fmu_dir / f"{model}.fmu")) == []


ESTIMATOR = {"free_curve": 1, "line": 2, "arc": 3, "program": 4}


def test_estimator_is_an_enumeration_importers_can_offer_as_a_choice(fmu_dir):
    md = read_model_description(str(fmu_dir / "ContourCCC2D.fmu"))
    v = next(v for v in md.modelVariables if v.name == "estimator")
    assert v.type == "Enumeration" and v.causality == "parameter" and v.start == "1"
    assert v.declaredType.name == "ContourEstimator"
    assert {item.name: int(item.value) for item in v.declaredType.items} == ESTIMATOR
    # `path` stays a String: it also takes file names.
    md = read_model_description(str(fmu_dir / "PathInterpolator2D.fmu"))
    assert next(v for v in md.modelVariables if v.name == "path").type == "String"


def test_dependencies_are_explicit_no_feedthrough_and_initial_values_from_parameters(fmu_dir):
    """As fmpy reads them: every output depends on no input at communication points (no
    direct feedthrough), and each initial value on exactly the parameters it is computed from."""
    expected_initial = {
        "PathInterpolator2D": {"ref.x": ["path", "line.x0", "arc.cx", "arc.r", "arc.start"],
                               "ref.y": ["path", "line.y0", "arc.cy", "arc.r", "arc.start"],
                               "done": [],
                               # At rest with a plan, the feed without.
                               "feedRate": ["feed", "accel"],
                               # The path and every limit.
                               "plannedDuration": ["path", "feed", "Ts", "accel", "jerk", "tolerance",
                                                   "rapid", "line.x0", "line.y0", "line.x1",
                                                   "line.y1", "arc.cx", "arc.cy", "arc.r",
                                                   "arc.start", "arc.sweep"]},
        "XYServoPlant": {"pos.x": ["pos0.x"], "pos.y": ["pos0.y"], "vel.x": [], "vel.y": []},
        "ContourCCC2D": {name: [] for name in CONTROLLER_OUTPUTS},
    }
    # The velocity and acceleration of the first sample (and the look-ahead over the
    # first period): the feed along the start's tangent (feed² times its curvature)
    # without a plan, at rest with one: they follow what the duration does.
    for axis in ("x", "y"):
        for name in ("vref", "aref", "ahead"):
            expected_initial["PathInterpolator2D"][f"{name}.{axis}"] = (
                expected_initial["PathInterpolator2D"]["plannedDuration"])
    for model, initial in expected_initial.items():
        md = read_model_description(str(fmu_dir / f"{model}.fmu"))
        outputs = [v.name for v in md.modelVariables if v.causality == "output"]
        assert sorted(u.variable.name for u in md.outputs) == sorted(outputs)
        for unknown in md.outputs:
            assert unknown.dependencies == [], (model, unknown.variable.name)
        assert ({u.variable.name: sorted(d.name for d in u.dependencies) for u in md.initialUnknowns}
                == {name: sorted(knowns) for name, knowns in initial.items()})


def test_initial_values_change_only_with_their_listed_dependencies(fmu_dir):
    """The interpolator's first sample follows arc.r on the arc path, not the feed."""
    def first_sample(**values):
        s = Slave(str(fmu_dir / "PathInterpolator2D.fmu"))
        s.set(**values)
        s.fmu.exitInitializationMode()
        point = s.reals(["ref.x", "ref.y"])
        s.close()
        return point

    base = first_sample(path="arc", arc__start=0.5)
    assert np.array_equal(first_sample(path="arc", arc__start=0.5, feed=3.0), base)
    moved = first_sample(path="arc", arc__start=0.5, arc__r=25.0)
    assert np.allclose(moved, [-20 + 25 * math.cos(0.5), 25 * math.sin(0.5)], atol=1e-12)


# ---------------------------------------------------------------------------------------
# Multi-rate: the control law fires at every multiple of Ts, whatever the step.

def held_inputs(t):
    """Piecewise-constant inputs, changing every 5 ms: a circle and a point lagging inside it."""
    k = math.floor(t / 0.005 + 1e-9)
    a = 0.05 * k
    return [10 * math.cos(a) - 10, 10 * math.sin(a), 9.98 * math.cos(a - 0.01) - 10, 9.98 * math.sin(a - 0.01)]


def run_controller(fmu_dir, h, stop=0.1):
    s = Slave(str(fmu_dir / "ContourCCC2D.fmu"))
    s.fmu.exitInitializationMode()
    inputs = [s.vr[n] for n in ("ref.x", "ref.y", "pos.x", "pos.y")]
    outputs = {}
    steps = int(round(stop / h))
    for k in range(steps):
        t = k * h
        s.fmu.setReal(inputs, held_inputs(t))
        s.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        outputs[round((k + 1) * h, 9)] = s.reals(CONTROLLER_OUTPUTS)
    s.close()
    return outputs


def test_controller_output_is_independent_of_the_communication_step(fmu_dir):
    runs = {h: run_controller(fmu_dir, h) for h in (0.001, 0.0025, 0.005)}
    shared = sorted(set(runs[0.001]) & set(runs[0.0025]) & set(runs[0.005]))
    assert len(shared) == 20
    for t in shared:
        assert np.array_equal(runs[0.001][t], runs[0.0025][t]), t
        assert np.array_equal(runs[0.001][t], runs[0.005][t]), t
    # The controller really acted: the CCC gains and commands are not trivial.
    last = runs[0.001][shared[-1]]
    assert abs(last[0]) > 1.0 and last[5] > 0.0


def test_interpolator_output_is_independent_of_the_communication_step(fmu_dir):
    def run(h):
        s = Slave(str(fmu_dir / "PathInterpolator2D.fmu"))
        s.set(path="trident", feed=40.0)
        s.fmu.exitInitializationMode()
        out = {}
        for k in range(int(round(0.2 / h))):
            s.fmu.doStep(currentCommunicationPoint=k * h, communicationStepSize=h)
            out[round((k + 1) * h, 9)] = s.reals(["ref.x", "ref.y"])
        s.close()
        return out

    fine, coarse = run(0.001), run(0.0025)
    shared = sorted(set(fine) & set(coarse))
    assert len(shared) == 40
    for t in shared:
        assert np.array_equal(fine[t], coarse[t])
    # 0.2 s at 40 mm/s from the trident's start point (40.2, -0.1): 8 mm along the path.
    travelled = np.hypot(*(fine[0.2] - np.array([40.2, -0.1])))
    assert 6.0 < travelled < 8.0


# ---------------------------------------------------------------------------------------
# FMU state of the controller covers the estimator history and the PID memories.

def step_controller(slave, k0, k1, input_time):
    """1 ms steps k0 … k1 - 1 of a controller with inputs held_inputs(input_time(k)); the
    outputs after each step."""
    inputs = [slave.vr[n] for n in ("ref.x", "ref.y", "pos.x", "pos.y")]
    out = []
    for k in range(k0, k1):
        slave.fmu.setReal(inputs, held_inputs(input_time(k)))
        slave.fmu.doStep(currentCommunicationPoint=k * 0.001, communicationStepSize=0.001)
        out.append(slave.reals(CONTROLLER_OUTPUTS))
    return np.array(out)


def test_controller_state_restores_the_estimator_and_pid_memories(controller):
    c = controller
    c.fmu.exitInitializationMode()

    def go(k0, k1):
        return step_controller(c, k0, k1, lambda k: k * 0.005)

    go(0, 40)
    state = c.fmu.getFMUstate()
    serialized = c.fmu.serializeFMUstate(state)
    expected = go(40, 90)
    c.fmu.setFMUstate(state)
    assert np.array_equal(go(40, 90), expected)
    restored = c.fmu.deSerializeFMUstate(serialized)
    c.fmu.setFMUstate(restored)
    assert np.array_equal(go(40, 90), expected)
    c.fmu.freeFMUstate(state)
    c.fmu.freeFMUstate(restored)


def test_a_saved_state_continues_in_a_fresh_instance_without_initialization(fmu_dir, controller):
    """fmusim's --initial-fmu-state-file: instantiate, deserialize, set, then step on."""
    c = controller
    c.fmu.exitInitializationMode()

    def go(slave, k0, k1):
        return step_controller(slave, k0, k1, lambda k: k * 0.001)

    go(c, 0, 30)
    state = c.fmu.getFMUstate()
    saved = c.fmu.serializeFMUstate(state)
    c.fmu.freeFMUstate(state)
    expected = go(c, 30, 70)

    md = c.md
    fresh = FMU2Slave(guid=md.guid, unzipDirectory=c.dir, modelIdentifier="ContourCCC2D",
                      instanceName="fresh")
    fresh.instantiate(callbacks=c.log.callbacks)
    restored = fresh.deSerializeFMUstate(saved)
    fresh.setFMUstate(restored)
    fresh.freeFMUstate(restored)

    class Wrapped:
        fmu = fresh
        vr = c.vr

        @staticmethod
        def reals(names):
            return np.array(fresh.getReal([c.vr[n] for n in names]))

    assert np.array_equal(go(Wrapped, 30, 70), expected)
    fresh.freeInstance()


# ---------------------------------------------------------------------------------------
# Bad input

def test_nan_input_is_refused_and_outputs_stay(controller):
    c = controller
    c.fmu.exitInitializationMode()
    c.set(ref__x=1.0, pos__x=0.5)
    c.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.001)
    before = c.reals(CONTROLLER_OUTPUTS + ["pos.x"])
    with pytest.raises(FMICallException) as failure:
        c.set(pos__x=float("nan"))
    assert failure.value.status == 3  # fmi2Error
    assert any("'pos.x' refuses the non-finite value NaN" in m for m in c.log.errors())
    assert np.array_equal(c.reals(CONTROLLER_OUTPUTS + ["pos.x"]), before)


def test_the_master_gives_the_fmus_messages_to_its_log(fmu_dir):
    log = FmuLog()
    units = [Unit("controller", str(fmu_dir / "ContourCCC2D.fmu"))]
    with Master(units, [], 1e-3, 0.01, log=log) as master:
        with pytest.raises(FMICallException):
            master.set("controller", "pos.x", float("nan"))
    assert len(log.failures()) == 1
    assert log.failures()[0].startswith("controller: ")
    assert "'pos.x' refuses the non-finite value NaN" in log.failures()[0]


@pytest.mark.parametrize("fixture, values, words", [
    ("controller", {"Ts": 0.0}, "parameter 'Ts' must be at least 1e-6 s (got 0)"),
    ("controller", {"Ts": -0.001}, "parameter 'Ts' must be at least 1e-6 s (got -0.001)"),
    ("controller", {"Ts": 1e-10}, "parameter 'Ts' must be at least 1e-6 s"),
    ("controller", {"fuzzy__enable": True, "ccc__limit": 0.0}, "parameter ccc.limit = 0 is invalid"),
    ("controller", {"estimator": ESTIMATOR["arc"], "arc__r": 0.0}, "parameters 'arc.*'"),
    ("controller", {"estimator": ESTIMATOR["line"], "line__x1": 0.0, "line__y1": 0.0}, "parameters 'line.*'"),
    ("interpolator", {"feed": 0.0}, "parameter 'feed' must be > 0"),
    ("interpolator", {"feed": -5.0}, "parameter 'feed' must be > 0"),
    ("interpolator", {"Ts": 0.0}, "parameter 'Ts' must be at least 1e-6 s"),
    ("interpolator", {"Ts": 1e-9}, "parameter 'Ts' must be at least 1e-6 s"),
    ("interpolator", {"path": "spiral"}, "unknown path 'spiral'"),
])
def test_bad_parameters_are_refused_when_initialization_ends(request, fixture, values, words):
    s = request.getfixturevalue(fixture)
    s.set(**values)
    with pytest.raises(FMICallException):
        s.fmu.exitInitializationMode()
    assert any(words in m for m in s.log.errors()), s.log.errors()


@pytest.mark.parametrize("value", [0, 5, -1])
def test_an_estimator_value_outside_the_enumeration_is_refused_and_the_old_one_kept(controller, value):
    estimator = controller.vr["estimator"]
    with pytest.raises(FMICallException) as failure:
        controller.fmu.setInteger([estimator], [value])
    assert failure.value.status == 3  # fmi2Error
    assert controller.log.errors()[-1] == (
        f"fmi2SetInteger: variable 'estimator' = {value} is not a value of its enumeration "
        "ContourEstimator (1 = free_curve, 2 = line, 3 = arc, 4 = program)")
    assert controller.fmu.getInteger([estimator]) == [ESTIMATOR["free_curve"]]
    controller.fmu.exitInitializationMode()


def test_negative_fuzzy_factors_are_refused_with_the_parameter_named(controller):
    for name in ("fuzzy.ke", "fuzzy.kde", "fuzzy.kp", "fuzzy.ki", "fuzzy.kd"):
        with pytest.raises(FMICallException):
            controller.fmu.setReal([controller.vr[name]], [-1.0])
        assert controller.log.errors()[-1].endswith(f"variable '{name}' = -1 is below its minimum 0")
    controller.fmu.exitInitializationMode()  # the refused values were not stored


def test_missing_and_malformed_path_files_name_the_file_and_line(interpolator, tmp_path):
    missing = tmp_path / "nowhere.json"
    interpolator.set(path=str(missing))
    with pytest.raises(FMICallException):
        interpolator.fmu.exitInitializationMode()
    assert any(str(missing) in m for m in interpolator.log.errors())

    broken = tmp_path / "broken.json"
    broken.write_text('{\n  "degree": 3,\n  "knots": [0, 0, 0, 0, 1, 1, 1, 1],\n  "control_points": [[0, 0], [1, 1]\n}\n')
    interpolator.set(path=str(broken))
    with pytest.raises(FMICallException):
        interpolator.fmu.exitInitializationMode()
    assert any(f"{broken}:5:" in m for m in interpolator.log.errors()), interpolator.log.errors()

    good = tmp_path / "quarter.json"
    good.write_text(json.dumps({"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0], [3, 4]]}))
    interpolator.set(path=str(good), feed=5.0)
    interpolator.fmu.exitInitializationMode()
    interpolator.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.5)
    assert np.allclose(interpolator.reals(["ref.x", "ref.y"]), [1.5, 2.0], atol=1e-9)


# ---------------------------------------------------------------------------------------
# The closed loop

@pytest.mark.parametrize("path, feed", paper.PATHS)
def test_fuzzy_ccc_beats_no_ccc_through_the_fmus(fmu_dir, path, feed):
    _, _, without = paper.run_path(fmu_dir, path, feed, {"ccc.enable": False})
    _, _, fixed = paper.run_path(fmu_dir, path, feed, {"fuzzy.enable": False})
    _, _, fuzzy = paper.run_path(fmu_dir, path, feed, {})
    assert fuzzy.max() < 0.5 * without.max()
    assert fixed.max() < 0.5 * without.max()
    assert fuzzy.mean() < 0.1 * without.mean()
    if path == "circle":
        # docs/design/two-axis.md §4.2: 47.7 um without CCC on the paper's circle and plant.
        assert 0.0476 < without.max() < 0.0478


def test_cross_check_files_reproduce_through_simulate_fmu(fmu_dir, tmp_path):
    before, after = closed_loop(fmu_dir, path="circle", stop=0.2)
    paper.write_cross_check(tmp_path, before, after)
    folder = tmp_path / "cross-check" / "ContourCCC2D"
    inputs = read_csv(folder / "ContourCCC2D_in.csv")
    reference = read_csv(folder / "ContourCCC2D_ref.csv")
    options = dict(line.split(",") for line in (folder / "ContourCCC2D_ref.opt").read_text().split())
    result = simulate_fmu(str(fmu_dir / "ContourCCC2D.fmu"), stop_time=float(options["StopTime"]),
                          step_size=float(options["StepSize"]), output_interval=float(options["StepSize"]),
                          input=inputs, output=list(reference.dtype.names[1:]))
    assert len(result) == len(reference)
    for name in reference.dtype.names[1:]:
        assert np.max(np.abs(result[name] - reference[name])) < 1e-9, name
    assert np.max(np.abs(reference["u.x"])) > 1.0


def test_a_path_file_in_the_fmus_resources_folder_is_found_by_its_relative_name(interpolator):
    resources = Path(interpolator.dir) / "resources"
    resources.mkdir(exist_ok=True)
    (resources / "diagonal.json").write_text(
        json.dumps({"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[1, 1], [7, 9]]}))
    interpolator.set(path="diagonal.json", feed=10.0)
    interpolator.fmu.exitInitializationMode()
    assert np.allclose(interpolator.reals(["ref.x", "ref.y"]), [1.0, 1.0])
    interpolator.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.5)
    assert np.allclose(interpolator.reals(["ref.x", "ref.y"]), [4.0, 5.0], atol=1e-9)


def test_a_gcode_part_runs_at_constant_feed_with_its_preamble_warned_about(interpolator, tmp_path):
    # A 20 mm square with a 2 mm round in its third corner, in inches and incremental
    # moves after the preamble a CAM system writes; the part is independent of the reader:
    # its corners are the test's own numbers.
    part = tmp_path / "square.NGC"
    part.write_text(
        "%\n(square)\nG20 G17 G40 G49 G80 G90 G94\nT1 M6\nS10000 M3\nG0 Z0.2\nG0 X0 Y0\n"
        "G1 Z-0.04 F10\nG1 X0.787402 F30\nG91 Y0.787402\nG90 X0.078740\n"
        "G3 X0 Y0.708661 I0 J-0.078740\nG1 Y0\nG0 Z0.2\nM30\n%\n")
    interpolator.fmu.setDebugLogging(True, ["logStatusWarning"])
    interpolator.set(path=str(part), feed=10.0)
    interpolator.fmu.exitInitializationMode()
    warnings = interpolator.log.warnings()
    # (G40, cutter compensation off, is read rather than skipped.)
    for kind in ["G49", "T (tool number)", "S (spindle speed)", "constant 'feed'"]:
        assert any(kind in w for w in warnings), (kind, warnings)
    assert np.allclose(interpolator.reals(["ref.x", "ref.y"]), [0.0, 0.0])
    length = 20.0 + 20.0 + 18.0 + np.pi + 18.0
    # At 10 mm/s: 10 mm along the first side, 5 mm up the second, 1.4 mm into the round.
    # A chord across a corner is one feed step long and so covers up to (sqrt 2 - 1) of
    # a step more of the part: the samples after a corner run up to 4.2 um ahead.
    along = {1.0: ([10.0, 0.0], 2e-5), 2.5: ([20.0, 5.0], 5e-3),
             5.94: ([2.0 - 2.0 * np.sin(0.7), 18.0 + 2.0 * np.cos(0.7)], 9e-3)}
    time = 0.0
    for t, (want, tolerance) in along.items():
        interpolator.fmu.doStep(currentCommunicationPoint=time, communicationStepSize=t - time)
        time = t
        assert np.allclose(interpolator.reals(["ref.x", "ref.y"]), want, atol=tolerance), t
    interpolator.fmu.doStep(currentCommunicationPoint=time, communicationStepSize=length / 10.0 - time + 0.01)
    assert np.allclose(interpolator.reals(["ref.x", "ref.y"]), [0.0, 0.0], atol=1e-9)
    assert interpolator.fmu.getBoolean([interpolator.vr["done"]])[0]


# A part with a tangent arc, a corner into an arc, a 0.5 mm radius and 90° corners, closed
# counter-clockwise, and its pieces as the test knows them: lines (start, end) and arcs
# (centre, radius, start angle, signed sweep).
PART = ("%\nG21 G90 G17 G64\nG0 X0 Y0\nG1 X25 F1200\nG3 X30 Y5 R5\nG1 Y12\nG2 X25 Y17 R5\n"
        "G1 Y20\nX0.5\nG3 X0 Y19.5 R0.5\nG1 Y0\nM30\n%\n")
PART_PIECES = [
    ("line", (0.0, 0.0), (25.0, 0.0)),
    ("arc", (25.0, 5.0), 5.0, -np.pi / 2, np.pi / 2),
    ("line", (30.0, 5.0), (30.0, 12.0)),
    ("arc", (30.0, 17.0), 5.0, -np.pi / 2, -np.pi / 2),
    ("line", (25.0, 17.0), (25.0, 20.0)),
    ("line", (25.0, 20.0), (0.5, 20.0)),
    ("arc", (0.5, 19.5), 0.5, np.pi / 2, np.pi / 2),
    ("line", (0.0, 19.5), (0.0, 0.0)),
]


def distance_to_pieces(pieces, points):
    """The test's own distance from each point to the nearest piece, and the side (+1 right
    of travel, -1 left, 0 where the foot is a piece's end)."""
    best = np.full(len(points), np.inf)
    side = np.zeros(len(points))
    for piece in pieces:
        if piece[0] == "line":
            a, b = np.array(piece[1]), np.array(piece[2])
            d = b - a
            t = np.clip((points - a) @ d / (d @ d), 0.0, 1.0)
            foot = a + t[:, None] * d
            tangent = np.broadcast_to(d / np.linalg.norm(d), points.shape)
        else:
            _, c, r, a0, sweep = piece
            q = points - np.array(c)
            turned = np.mod(np.sign(sweep) * (np.arctan2(q[:, 1], q[:, 0]) - a0), 2 * np.pi)
            ends = [np.array(c) + r * np.array([np.cos(a0 + u * sweep), np.sin(a0 + u * sweep)])
                    for u in (0.0, 1.0)]
            nearer_end = np.where(np.linalg.norm(points - ends[0], axis=1)
                                  <= np.linalg.norm(points - ends[1], axis=1), 0.0, 1.0)
            t = np.where(turned <= abs(sweep), turned / abs(sweep), nearer_end)
            phi = a0 + t * sweep
            foot = np.array(c) + r * np.stack([np.cos(phi), np.sin(phi)], axis=1)
            tangent = np.sign(sweep) * np.stack([-np.sin(phi), np.cos(phi)], axis=1)
        distance = np.linalg.norm(points - foot, axis=1)
        offset = points - foot
        right = -(tangent[:, 0] * offset[:, 1] - tangent[:, 1] * offset[:, 0])
        inside = (t > 1e-9) & (t < 1 - 1e-9) & (distance > 1e-9)
        nearer = distance < best
        best = np.where(nearer, distance, best)
        side = np.where(nearer, np.where(inside, np.sign(right), 0.0), side)
    return best, side


def test_the_program_estimator_gives_the_exact_distance_to_a_gcode_part_in_the_closed_loop(
        fmu_dir, tmp_path):
    part = tmp_path / "part.ngc"
    part.write_text(PART)
    length = 25 + 2.5 * np.pi + 7 + 2.5 * np.pi + 3 + 24.5 + 0.25 * np.pi + 19.5
    feed = 50.0
    stop = round(length / feed + 0.3, 3)
    controller = {"estimator": ESTIMATOR["program"], "path": str(part)}
    runs = {}
    for name, extra in [("ccc", {}), ("no ccc", {"ccc.enable": False})]:
        before, after = closed_loop(fmu_dir, path=str(part), feed=feed, stop=stop,
                                    controller={**controller, **extra})
        points = np.stack([before["plant.pos.x"], before["plant.pos.y"]], axis=1)
        want, side = distance_to_pieces(PART_PIECES, points)
        # The command of the step from t_k is computed from pos(t_k).
        got = after["controller.contourError"]
        assert np.abs(np.abs(got) - want).max() < 1e-9, name
        signed = side != 0
        assert signed.sum() > 0.5 * len(got)
        assert np.array_equal(np.sign(got[signed]), side[signed]), name
        runs[name] = want
    # The exact estimate at the corners makes the CCC worth having (0.62 -> 0.18 mm).
    assert runs["no ccc"].max() > 0.3
    assert runs["ccc"].max() < 0.4 * runs["no ccc"].max()


def test_a_reference_off_the_program_estimators_path_is_warned_about_once(controller):
    # The controller measures against the line (0, 0) -> (40, 30) of the line.* parameters;
    # the reference goes along it, then 0.5 um off it (within 1 um: rounding), then 20 um
    # and 50 um off it (another path).
    controller.fmu.setDebugLogging(True, ["logStatusWarning"])
    controller.set(estimator=ESTIMATOR["program"], path="line")
    controller.fmu.exitInitializationMode()
    normal = np.array([-0.6, 0.8])
    time = 0.0
    for k, off in enumerate([0.0, 0.0, 0.0005, 0.02, 0.05, 0.0]):
        reference = np.array([0.4, 0.3]) * (k + 1) + normal * off
        actual = reference - np.array([0.4, 0.3]) + normal * 0.01
        controller.fmu.setReal([controller.vr[n] for n in ["ref.x", "ref.y", "pos.x", "pos.y"]],
                               [*reference, *actual])
        controller.fmu.doStep(currentCommunicationPoint=time, communicationStepSize=1e-3)
        time += 1e-3
        # 10 um left of the line: -0.01 mm, as far as the reference is on it.
        if off == 0.0:
            assert abs(controller.reals(["contourError"])[0] + 0.01) < 1e-12
        warnings = [w for w in controller.log.warnings() if "off the path" in w]
        assert len(warnings) == (1 if off >= 0.02 or k == 5 else 0), (k, warnings)
    assert "0.020000 mm off the path of parameter 'path' by t = 0.004 s" in warnings[0], warnings
