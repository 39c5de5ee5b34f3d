"""The FMI 3.0 FMUs (target/fmu3, target/fmu3-si) through fmpy: each passes fmpy's
validation (schema and rules); each model, simulated by fmpy alone over its default
experiment, gives through FMI 3.0 the FMI 2.0 FMU's results bit for bit; and the shipped
two-axis and five-axis loops, run by the fmpy master (FMU3Slave) on the FMI 3.0 FMUs, give
the FMI 2.0 trajectories bit for bit, in mm and SI, also with the standards mixed. (The
drive loop through FMI 3.0: tests/fmpy/test_drive_loop.py.)"""

from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

from contour_fmu.engines.fmu_log import FmuLog
from contour_fmu.engines.master import (CLOSED_LOOP_RECORD, Master, Unit, closed_loop,
                                        five_axis_closed_loop, loop_units)
from contour_fmu.loops.wiring import LOOPS, TWO_AXIS

MODELS = ["XYServoPlant", "ContourCCC2D", "PathInterpolator2D", "FiveAxisPlant", "ContourCCC5X",
          "PathInterpolator5X", "ServoDrive", "ServoDriveRotary"]


def pairs(fmu_dir):
    """(FMI 2.0 FMU, FMI 3.0 FMU) of every model in both unit systems."""
    target = fmu_dir.parent
    return [(target / two / f"{model}.fmu", target / three / f"{model}.fmu")
            for two, three in (("fmu", "fmu3"), ("fmu-si", "fmu3-si")) for model in MODELS]


def test_every_fmi3_fmu_passes_fmpy_validation(fmu_dir):
    for _, fmu3 in pairs(fmu_dir):
        description = read_model_description(str(fmu3), validate=True)
        assert description.fmiVersion == "3.0", fmu3
        assert description.coSimulation is not None and description.modelExchange is None
        assert validate_fmu(str(fmu3)) == [], fmu3
        independent = [v for v in description.modelVariables if v.causality == "independent"]
        assert [v.name for v in independent] == ["time"], fmu3


@pytest.mark.parametrize("index", range(2 * len(MODELS)))
def test_fmpy_simulates_each_model_through_fmi3_as_through_fmi2_bit_for_bit(fmu_dir, index):
    fmu2, fmu3 = pairs(fmu_dir)[index]
    two = read_model_description(str(fmu2))
    outputs = [v.name for v in two.modelVariables if v.causality == "output"]
    experiment = two.defaultExperiment  # fmpy keeps its attributes as text
    stop = min(float(experiment.stopTime), 200 * float(experiment.stepSize))
    results = [simulate_fmu(str(fmu), stop_time=stop, output=outputs, validate=False)
               for fmu in (fmu2, fmu3)]
    assert len(results[0]) == len(results[1]) > 100
    for name in ["time", *outputs]:
        a, b = (np.asarray(r[name], dtype=np.float64) for r in results)
        assert np.array_equal(a.view(np.uint64), b.view(np.uint64)), f"{fmu3.name}: {name}"


def bits(table):
    """Every column of a structured array, as the bits of its float64 values."""
    return {name: np.asarray(table[name], dtype=np.float64).view(np.uint64) for name in table.dtype.names}


def assert_same_bits(a, b, label):
    for name, column in bits(a).items():
        assert np.array_equal(column, bits(b)[name]), f"{label}: {name}"


def test_the_two_axis_loops_through_fmi3_give_the_fmi2_trajectories_bit_for_bit(fmu_dir):
    fmu3 = fmu_dir.parent / "fmu3"
    for controller in (None, LOOPS["two_axis"].feed_forward):
        for path in ("circle", "infinity"):
            runs = [closed_loop(d, path=path, stop=0.6, controller=controller) for d in (fmu_dir, fmu3)]
            for phase in (0, 1):
                assert_same_bits(runs[0][phase], runs[1][phase], f"{path} {controller}")
    # The SI build too.
    runs = [closed_loop(fmu_dir.parent / d, stop=0.4) for d in ("fmu-si", "fmu3-si")]
    assert_same_bits(runs[0][0], runs[1][0], "SI circle")


