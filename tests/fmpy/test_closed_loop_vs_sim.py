"""The FMU closed loop reproduces the in-process simulator (`contour_fmu::sim`): the same
algorithms behind the FMI boundary, so the same numbers to 1e-9 mm."""

import numpy as np
import pytest

from contour_fmu.engines.master import closed_loop

CASES = [("circle", "fuzzy"), ("infinity", "fuzzy"), ("trident", "fuzzy"), ("circle", "off"), ("trident", "fixed")]
CONTROLLER = {"off": {"ccc.enable": False}, "fixed": {"fuzzy.enable": False}, "fuzzy": {}}


@pytest.mark.parametrize("path, mode", CASES)
def test_fmus_reproduce_the_in_process_simulator(rust_json, fmu_dir, path, mode):
    sim = rust_json("closed_loop_dump", path, "paper", mode)
    t = np.array(sim["trace"]["t"])
    steps = len(t)
    before, after = closed_loop(fmu_dir, path=path, feed=sim["feed"], stop=steps * sim["ts"],
                                controller=CONTROLLER[mode])
    assert len(before) == steps
    actual = np.array(sim["trace"]["actual"])
    reference = np.array(sim["trace"]["reference"])
    u = np.array(sim["trace"]["u"])
    assert np.max(np.abs(before["plant.pos.x"] - actual[:, 0])) < 1e-9
    assert np.max(np.abs(before["plant.pos.y"] - actual[:, 1])) < 1e-9
    assert np.max(np.abs(before["interpolator.ref.x"] - reference[:, 0])) < 1e-9
    assert np.max(np.abs(before["interpolator.ref.y"] - reference[:, 1])) < 1e-9
    assert np.max(np.abs(after["controller.u.x"] - u[:, 0])) < 1e-9
    assert np.max(np.abs(after["controller.contourError"] - np.array(sim["trace"]["estimated_error"]))) < 1e-9
    # The run is not trivial: the tool moved along the path.
    assert np.ptp(actual[:, 0]) > 15.0
