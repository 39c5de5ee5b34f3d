"""PathInterpolator5X, ContourCCC5X and FiveAxisPlant through fmpy: validation, the closed
loop against the in-process simulator, multi-rate sampling, state save/restore into a
fresh instance, bad input, the FMI cross-check files."""

import math
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_csv, simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu

from contour_fmu.demo import five_axis as five_axis_demo
from contour_fmu.engines.master import five_axis_closed_loop
from contour_fmu.output_files import write_cross_check
from contour_fmu.loops.wiring import FIVE_AXIS_JOINTS
from contour_fmu.checks.five_axis_truth import forward
from helpers.fmu_slave import Slave

REPO = Path(__file__).resolve().parents[2]
BLADE = REPO / "examples" / "cl" / "blade.cl"
MODELS = ["PathInterpolator5X", "ContourCCC5X", "FiveAxisPlant"]
REF = [f"ref.{j}" for j in FIVE_AXIS_JOINTS]
VREF = [f"vref.{j}" for j in FIVE_AXIS_JOINTS]
AREF = [f"aref.{j}" for j in FIVE_AXIS_JOINTS]
POS = [f"pos.{j}" for j in FIVE_AXIS_JOINTS]
U = [f"u.{j}" for j in FIVE_AXIS_JOINTS]
CONTROLLER_OUTPUTS = U + [f"err.{j}" for j in FIVE_AXIS_JOINTS] + [
    "contourError.tip", "contourError.orientation", "evaluation.tip", "evaluation.orientation",
    "evaluation.delay"]
MODES = {"off": {"ccc.enable": False}, "fixed": {"fuzzy.enable": False}, "fuzzy": {}}


@pytest.fixture
def controller(fmu_dir):
    s = Slave(str(fmu_dir / "ContourCCC5X.fmu"))
    yield s
    s.close()


@pytest.fixture
def interpolator(fmu_dir):
    s = Slave(str(fmu_dir / "PathInterpolator5X.fmu"))
    yield s
    s.close()


@pytest.mark.parametrize("model", MODELS)
def test_validates_without_problems(fmu_dir, model):
    assert validate_fmu(str(fmu_dir / f"{model}.fmu")) == []


# ---------------------------------------------------------------------------------------
# The closed loop is the in-process simulator's, to rounding.

@pytest.mark.parametrize("path, mode", [
    ("tilted_helix", "fuzzy"), ("figure_eight", "fuzzy"), ("tilted_helix", "off"),
    (str(BLADE), "fixed"),
])
def test_fmus_reproduce_the_in_process_simulator(rust_json, fmu_dir, path, mode):
    sim = rust_json("five_axis_dump", "closed_loop", path, mode)
    records = sim["records"]
    steps = len(records)
    before, after = five_axis_closed_loop(fmu_dir, path=path, feed=sim["feed"],
                                          stop=steps * sim["ts"], controller=MODES[mode])
    assert len(before) == steps

    def column(key):
        return np.array([r[key] for r in records], dtype=float)

    for i, j in enumerate(FIVE_AXIS_JOINTS):
        assert np.max(np.abs(before[f"plant.pos.{j}"] - column("actual")[:, i])) < 1e-9, j
        assert np.max(np.abs(before[f"interpolator.ref.{j}"] - column("reference")[:, i])) < 1e-9, j
        assert np.max(np.abs(after[f"controller.u.{j}"] - column("u")[:, i])) < 1e-9, j
    # The per-sample estimates (none before the reference has a segment: the FMU says 0).
    for ours, theirs in (("contourError.tip", "tip_estimate"),
                         ("contourError.orientation", "orientation_estimate")):
        expected = np.nan_to_num(column(theirs), nan=0.0)
        assert np.max(np.abs(after[f"controller.{ours}"] - expected)) < 1e-9, ours
    # The evaluation-function estimate, held from the sample that produced it.
    held = {"tip": 0.0, "orientation": 0.0}
    evaluated = 0
    for k, r in enumerate(records):
        if r["evaluation"] is not None:
            held = r["evaluation"]
            evaluated += 1
            delay = (k - held["sample"]) * sim["ts"]
            assert abs(after["controller.evaluation.delay"][k] - delay) < 1e-12
        assert abs(after["controller.evaluation.tip"][k] - held["tip"]) < 1e-9
        assert abs(after["controller.evaluation.orientation"][k] - held["orientation"]) < 1e-9
    assert evaluated > 0.8 * steps
    # The run is not trivial: the table turned and the tool travelled.
    assert np.ptp(column("actual")[:, 4]) > 1.0 or np.ptp(column("actual")[:, 0]) > 10.0


