"""Direction of travel through the FMUs: the closed loop PathInterpolator2D ->
ContourCCC2D <- XYServoPlant on a full circle run counter-clockwise (sweep +2π) and on
its mirror image run clockwise (centre (cx, -cy), start -a0, sweep -2π) gives, sample by
sample, the negated signed contour error and mirrored positions; the same for the
trident and its mirror image from a NURBS file. With the fuzzy CCC at the paper's factors
and at a large-kp set, the kind a tuner finds, where an asymmetric schedule showed most."""

import math

import numpy as np
import pytest

from contour_fmu.demo import paper
from contour_fmu.engines.master import closed_loop

LARGE_KP = {"fuzzy.ke": 3.0, "fuzzy.kde": 0.5, "fuzzy.kp": 300.0, "fuzzy.ki": 0.0, "fuzzy.kd": 3.0}
CONTROLLERS = {"paper factors": {}, "large kp": LARGE_KP, "no CCC": {"ccc.enable": False}}


def arc(cx, cy, start, sweep):
    return {"path": "arc", "arc.cx": cx, "arc.cy": cy, "arc.r": 12.0, "arc.start": start, "arc.sweep": sweep}


def assert_mirrored(a, b):
    before_a, after_a = a
    before_b, after_b = b
    assert len(after_a) == len(after_b) > 1000
    error = after_a["controller.contourError"]
    assert np.abs(error).max() > 1e-4  # there is contour error to mirror (mm)
    assert np.abs(error + after_b["controller.contourError"]).max() <= 1e-12
    assert np.abs(before_a["plant.pos.x"] - before_b["plant.pos.x"]).max() <= 1e-12
    assert np.abs(before_a["plant.pos.y"] + before_b["plant.pos.y"]).max() <= 1e-12
    for gain in ("ccc.Kp", "ccc.Ki", "ccc.Kd"):
        # Same gains; not bit-identical where ε differs in its last bits (1e-12 mm above).
        np.testing.assert_allclose(after_a[f"controller.{gain}"], after_b[f"controller.{gain}"],
                                   rtol=1e-9, atol=1e-9, err_msg=gain)


@pytest.mark.parametrize("controller", CONTROLLERS, ids=list(CONTROLLERS))
def test_counter_clockwise_and_clockwise_circles_give_mirrored_runs(fmu_dir, controller):
    stop = 2 * math.pi * 12.0 / (10 * math.pi)  # one turn at the paper's feed: 2.4 s
    runs = [closed_loop(fmu_dir, feed=10 * math.pi, stop=stop, controller=CONTROLLERS[controller],
                        interpolator=geometry)
            for geometry in (arc(-5.0, 3.0, 0.4, 2 * math.pi), arc(-5.0, -3.0, -0.4, -2 * math.pi))]
    assert_mirrored(*runs)


def test_trident_and_its_mirror_image_from_a_file_give_mirrored_runs(fmu_dir, tmp_path):
    mirror = paper.mirrored_interpolator("trident", tmp_path)
    runs = [closed_loop(fmu_dir, path="trident", feed=50.0, stop=2.0, controller=LARGE_KP,
                        interpolator=geometry) for geometry in (None, mirror)]
    assert_mirrored(*runs)