def test_the_five_axis_loop_through_fmi3_gives_the_fmi2_trajectory_bit_for_bit(fmu_dir):
    runs = [five_axis_closed_loop(d, stop=0.4) for d in (fmu_dir, fmu_dir.parent / "fmu3")]
    for phase in (0, 1):
        assert_same_bits(runs[0][phase], runs[1][phase], "five-axis")


def test_a_loop_of_both_standards_is_the_loop_of_either(fmu_dir):
    """An FMI 3.0 controller between an FMI 2.0 plant and interpolator: the master mixes
    standards, and the trajectory is the same."""
    fmu3 = fmu_dir.parent / "fmu3"
    units = loop_units(TWO_AXIS, fmu_dir, {"interpolator": {"path": "circle"}})
    mixed = [Unit(u.name, str(fmu3 / Path(u.path).name) if u.name == "controller" else u.path,
                  u.start_values) for u in units]
    runs = []
    for chosen in (units, mixed):
        with Master(chosen, TWO_AXIS.connections, 1e-3, 0.4, initial=TWO_AXIS.initial_copies) as m:
            runs.append(m.run(CLOSED_LOOP_RECORD))
    assert_same_bits(runs[0][0], runs[1][0], "mixed")


def test_an_fmi3_instance_logs_through_fmi3s_callback(fmu_dir):
    """The FMI 3.0 log callback takes the message itself: a refused start value arrives
    whole, with the instance's name from the master."""
    log = FmuLog()
    fmu3 = fmu_dir.parent / "fmu3"
    units = [Unit("plant", str(fmu3 / "XYServoPlant.fmu"), {"x.J": -1.0})]
    with pytest.raises(Exception):
        with Master(units, [], 1e-3, 0.01, log=log):
            pass
    assert any(name == "plant" and "x.J" in message and "-1" in message
               for name, _status, _category, message in log.records), log.records


DATA = Path(__file__).resolve().parents[1] / "data"


@pytest.mark.parametrize("program", ["own-style/fusion360-makera-style.nc",
                                     "cambam/enclosure-labels.nc",
                                     "own-style/fanuc-inventor-hsm-style.nc"])
def test_users_cam_programs_through_fmi3_give_the_fmi2_trajectories_bit_for_bit(fmu_dir, program):
    """Public and CAM-shaped G-code (tests/data/cam/README.md names their sources), planned
    within acceleration and jerk limits, in the shipped loop with the program estimator."""
    part = str(DATA / "cam" / program)
    controller = {**LOOPS["two_axis"].feed_forward, "estimator": 4, "path": part}
    interpolator = {"accel": 2000.0, "jerk": 100000.0}
    runs = [closed_loop(d, path=part, stop=1.5, controller=controller, interpolator=interpolator)
            for d in (fmu_dir, fmu_dir.parent / "fmu3")]
    moved = max(np.ptp(runs[0][0][f"interpolator.ref.{axis}"]) for axis in "xy")
    assert moved > 0.1, f"the program moved the axes {moved} mm"
    for phase in (0, 1):
        assert_same_bits(runs[0][phase], runs[1][phase], program)


def test_cl_data_through_the_pole_and_from_creo_through_fmi3_give_the_fmi2_trajectories(fmu_dir,
                                                                                      tmp_path):
    """Five-axis CL data: a raster over a dome's apex (the tool axis through the pole) and a
    Creo CL file (tests/data/cl/README.md), the FMI 3.0 loop against the FMI 2.0 one."""
    from contour_fmu.demo import cam_paths
    dome = tmp_path / "dome.cl"
    dome.write_text(cam_paths.dome_raster())
    for cl in (dome, DATA / "cl" / "profilfraesen_2.ncl"):
        runs = [five_axis_closed_loop(d, path=str(cl), feed=50.0, stop=0.8)
                for d in (fmu_dir, fmu_dir.parent / "fmu3")]
        for phase in (0, 1):
            assert_same_bits(runs[0][phase], runs[1][phase], cl.name)