# ---------------------------------------------------------------------------------------
# Multi-rate: the sampled models fire at every multiple of Ts, whatever the step.

def held_joints(t):
    """Piecewise-constant inputs changing every 5 ms: joints on a tilted circle and
    measured joints trailing them."""
    k = math.floor(t / 0.005 + 1e-9)

    def joints(s):
        return [20 * math.cos(s), 20 * math.sin(s), 0.5 * s, 0.3 + 0.1 * math.sin(s), 0.2 * s]

    return joints(0.05 * k) + joints(0.05 * k - 0.01)


def run_controller(fmu_dir, h, stop=0.2):
    s = Slave(str(fmu_dir / "ContourCCC5X.fmu"))
    s.fmu.exitInitializationMode()
    inputs = [s.vr[n] for n in REF + POS]
    outputs = {}
    for k in range(int(round(stop / h))):
        t = k * h
        s.fmu.setReal(inputs, held_joints(t))
        s.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        outputs[round((k + 1) * h, 9)] = s.reals(CONTROLLER_OUTPUTS)
    s.close()
    return outputs


def test_controller_output_is_independent_of_the_communication_step(fmu_dir):
    runs = {h: run_controller(fmu_dir, h) for h in (0.001, 0.0025, 0.005)}
    shared = sorted(set(runs[0.001]) & set(runs[0.0025]) & set(runs[0.005]))
    assert len(shared) == 40
    for t in shared:
        assert np.array_equal(runs[0.001][t], runs[0.0025][t]), t
        assert np.array_equal(runs[0.001][t], runs[0.005][t]), t
    # The controller acted: a contour error was mapped and corrected.
    last = runs[0.001][shared[-1]]
    assert last[CONTROLLER_OUTPUTS.index("contourError.tip")] > 0.0
    assert np.any(last[:5] != 0.0)


def test_interpolator_output_is_independent_of_the_communication_step(fmu_dir):
    def run(h):
        s = Slave(str(fmu_dir / "PathInterpolator5X.fmu"))
        s.set(path="figure_eight", feed=40.0)
        s.fmu.exitInitializationMode()
        out = {}
        for k in range(int(round(0.2 / h))):
            s.fmu.doStep(currentCommunicationPoint=k * h, communicationStepSize=h)
            out[round((k + 1) * h, 9)] = s.reals(REF)
        s.close()
        return out

    runs = {h: run(h) for h in (0.001, 0.0025, 0.005)}
    shared = sorted(set(runs[0.001]) & set(runs[0.0025]) & set(runs[0.005]))
    assert len(shared) == 40
    for t in shared:
        assert np.array_equal(runs[0.001][t], runs[0.0025][t])
        assert np.array_equal(runs[0.001][t], runs[0.005][t])


def test_plant_trajectory_does_not_depend_on_the_communication_step(fmu_dir):
    """Exact discretisation: commands held 5 ms give the same motion in steps of 1, 2.5
    or 5 ms, to rounding."""
    def run(h):
        s = Slave(str(fmu_dir / "FiveAxisPlant.fmu"))
        s.fmu.exitInitializationMode()
        u = [s.vr[n] for n in U]
        out = {}
        for k in range(int(round(0.1 / h))):
            t = k * h
            n = math.floor(t / 0.005 + 1e-9)
            s.fmu.setReal(u, [10 * math.sin(n), -5.0, 2.0 * n, 0.3 * math.cos(n), 0.5])
            s.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            out[round((k + 1) * h, 9)] = s.reals(POS + [f"vel.{j}" for j in FIVE_AXIS_JOINTS])
        s.close()
        return out

    runs = {h: run(h) for h in (0.001, 0.0025, 0.005)}
    for h in (0.0025, 0.005):
        for t in sorted(set(runs[0.001]) & set(runs[h])):
            assert np.allclose(runs[h][t], runs[0.001][t], rtol=1e-12, atol=1e-12), (h, t)
    assert abs(runs[0.001][0.1][3]) > 1e-4  # the A axis moved


