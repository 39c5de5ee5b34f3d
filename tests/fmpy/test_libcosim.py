"""XYServoPlant in a second importer, libcosim (through libcosimpy), in a subprocess."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np

from helpers.plant_reference import PAPER_AXIS, simulate_axis

HERE = Path(__file__).resolve().parent


def test_steps_in_libcosim_and_matches_scipy(xy_plant_fmu):
    step_ns, steps = 1_000_000, 200  # 1 ms steps for 0.2 s
    u_x, u_y = 25.0, -10.0
    done = subprocess.run(
        [sys.executable, str(HERE / "helpers" / "cosim_run.py"), xy_plant_fmu, str(step_ns),
         str(steps),
         f"0={u_x}", f"1={u_y}", "--observe", "2", "3"],
        capture_output=True, text=True, timeout=120,
    )
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout.strip().splitlines()[-1])
    assert result["time_ns"] == step_ns * steps
    times = np.arange(steps + 1) * 1e-3
    pos_x, _ = simulate_axis(PAPER_AXIS, times, np.full(steps + 1, u_x))
    pos_y, _ = simulate_axis(PAPER_AXIS, times, np.full(steps + 1, u_y))
    assert abs(result["values"][0] - pos_x[-1]) < 1e-6
    assert abs(result["values"][1] - pos_y[-1]) < 1e-6
