"""The SI build (`target/fmu-si/`, written by `make fmus` beside the mm build): every FMU
validates, declares metres where the mm build declares millimetres (starts and bounds
scaled by the unit's factor, everything else the same, a GUID of its own), and both
closed loops through the SI FMUs in fmpy run the mm loops' trajectories in metres to
1e-12 relative."""

import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from contour_fmu.engines.master import closed_loop, five_axis_closed_loop

# The mm build's length units and their SI counterparts (SI value = 1e-3 × mm value).
SI_OF = {"mm": "m", "mm/s": "m/s", "mm/s2": "m/s2", "mm/s3": "m/s3", "mm/rad": "m/rad"}
# Per-length units (the servo drives' gains): SI value = 1e3 × mm value.
SI_OF_PER_LENGTH = {"N.s/mm": "N.s/m", "N/mm": "N/m"}


@pytest.fixture(scope="module")
def si_dir(fmu_dir):
    return fmu_dir.parent / "fmu-si"


def test_every_si_fmu_validates_and_declares_metres(fmu_dir, si_dir):
    mm_fmus = sorted(fmu_dir.glob("*.fmu"))
    assert [f.name for f in mm_fmus] == sorted(f.name for f in si_dir.glob("*.fmu"))
    for mm_fmu in mm_fmus:
        si_fmu = si_dir / mm_fmu.name
        assert validate_fmu(str(si_fmu)) == [], si_fmu
        mm, si = read_model_description(str(mm_fmu)), read_model_description(str(si_fmu))
        assert mm.guid != si.guid
        assert mm.coSimulation.modelIdentifier == si.coSimulation.modelIdentifier
        assert not [u.name for u in si.unitDefinitions if u.name.startswith("mm")]
        for u in si.unitDefinitions:
            # Every declared unit is SI: a factor of 1 to its base units.
            assert float(u.baseUnit.factor) == 1.0, (si_fmu.name, u.name)
        for a, b in zip(mm.modelVariables, si.modelVariables, strict=True):
            assert (a.name, a.valueReference, a.causality, a.variability) == (
                b.name, b.valueReference, b.causality, b.variability)
            factor = 1e-3 if a.unit in SI_OF else 1e3 if a.unit in SI_OF_PER_LENGTH else 1.0
            assert b.unit == {**SI_OF, **SI_OF_PER_LENGTH}.get(a.unit, a.unit), a.name
            for attribute in ("start", "min", "max"):
                x, y = getattr(a, attribute), getattr(b, attribute)
                if a.type == "Real" and x is not None:
                    assert float(y) == float(x) * factor, (a.name, attribute, x, y)
                else:
                    assert x == y, (a.name, attribute)


def compare_in_metres(mm, si, model_description_of):
    """Every recorded column of `si` equals `mm`'s times the unit's factor (1e-3 for a
    length, from the SI model description of the column's unit). The trajectories (every
    length) to 1e-12 of the largest length in the loop (a contour error is a difference of
    positions, rounded at their scale); the rest (the fuzzy system's gains, angles) to
    1e-9 of the column's largest value: the gains follow the contour error through the
    fuzzy sets' slopes, which magnify its rounding (1e-11 seen)."""
    columns = {c: c.split(".", 1) for c in mm.dtype.names[1:]}
    is_length = {c: model_description_of[u][n].unit in SI_OF.values()
                 for c, (u, n) in columns.items()}
    largest_length = max(np.max(np.abs(mm[c])) for c in columns if is_length[c])
    for column in columns:
        factor = 1e-3 if is_length[column] else 1.0
        scale = largest_length if is_length[column] else np.max(np.abs(mm[column]))
        off = np.max(np.abs(si[column] / factor - mm[column])) / max(scale, 1e-9)
        assert off <= (1e-12 if is_length[column] else 1e-9), (column, off)


def variables_of(directory, files):
    return {unit: {v.name: v for v in read_model_description(str(directory / f)).modelVariables}
            for unit, f in files.items()}