# ---------------------------------------------------------------------------------------
# FMU state: the mapping, the laws' memories and the interpolator's progress.

def fresh_instance(slave, model):
    """A new instance of the same unpacked FMU, instantiated only (fmusim's
    --initial-fmu-state-file flow)."""
    fresh = FMU2Slave(guid=slave.md.guid, unzipDirectory=slave.dir, modelIdentifier=model,
                      instanceName="fresh")
    fresh.instantiate(callbacks=slave.log.callbacks)
    return fresh


def step_controller(fmu, vr, k0, k1):
    inputs = [vr[n] for n in REF + POS]
    out = []
    for k in range(k0, k1):
        fmu.setReal(inputs, held_joints(k * 0.002))
        fmu.doStep(currentCommunicationPoint=k * 0.001, communicationStepSize=0.001)
        out.append(fmu.getReal([vr[n] for n in CONTROLLER_OUTPUTS]))
    return np.array(out)


def test_controller_state_continues_bit_identically_in_a_fresh_instance(controller):
    c = controller
    c.fmu.exitInitializationMode()
    step_controller(c.fmu, c.vr, 0, 120)
    state = c.fmu.getFMUstate()
    saved = c.fmu.serializeFMUstate(state)
    expected = step_controller(c.fmu, c.vr, 120, 200)
    c.fmu.setFMUstate(state)
    assert np.array_equal(step_controller(c.fmu, c.vr, 120, 200), expected)
    c.fmu.freeFMUstate(state)

    fresh = fresh_instance(c, "ContourCCC5X")
    restored = fresh.deSerializeFMUstate(saved)
    fresh.setFMUstate(restored)
    fresh.freeFMUstate(restored)
    assert np.array_equal(step_controller(fresh, c.vr, 120, 200), expected)
    # The evaluation estimate was running (it needs the mapping's history).
    assert expected[-1][CONTROLLER_OUTPUTS.index("evaluation.delay")] > 0.0
    fresh.freeInstance()


BUILTINS = ("tilted_helix", "figure_eight")

# A compensated G-code profile on the five-axis machine: a ramp, G41 with tool 1 (r 2), an
# arc inside which the tool runs on r 3.
GCODE = ("G21 G90\nG0 X0 Y0 Z5\nG1 Z-1 F600\nG1 X5 Z-2\nG41 D1 G1 X10 Y0\nG1 X20\n"
         "G3 X25 Y5 I0 J5\nG1 Y15\nG40 G1 X30 Y15\nG0 Z5\nM30\n")


@pytest.mark.parametrize("path", ["blade", "tilted_helix", "figure_eight", "gcode"])
def test_interpolator_state_continues_in_a_fresh_instance(interpolator, path, tmp_path):
    i = interpolator
    if path == "gcode":
        program = tmp_path / "profile.ngc"
        program.write_text(GCODE)
        i.set(path=str(program), feed=30.0, toolRadii="1:2")
    else:
        i.set(path=str(BLADE) if path == "blade" else path, feed=30.0)
    i.fmu.exitInitializationMode()

    def go(fmu, k0, k1):
        out = []
        for k in range(k0, k1):
            fmu.doStep(currentCommunicationPoint=k * 0.001, communicationStepSize=0.001)
            # The feed-forward outputs too: they read the saved previous sample.
            out.append(fmu.getReal([i.vr[n] for n in REF + VREF + AREF]))
        return np.array(out)

    go(i.fmu, 0, 300)
    state = i.fmu.getFMUstate()
    saved = i.fmu.serializeFMUstate(state)
    i.fmu.freeFMUstate(state)
    # A built-in is saved by name (its 80 001 poses are rebuilt from it), a file's path
    # once: the CL part's 301 poses take 2 × 301 × 24 bytes (22 kB when it was saved twice).
    assert len(saved) < (2_000 if path in BUILTINS else 16_500), len(saved)
    expected = go(i.fmu, 300, 600)
    fresh = fresh_instance(i, "PathInterpolator5X")
    restored = fresh.deSerializeFMUstate(saved)
    fresh.setFMUstate(restored)
    fresh.freeFMUstate(restored)
    assert np.array_equal(go(fresh, 300, 600), expected)
    fresh.freeInstance()


