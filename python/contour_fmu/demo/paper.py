"""Demo: the paper's comparison of contour error with and without CCC, through the FMUs.

PathInterpolator2D -> ContourCCC2D <- XYServoPlant, stepped by the fixed-step master of
contour_fmu.engines.master (fmpy's FMU2Slave), on the circle, the infinity curve and the
trident: without CCC, with the fuzzy-PID CCC and the paper's factors, and with factors
tuned by PSO (`ccc-tune`, applied as start values).

Every controller also runs on the mirror image of each path (about the x axis, so the
circle turns clockwise): a controller must not care about the direction of travel, and
the table shows both. Prints a table like the paper's Tables 4-5 (max and mean |true
contour error| on the path and on its mirror, the reduction), and writes to out/: one CSV
time series per run, one PNG per path (path tracking and contour error vs time), the PSO
fitness histories (standard vs improved, like the paper's Figures 10 and 13), and the FMI
cross-check files of ContourCCC2D (out/cross-check/ContourCCC2D/: _in.csv, _ref.csv,
_ref.opt) from the fuzzy circle run.

`python -m contour_fmu.demo` runs it first, then the part, ballbar and five-axis demos.
Needs the plots and reference extras (matplotlib; geomdl, scipy).
"""

import json
import math
import subprocess

import numpy as np

from ..engines.master import closed_loop
from ..extras import needs
from ..loops.wiring import LOOPS
from ..output_files import write_csv
from ..output_files import write_cross_check as write_cross_check_files
from ..tuned import start_values
from . import part

with needs("plots", "reference"):
    import matplotlib  # noqa: F401  the plots, here so that a missing one stops us before any run
    from ..checks.reference_paths import INFINITY, TRIDENT, ContourReference, clamped_uniform

STEP = 1e-3

# (path, feed mm/s): the paper's circle at its own feed (2 s per turn); the NURBS at a
# feed that keeps the drives' current demand in a realistic range.
PATHS = [("circle", 10 * math.pi), ("infinity", 50.0), ("trident", 50.0)]

# No CCC and the fuzzy-PID CCC with the FMU's defaults (the paper's fuzzy factors): the
# paper's loop, which has no feed-forward. The CCC with the shipped loop's feed-forward
# (contour_fmu/loops/two_axis.ssd) follows the PSO rows, on the paper's reference (constant
# feed from the first sample; the run ends with the reference, as the others do).
VARIANTS = part.VARIANTS[:2]
SHIPPED = ("CCC + feed-forward", dict(LOOPS["two_axis"].feed_forward))


# The tuner scores the maximum error: a part's tolerance band is about the worst point,
# and on the circle the paper's mean is flat in the factors (the integral action fixes
# the steady state), so it gives the swarm nothing to improve.
TUNING_FITNESS = "max"


def tune(program, out, path, feed, algorithm):
    """Runs ccc-tune; returns its JSON document (also written to out/)."""
    target = out / f"tuned_{path}_{algorithm}.json"
    subprocess.run([str(program), "--path", path, "--feed", repr(feed), "--algorithm", algorithm,
                    "--fitness", TUNING_FITNESS, "--seed", "1", "--out", str(target)],
                   check=True, stderr=subprocess.DEVNULL)
    return target


def plot_histories(out, path, histories):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for algorithm, history in histories.items():
        ax.plot(range(1, len(history) + 1), [h * 1e3 for h in history], label=f"{algorithm} PSO")
    ax.set_xlabel("iteration"), ax.set_ylabel(f"best fitness: {TUNING_FITNESS} |contour error| (µm)")
    ax.set_title(f"{path}: PSO convergence"), ax.legend()
    fig.tight_layout()
    fig.savefig(out / f"pso_{path}.png", dpi=120)
    plt.close(fig)


def mirrored_interpolator(path, out):
    """PathInterpolator2D start values for the mirror image of a built-in path about the
    x axis: the circle as a clockwise arc, a NURBS as a JSON file with (x, -y) control
    points (written to out/paths/)."""
    if path == "circle":
        return {"path": "arc", "arc.cx": -10.0, "arc.cy": 0.0, "arc.r": 10.0,
                "arc.start": 0.0, "arc.sweep": -2 * math.pi}
    ctrl = {"infinity": INFINITY, "trident": TRIDENT}[path]
    document = {"degree": 3, "knots": clamped_uniform(len(ctrl), 3),
                "control_points": [[float(x), -float(y)] for x, y in ctrl]}
    target = out / "paths" / f"{path}_mirrored.json"
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text(json.dumps(document))
    return {"path": str(target)}