def test_the_si_two_axis_loop_is_the_mm_loop_in_metres(fmu_dir, si_dir):
    # The planned circle: the limits in each build's own units.
    limits = {"accel": 2000.0, "jerk": 1e5}
    mm = closed_loop(fmu_dir, stop=1.5, interpolator=limits)
    si = closed_loop(si_dir, stop=1.5, interpolator={k: v * 1e-3 for k, v in limits.items()})
    files = {"controller": "ContourCCC2D.fmu", "plant": "XYServoPlant.fmu",
             "interpolator": "PathInterpolator2D.fmu"}
    described = variables_of(si_dir, files)
    for a, b in zip(mm, si):
        compare_in_metres(a, b, described)
    # The loop moved: the circle is 10 mm = 0.01 m in radius.
    assert np.max(np.abs(si[0]["interpolator.ref.x"])) > 0.009


def test_the_si_five_axis_loop_is_the_mm_loop_in_metres(fmu_dir, si_dir):
    mm = five_axis_closed_loop(fmu_dir, stop=0.5)
    si = five_axis_closed_loop(si_dir, stop=0.5)
    files = {"controller": "ContourCCC5X.fmu", "plant": "FiveAxisPlant.fmu",
             "interpolator": "PathInterpolator5X.fmu"}
    described = variables_of(si_dir, files)
    # ContourCCC5X's evaluation.* outputs (the delayed evaluation-function estimate) are
    # left out: in the mm build alone, the plant's X.J changed by 1e-14 (relative) moves
    # them by up to 0.24 um and 5 urad on most samples while every trajectory and the
    # contour error move by 1e-14: they amplify rounding, whatever the units.
    kept = [c for c in mm[0].dtype.names if ".evaluation." not in c]
    for a, b in zip(mm, si):
        compare_in_metres(a[kept], b[kept], described)


def test_the_master_refuses_a_loop_that_mixes_the_builds_naming_the_connection(fmu_dir, si_dir):
    """An mm controller on an SI plant would command metres as millimetres: the master
    reads the declared units of both ends of every connection before it starts an FMU."""
    from contour_fmu.engines.master import Master, Unit
    from contour_fmu.loops.wiring import CLOSED_LOOP_CONNECTIONS, PATH_START

    def loop(plant_dir, connections=CLOSED_LOOP_CONNECTIONS):
        units = [Unit("controller", str(fmu_dir / "ContourCCC2D.fmu")),
                 Unit("plant", str(plant_dir / "XYServoPlant.fmu")),
                 Unit("interpolator", str(fmu_dir / "PathInterpolator2D.fmu"))]
        return Master(units, connections, 1e-3, 0.01, initial=PATH_START)

    with pytest.raises(ValueError, match=r"plant\.pos\.x -> controller\.pos\.x: units differ "
                                         r"\(m onto mm\)"):
        loop(si_dir).__enter__()
    with pytest.raises(ValueError, match=r"interpolator has no variable 'ref\.z'"):
        loop(fmu_dir, CLOSED_LOOP_CONNECTIONS + [("interpolator", "ref.z", "controller", "ref.x")]
             ).__enter__()
    with pytest.raises(ValueError, match=r"interpolator\.done -> controller\.ref\.x: a Boolean "
                                         r"onto a Real"):
        loop(fmu_dir, CLOSED_LOOP_CONNECTIONS + [("interpolator", "done", "controller", "ref.x")]
             ).__enter__()
    # One build throughout runs.
    with loop(fmu_dir) as master:
        assert master.get("plant", "pos.x") == master.get("interpolator", "ref.x")


def test_an_si_model_says_its_messages_numbers_are_in_mm(fmu_dir, si_dir):
    """The model computes in mm and its messages quote its own values; the SI build says
    so wherever a message has numbers, the mm build says nothing."""
    from fmpy.fmi1 import FMICallException

    from helpers.fmu_slave import Slave

    note = "lengths in this message in mm, the model's own unit: 1 mm = 0.001 m"
    # A radius of -2 mm: -0.002 in the SI build.
    for directory, radius, noted in ((fmu_dir, -2.0, False), (si_dir, -0.002, True)):
        s = Slave(str(directory / "PathInterpolator2D.fmu"))
        try:
            s.set(path="arc", **{"arc.r": radius})
            with pytest.raises(FMICallException):
                s.fmu.exitInitializationMode()
            (error,) = s.log.errors()
            assert "arc radius must be > 0, got -2" in error
            assert (note in error) == noted, error
        finally:
            s.close()