# ---------------------------------------------------------------------------------------
# Bad input

def test_nan_joints_are_refused_and_outputs_stay(controller):
    c = controller
    c.fmu.exitInitializationMode()
    c.fmu.setReal([c.vr[n] for n in REF + POS], held_joints(0.0))
    c.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.001)
    before = c.reals(CONTROLLER_OUTPUTS + POS)
    for name in ("pos.A", "ref.C"):
        with pytest.raises(FMICallException) as failure:
            c.set(**{name.replace(".", "__"): float("nan")})
        assert failure.value.status == 3  # fmi2Error
        assert any(f"'{name}' refuses the non-finite value NaN" in m for m in c.log.errors())
    assert np.array_equal(c.reals(CONTROLLER_OUTPUTS + POS), before)


def test_a_vertical_tool_at_a_equal_zero_keeps_every_output_finite(controller):
    """A = 0 puts the tool on the C axis: C no longer turns it and the Jacobian loses
    rank; the damped inverse keeps the correction bounded, never NaN."""
    c = controller
    c.fmu.exitInitializationMode()
    inputs = [c.vr[n] for n in REF + POS]
    for k in range(200):
        s = 0.002 * k
        ref = [10 * math.cos(s), 10 * math.sin(s), 0.0, 0.0, 0.0]
        pos = [10 * math.cos(s - 0.01) + 0.01, 10 * math.sin(s - 0.01), 0.0, 0.0, 0.3]
        c.fmu.setReal(inputs, ref + pos)
        c.fmu.doStep(currentCommunicationPoint=k * 0.001, communicationStepSize=0.001)
        out = c.reals(CONTROLLER_OUTPUTS)
        assert np.all(np.isfinite(out)), k
    assert out[CONTROLLER_OUTPUTS.index("contourError.tip")] > 1e-3
    assert np.max(np.abs(out[:5])) < 1e3


@pytest.mark.parametrize("fixture, values, words", [
    ("controller", {"Ts": 0.0}, "parameter 'Ts' must be at least 1e-6 s (got 0)"),
    ("controller", {"damping": 0.0}, "parameter damping = 0 is invalid"),
    ("controller", {"toolLength": -5.0}, "parameter toolLength = -5 is invalid"),
    ("controller", {"hmm__beam": 0.0}, "parameter hmm.beam = 0 is invalid"),
    ("controller", {"tip__limit": 0.0}, "parameter tip.limit = 0 is invalid"),
    ("controller", {"orientation__limit": 0.0}, "parameter orientation.limit = 0 is invalid"),
    ("interpolator", {"feed": 0.0}, "parameter 'feed' must be > 0"),
    ("interpolator", {"Ts": 1e-9}, "parameter 'Ts' must be at least 1e-6 s"),
    ("interpolator", {"path": "spiral"}, "unknown five-axis path \"spiral\""),
    ("interpolator", {"path": "/nowhere/part.cl"}, "/nowhere/part.cl"),
])
def test_bad_parameters_are_refused_when_initialization_ends(request, fixture, values, words):
    s = request.getfixturevalue(fixture)
    s.set(**values)
    with pytest.raises(FMICallException):
        s.fmu.exitInitializationMode()
    assert any(words in m for m in s.log.errors()), s.log.errors()


