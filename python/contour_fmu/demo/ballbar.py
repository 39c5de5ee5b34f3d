"""Demo: the ballbar demo, the circular test of ISO 230-4 on XYServoPlant with friction,
through the FMUs, without CCC, with the fuzzy-PID CCC, and with the CCC and velocity
feed-forward.

As a ballbar test runs it: a 50 mm circle at F1000 (mm/min) about the origin, entered
and left along half-circle arcs of half the radius from the centre (so the start transient
is not the circle's deviation), counter-clockwise and clockwise, planned within
`ACCEL` and `JERK`. The plant's axes carry Coulomb, static and Stribeck friction, which
makes the quadrant glitches. `contour-eval --circle` (the Rust tool) gives the figures on
the samples whose reference is on the circle, and draws out/ballbar_<controller>.png.

usage: python -m contour_fmu.demo.ballbar [--fmu-dir DIR] [--out DIR]
"""

import argparse
import json
import re
import subprocess
from pathlib import Path

import numpy as np

from .. import repo
from ..engines.master import closed_loop
from ..loops.wiring import LOOPS
from ..output_files import write_csv

RADIUS = 50.0  # mm, a ballbar's
FEED = 1000.0  # mm/min
ACCEL, JERK = 2000.0, 1e5  # the part demo's limits (usage.md)
# Per axis, at the motor: 0.5 N.m of Coulomb (314 N at the table through the 10 mm lead),
# 0.8 N.m to break away, the drop over 1 mm/s.
FRICTION = {f"{axis}.{name}": value for axis in "xy"
            for name, value in (("coulomb", 0.5), ("stiction", 0.8), ("stribeckVelocity", 1.0))}
# No CCC, the fuzzy CCC, feed-forward alone and both (the shipped loop's settings).
CONTROLLERS = LOOPS["two_axis"].variants()


def file_name(label):
    """A controller's label as part of a file name."""
    return re.sub(r"[^A-Za-z0-9-]+", "_", label).strip("_")


def program(clockwise):
    """The ballbar program: lead-in, the full circle, lead-out."""
    g = "G2" if clockwise else "G3"
    r = RADIUS
    return (f"%\nG21 G90 G17 G64\nG0 X0 Y0\n{g} X{r} Y0 I{r / 2} J0 F{FEED}\n"
            f"{g} X{r} Y0 I{-r} J0\n{g} X0 Y0 I{-r / 2} J0\nM2\n%\n")


def run(fmu_dir, file, controller):
    """The closed loop on `file`; (before, the first and last time the reference is on
    the circle)."""
    interpolator = {"accel": ACCEL, "jerk": JERK, "tolerance": 0.0}
    controller = {**controller, "path": str(file), "estimator": 4, "tolerance": 0.0}
    stop = round(2 * np.pi * RADIUS * 1.5 / (FEED / 60.0) + 1.0, 3)
    before, _ = closed_loop(fmu_dir, path=str(file), stop=stop, interpolator=interpolator,
                            controller=controller, plant=FRICTION)
    on = np.flatnonzero(np.abs(np.hypot(before["interpolator.ref.x"],
                                        before["interpolator.ref.y"]) - RADIUS) < 1e-9)
    return before, before["time"][on[0]], before["time"][on[-1]]


def figures(file):
    """The figures contour-eval wrote (--figures), in um (the LSC radius in mm)."""
    written = json.loads(Path(file).read_text())
    runs = written["runs"]
    return dict(G=[r["G"] * 1e3 for r in runs], F=[[f * 1e3 for f in r["F"]] for r in runs],
                radius=[r["radius"] for r in runs], Gb=written["Gb"] * 1e3)


def ballbar_demo(fmu_dir, out, tool=None):
    """Runs every controller both ways; {controller: figures}. Writes the runs' CSVs and
    plots to `out`."""
    tool = tool or repo.contour_eval()
    if not Path(tool).exists():
        raise FileNotFoundError(f"{tool} is missing: cargo build --release -p contour-eval")
    out.mkdir(parents=True, exist_ok=True)
    files = {}
    for direction, clockwise in (("ccw", False), ("cw", True)):
        files[direction] = out / f"ballbar_{direction}.ngc"
        files[direction].write_text(program(clockwise))
    results = {}
    for label, controller in CONTROLLERS:
        name = file_name(label)
        runs, windows = [], []
        for direction, file in files.items():
            before, start, end = run(fmu_dir, file, controller)
            csv = out / f"ballbar_{name}_{direction}.csv"
            write_csv(csv, {"time": before["time"], "X": before["plant.pos.x"],
                            "Y": before["plant.pos.y"]})
            runs.append(csv)
            windows.append((start, end))
        start, end = max(w[0] for w in windows), min(w[1] for w in windows)
        done = subprocess.run(
            [str(tool), "--circle", f"0,0,{RADIUS}", "--measured", str(runs[0]), "--reverse",
             str(runs[1]), "--from", repr(float(start)), "--to", repr(float(end)), "--plot",
             str(out / f"ballbar_{name}.png"), "--figures", str(out / f"ballbar_{name}.json")],
            capture_output=True, text=True)
        if done.returncode != 0:
            raise RuntimeError(f"contour-eval failed on {runs}: {done.stderr}")
        results[label] = {**figures(out / f"ballbar_{name}.json"),
                          "window": (float(start), float(end))}
    return results


def print_table(results):
    print(f"Ballbar test (ISO 230-4) on XYServoPlant with friction: R {RADIUS:g} mm, F{FEED:g}, "
          f"counter-clockwise / clockwise; um")
    print(f"{'controller':34} {'G ccw':>7} {'G cw':>7} {'G(b)':>7} {'F min':>8} {'F max':>8}")
    for label, r in results.items():
        f_min = min(f[0] for f in r["F"])
        f_max = max(f[1] for f in r["F"])
        print(f"{label:34} {r['G'][0]:7.3f} {r['G'][1]:7.3f} {r['Gb']:7.3f} {f_min:8.3f} "
              f"{f_max:8.3f}")


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m contour_fmu.demo.ballbar")
    parser.add_argument("--fmu-dir", type=Path, default=repo.fmu_dir())
    parser.add_argument("--out", type=Path, default=repo.out_dir())
    args = parser.parse_args(argv)
    results = ballbar_demo(args.fmu_dir, args.out)
    print_table(results)
    return results


if __name__ == "__main__":
    main()