def run_path(fmu_dir, path, feed, controller, mirrored=None):
    """The closed loop on `path`, or on its mirror image when `mirrored` holds the
    interpolator start values of mirrored_interpolator(); returns (before, after,
    |true contour error| per sample)."""
    reference = ContourReference(path, mirrored=mirrored is not None)
    length = np.sum(np.hypot(*np.diff(reference.points, axis=0).T))
    stop = round(math.ceil(length / feed / STEP - 1e-6) * STEP, 9)
    before, after = closed_loop(fmu_dir, path=path, feed=feed, stop=stop, controller=controller,
                                interpolator=mirrored)
    error = reference.distance(np.column_stack([before["plant.pos.x"], before["plant.pos.y"]]))
    return before, after, error


def write_cross_check(out, before, after):
    """ContourCCC2D's cross-check files: inputs at t_k, outputs after the step to t_k+1."""
    inputs = [(ours, f"{unit}.{ours}") for unit, ours in (
        ("interpolator", "ref.x"), ("interpolator", "ref.y"), ("plant", "pos.x"), ("plant", "pos.y"))]
    outputs = ["u.x", "u.y", "contourError", "ccc.Kp", "ccc.Ki", "ccc.Kd"]
    write_cross_check_files(out, "ContourCCC2D", before, after, inputs, outputs, STEP)


def plot(out, path, runs):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.5))
    first = runs[0][1]
    a.plot(first["interpolator.ref.x"], first["interpolator.ref.y"], "k-", lw=1, label="reference")
    for label, before, error in runs:
        a.plot(before["plant.pos.x"], before["plant.pos.y"], "--", lw=1, label=label)
        b.plot(before["time"], error * 1e3, lw=1, label=label)
    a.set_aspect("equal"), a.set_xlabel("x (mm)"), a.set_ylabel("y (mm)"), a.legend(fontsize=8)
    a.set_title(f"{path}: path tracking")
    b.set_xlabel("time (s)"), b.set_ylabel("|contour error| (µm)"), b.legend(fontsize=8)
    b.set_title(f"{path}: true contour error")
    fig.tight_layout()
    fig.savefig(out / f"{path}.png", dpi=120)
    plt.close(fig)


def paper_demo(fmu_dir, out, ccc_tune=None, params=None):
    """Runs every path with every variant, and on its mirror image: with `ccc_tune` (the
    program) also with factors it tunes on the path, with `params` (a ccc-tune JSON) with
    those. Writes the CSVs, plots and cross-check files to `out`; returns the table's rows
    (path, feed, controller, max, mean, max and mean on the mirror image, reductions)."""
    rows = []
    for path, feed in PATHS:
        variants = list(VARIANTS)
        if ccc_tune:
            histories = {}
            for algorithm in ("improved", "standard"):
                document = tune(ccc_tune, out, path, feed, algorithm)
                histories[algorithm] = json.loads(document.read_text())["history_mm"]
            plot_histories(out, path, histories)
            for algorithm in ("improved", "standard"):
                variants.append((f"PSO {algorithm}", start_values(out / f"tuned_{path}_{algorithm}.json")))
        elif params:
            variants.append(("PSO-tuned CCC", start_values(params)))
        variants.append(SHIPPED)
        mirror = mirrored_interpolator(path, out)
        runs, mirrored_runs = [], []
        for label, controller in variants:
            before, after, error = run_path(fmu_dir, path, feed, controller)
            runs.append((label, before, error))
            columns = {name: before[name] for name in before.dtype.names}
            columns["trueContourError"] = error
            write_csv(out / f"{path}_{label.replace(' ', '_')}.csv", columns)
            if path == "circle" and controller == {}:
                write_cross_check(out, before, after)
            _, _, mirrored_error = run_path(fmu_dir, path, feed, controller, mirror)
            mirrored_runs.append(mirrored_error)
        plot(out, path, runs)
        base_max, base_mean = runs[0][2].max(), runs[0][2].mean()
        for (label, _, error), mirrored_error in zip(runs, mirrored_runs):
            rows.append((path, feed, label, error.max(), error.mean(), mirrored_error.max(),
                         mirrored_error.mean(), 100 * (1 - error.max() / base_max),
                         100 * (1 - error.mean() / base_mean)))
    return rows


def print_table(rows):
    print("Closed loop through the FMUs (PathInterpolator2D -> ContourCCC2D <- XYServoPlant), Ts = 1 ms;")
    print("|true contour error| in um on the path and on its mirror image (y -> -y, reversed turning sense)")
    print(f"{'path':9} {'feed mm/s':>9}  {'controller':38} {'max':>8} {'mean':>8} {'max mir.':>9} "
          f"{'mean mir.':>9} {'max red. %':>10} {'mean red. %':>11}")
    for path, feed, label, emax, emean, mmax, mmean, rmax, rmean in rows:
        print(f"{path:9} {feed:9.2f}  {label:38} {emax * 1e3:8.3f} {emean * 1e3:8.3f} {mmax * 1e3:9.3f} "
              f"{mmean * 1e3:9.3f} {rmax:10.1f} {rmean:11.1f}")