def test_an_integer_parameter_out_of_range_is_refused_and_the_old_one_kept(controller):
    band = controller.vr["hmm.band"]
    with pytest.raises(FMICallException):
        controller.fmu.setInteger([band], [1])
    assert controller.log.errors()[-1].endswith("variable 'hmm.band' = 1 is below its minimum 2")
    assert controller.fmu.getInteger([band]) == [128]
    controller.fmu.exitInitializationMode()


def test_cl_files_with_a_malformed_record_or_no_motion_name_the_file_and_line(interpolator, tmp_path):
    broken = tmp_path / "broken.cl"
    broken.write_text("PARTNO/TEST\nMULTAX\nGOTO/0,0,0,0,0,1\nGOTO/1,2,abc,0,0,1\n")
    interpolator.set(path=str(broken))
    with pytest.raises(FMICallException):
        interpolator.fmu.exitInitializationMode()
    assert any(f"{broken}:4" in m for m in interpolator.log.errors()), interpolator.log.errors()

    empty = tmp_path / "empty.cl"
    empty.write_text("PARTNO/NOTHING\n$$ no motion\nFINI\n")
    interpolator.set(path=str(empty))
    with pytest.raises(FMICallException):
        interpolator.fmu.exitInitializationMode()
    assert any(str(empty) in m and "GOTO" in m for m in interpolator.log.errors()), \
        interpolator.log.errors()


def test_a_cl_axis_far_from_unit_is_normalised_with_a_warning(interpolator, tmp_path):
    part = tmp_path / "tilted.cl"
    part.write_text("GOTO/0,0,0,0,0,2\nGOTO/10,0,0,0,0.5,0.5\n")
    interpolator.fmu.setDebugLogging(True, ["logStatusWarning"])
    interpolator.set(path=str(part), feed=10.0)
    interpolator.fmu.exitInitializationMode()
    assert any("tilted.cl" in m for m in interpolator.log.warnings()), interpolator.log.messages
    # 10 mm at 10 mm/s, planned: a second and the ramps.
    interpolator.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=2.0)
    # At the end: the tip at x = 10 and the axis (0, 1, 1)/√2, so A = 45° and C = 0.
    x, y, z, a, c = interpolator.reals(REF)
    assert abs(a - math.pi / 4) < 1e-12 and abs(c) < 1e-12


def test_a_cl_file_in_the_fmus_resources_folder_is_found_by_its_relative_name(interpolator):
    resources = Path(interpolator.dir) / "resources"
    resources.mkdir(exist_ok=True)
    (resources / "line.cl").write_text("GOTO/1,2,3,0,0,1\nGOTO/5,2,3,0,0,1\n")
    # At constant feed (no plan), so that the second's travel is exact.
    interpolator.set(path="line.cl", feed=2.0, accel=0.0)
    interpolator.fmu.exitInitializationMode()
    assert np.allclose(interpolator.reals(REF), [1, 2, 3, 0, 0])
    interpolator.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=1.0)
    assert np.allclose(interpolator.reals(REF), [3, 2, 3, 0, 0], atol=1e-9)


NX_SPEEDS = """TOOL PATH/OP010,TOOL,EM_10
TLDATA/MILL,10.0000,0.0000,75.0000,0.0000,0.0000
PAINT/COLOR,211
GOTO/0.0000,0.0000,0.0000,0.0000000,0.0000000,1.0000000
GOTO/20.0000,0.0000,0.0000,0.0000000,0.0000000,1.0000000
FEDRAT/MMPM,600.0000
GOTO/60.0000,0.0000,0.0000,0.0000000,0.0000000,1.0000000
PAINT/COLOR,186
RAPID
GOTO/60.0000,0.0000,60.0000,0.0000000,0.0000000,1.0000000
GOTO/100.0000,0.0000,60.0000,0.0000000,0.0000000,1.0000000
END-OF-PATH
"""


def run_tip(interpolator, seconds):
    """Steps the interpolator 1 ms at a time until done (at most `seconds`); the tip's
    speed between samples (the tool stays vertical, so X, Y, Z are the tip)."""
    i = interpolator
    tips = [i.reals(REF)[:3]]
    for k in range(int(seconds * 1000)):
        i.fmu.doStep(currentCommunicationPoint=k * 1e-3, communicationStepSize=1e-3)
        tips.append(i.reals(REF)[:3])
        if i.fmu.getBoolean([i.vr["done"]])[0]:
            break
    tips = np.array(tips)
    return tips, np.linalg.norm(np.diff(tips, axis=0), axis=1) / 1e-3


def test_a_cl_files_feeds_win_over_the_feed_parameter_and_its_rapids_run_at_rapid(
        interpolator, tmp_path):
    part = tmp_path / "speeds.cls"
    part.write_text(NX_SPEEDS)
    # 20 mm at the `feed` parameter (before the first FEDRAT), 40 mm at 600 mm/min,
    # 60 mm at `rapid`, 40 mm at 600 mm/min again (a RAPID holds for one GOTO).
    interpolator.set(path=str(part), feed=40.0, rapid=120.0)
    interpolator.fmu.exitInitializationMode()
    duration = interpolator.reals(["plannedDuration"])[0]
    tips, speed = run_tip(interpolator, 20.0)
    assert np.allclose(tips[-1], [100, 0, 60], atol=1e-9)
    first = tips[1:, 0] < 19.0
    feed = (tips[1:, 0] > 21.0) & (tips[1:, 2] < 1e-9) & (tips[1:, 0] < 59.0)
    rapid = (tips[1:, 2] > 1.0) & (tips[1:, 2] < 59.0)
    back = tips[1:, 0] > 61.0
    assert 39.0 < speed[first].max() <= 40.0 * (1 + 1e-6)
    # The jerk filter carries a speed change over its 25 ms: 40 mm/s runs 1 mm into the
    # 10 mm/s move.
    assert 9.9 < speed[feed & (tips[1:, 0] > 22.0)].max() <= 10.0 * (1 + 1e-6)
    assert 119.0 < speed[rapid].max() <= 120.0 * (1 + 1e-6)
    assert 9.9 < speed[back].max() <= 10.0 * (1 + 1e-6)
    # No faster than every move at its own speed.
    assert duration >= 20 / 40 + 40 / 10 + 60 / 120 + 40 / 10

    # The rapid at half the speed: its 60 mm take 0.5 s longer at speed, 0.03 s less
    # accelerating to it.
    interpolator.fmu.reset()
    interpolator.fmu.setupExperiment(startTime=0.0)
    interpolator.fmu.enterInitializationMode()
    interpolator.set(path=str(part), feed=40.0, rapid=60.0)
    interpolator.fmu.exitInitializationMode()
    slower = interpolator.reals(["plannedDuration"])[0]
    assert 0.42 < slower - duration < 0.52, (slower, duration)


def test_without_a_plan_a_cl_files_speeds_are_not_followed_and_it_says_so(interpolator, tmp_path):
    part = tmp_path / "speeds.cls"
    part.write_text(NX_SPEEDS)
    interpolator.fmu.setDebugLogging(True, ["logStatusWarning"])
    interpolator.set(path=str(part), feed=40.0, accel=0.0)
    interpolator.fmu.exitInitializationMode()
    assert any("FEDRAT and RAPID" in m for m in interpolator.log.warnings()), \
        interpolator.log.messages
    _, speed = run_tip(interpolator, 10.0)
    assert np.allclose(speed[5:-5], 40.0, rtol=1e-6)


TURN_ON_THE_SPOT = ("GOTO/0,0,0,0,0,1\nGOTO/0,0,0,0,0,1\nGOTO/10,0,0,0,0,1\n"
                    "GOTO/10,0,0,0,0.6,0.8\nGOTO/20,0,0,0,0.6,0.8\n")


def test_a_cl_tool_turning_on_the_spot_is_planned(interpolator, tmp_path):
    part = tmp_path / "turn.cls"
    part.write_text(TURN_ON_THE_SPOT)
    interpolator.set(path=str(part), feed=20.0)
    interpolator.fmu.exitInitializationMode()
    i = interpolator
    joints = [i.reals(REF)]
    for k in range(10_000):
        i.fmu.doStep(currentCommunicationPoint=k * 1e-3, communicationStepSize=1e-3)
        joints.append(i.reals(REF))
        if i.fmu.getBoolean([i.vr["done"]])[0]:
            break
    tips, axes = forward(np.array(joints))
    tilt = np.arccos(np.clip(axes[:, 2], -1.0, 1.0))
    final = math.atan2(0.6, 0.8)
    # The tool tilts 36.87° (A) while the tip stands at x = 10, within the plan's
    # tolerance (5 µm, the corners blended); the tip never leaves the line.
    assert np.max(np.abs(tips[:, 1:])) < 1e-6
    turning = (tilt > 1e-3) & (tilt < final - 1e-3)
    assert turning.sum() > 50, "the turn takes time"
    assert np.max(np.abs(tips[turning, 0] - 10.0)) < 5e-3
    assert abs(joints[-1][3] - final) < 1e-9
    assert np.allclose(tips[-1], [20, 0, 0], atol=1e-9)


def test_at_constant_feed_a_tool_turning_on_the_spot_is_refused(interpolator, tmp_path):
    part = tmp_path / "turn.cls"
    part.write_text(TURN_ON_THE_SPOT)
    interpolator.set(path=str(part), accel=0.0)
    with pytest.raises(FMICallException):
        interpolator.fmu.exitInitializationMode()
    # The repeated GOTO (line 2) is left out: poses 1 and 2 are lines 3 and 4.
    assert any("turns on the spot from pose 1 to pose 2" in m and "accel > 0" in m
               for m in interpolator.log.errors()), interpolator.log.errors()


def test_cross_check_files_reproduce_through_simulate_fmu(fmu_dir, tmp_path):
    before, after = five_axis_closed_loop(fmu_dir, path="tilted_helix", stop=0.3)
    write_cross_check(tmp_path, "ContourCCC5X", before, after, five_axis_demo.CROSS_CHECK_INPUTS,
                      five_axis_demo.CROSS_CHECK_OUTPUTS, 1e-3)
    folder = tmp_path / "cross-check" / "ContourCCC5X"
    inputs = read_csv(folder / "ContourCCC5X_in.csv")
    reference = read_csv(folder / "ContourCCC5X_ref.csv")
    options = dict(line.split(",") for line in (folder / "ContourCCC5X_ref.opt").read_text().split())
    result = simulate_fmu(str(fmu_dir / "ContourCCC5X.fmu"), stop_time=float(options["StopTime"]),
                          step_size=float(options["StepSize"]), output_interval=float(options["StepSize"]),
                          input=inputs, output=list(reference.dtype.names[1:]))
    assert len(result) == len(reference)
    for name in reference.dtype.names[1:]:
        assert np.max(np.abs(result[name] - reference[name])) < 1e-9, name
    assert np.max(np.abs(reference["u.C"])) > 0.1 and np.max(reference["contourError.tip"]) > 1e-3


def test_the_example_cl_part_ships_in_the_interpolators_resources(interpolator):
    interpolator.set(path="blade.cl")
    interpolator.fmu.exitInitializationMode()
    interpolator.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.1)
    assert np.all(np.isfinite(interpolator.reals(REF)))
    assert (Path(interpolator.dir) / "resources" / "blade.cl").read_text() == BLADE.read_text()


def test_switching_the_evaluation_estimate_off_changes_no_command(fmu_dir):
    """The evaluation-function estimate is a diagnostic: without it the loop is the same."""
    on = five_axis_closed_loop(fmu_dir, path="figure_eight", stop=0.3)[1]
    off = five_axis_closed_loop(fmu_dir, path="figure_eight", stop=0.3,
                                controller={"evaluation.enable": False})[1]
    for j in FIVE_AXIS_JOINTS:
        assert np.array_equal(on[f"controller.u.{j}"], off[f"controller.u.{j}"]), j
    assert np.all(off["controller.evaluation.tip"] == 0.0)
    assert np.max(on["controller.evaluation.tip"]) > 0.0
