"""Demo: the five-axis demo, PathInterpolator5X -> ContourCCC5X <- FiveAxisPlant through the
fmpy master, without and with the five-axis CCC, on the two built-in paths, the example CL
part (examples/cl/blade.cl, which PathInterpolator5X carries in its resources as blade.cl)
and a hemisphere finishing raster with the tool normal to the surface, over the apex and
beside it (contour_fmu.demo.cam_paths, written to OUT), with the true contour errors
computed in Python (contour_fmu.checks.five_axis_truth). The reference is planned within the
machine's default limits (docs/design/five-axis.md §5.3b); for the domes a plot shows every
joint's speed and acceleration against its limit.

Writes to OUT: one CSV per run (joints, commands, estimates, true errors), one PNG per
path (the tool-tip path with tool-axis glyphs, tip and orientation error against time)
and the FMI cross-check files of ContourCCC5X (OUT/cross-check/ContourCCC5X/) from the
fuzzy-CCC run on the helix. Returns the table rows; `print_table` prints them. The plots
need the plots extra (matplotlib).
"""

import numpy as np

from ..checks.five_axis_truth import contour_errors, forward
from ..engines.master import Master, Unit, five_axis_closed_loop
from ..extras import needs
from ..loops.wiring import FIVE_AXIS_JOINTS, LOOPS
from ..output_files import write_cross_check, write_csv
from . import cam_paths

STEP = 1e-3
SETTLE = 0.1  # seconds run after the reference is done, as the in-process simulator
FEED = 50.0

# No CCC, the five-axis CCC with the FMU's defaults (fuzzy-PID laws on tip and orientation),
# feed-forward alone and both: the shipped loop (contour_fmu/loops/five_axis.ssd).
VARIANTS = LOOPS["five_axis"].variants("five-axis CCC")

CROSS_CHECK_INPUTS = [(f"ref.{j}", f"interpolator.ref.{j}") for j in FIVE_AXIS_JOINTS] + [
    (f"pos.{j}", f"plant.pos.{j}") for j in FIVE_AXIS_JOINTS]
CROSS_CHECK_OUTPUTS = [f"u.{j}" for j in FIVE_AXIS_JOINTS] + [
    "contourError.tip", "contourError.orientation"]


# (label, the interpolator's path parameter; CL text written to OUT under that name)
PATHS = [("tilted_helix", "tilted_helix", None), ("figure_eight", "figure_eight", None),
         ("blade.cl", "blade.cl", None),
         ("dome_apex.cl", "dome_apex.cl", cam_paths.dome_raster()),
         ("dome_beside.cl", "dome_beside.cl", cam_paths.dome_raster(offset=1.0))]

# PathInterpolator5X's default joint limits (X Y Z A C; docs/design/five-axis.md §5.3b).
JOINT_VMAX = np.array([500.0, 500.0, 500.0, 3.0, 5.0])
JOINT_AMAX = np.array([5000.0, 5000.0, 5000.0, 20.0, 30.0])


def reference_duration(fmu_dir, path, feed):
    """Seconds until the interpolator reports `done` at this feed (run on its own)."""
    unit = Unit("interpolator", str(fmu_dir / "PathInterpolator5X.fmu"),
                {"path": path, "feed": feed})
    with Master([unit], [], STEP, 3600.0) as master:
        slave, k = master.slaves["interpolator"], 0
        while not master.get("interpolator", "done"):
            slave.doStep(currentCommunicationPoint=k * STEP, communicationStepSize=STEP)
            k += 1
    return k * STEP


def run(fmu_dir, path, controller, stop, feed=FEED):
    """The closed loop; returns (before, after, true tip error, true orientation error)."""
    before, after = five_axis_closed_loop(fmu_dir, path=path, feed=feed, stop=stop,
                                          controller=controller)
    joints = lambda unit, name: np.column_stack(  # noqa: E731
        [before[f"{unit}.{name}.{j}"] for j in FIVE_AXIS_JOINTS])
    tip, orientation = contour_errors(joints("interpolator", "ref"), joints("plant", "pos"))
    return before, after, tip, orientation


def write_run_csv(filename, before, after, tip, orientation):
    columns = {name: before[name] for name in before.dtype.names}
    for name in after.dtype.names[1:]:
        if name.startswith("controller."):
            columns[name] = after[name]
    columns["trueTipError"] = tip
    columns["trueOrientationError"] = orientation
    write_csv(filename, columns)


def plot(out, label, runs):
    with needs("plots"):
        import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(14, 4.8))
    space = fig.add_subplot(1, 3, 1, projection="3d")
    before = runs[0][1]
    ref = np.column_stack([before[f"interpolator.ref.{j}"] for j in FIVE_AXIS_JOINTS])
    tips, axes = forward(ref)
    space.plot(*tips.T, "k-", lw=0.8, label="reference tip")
    every = max(len(tips) // 40, 1)
    glyph = 0.15 * np.ptp(tips, axis=0).max()
    space.quiver(*tips[::every].T, *(axes[::every] * glyph).T, color="tab:blue", lw=0.6,
                 label="tool axis")
    # One scale on every axis (a planar path stays flat, the glyphs keep their angles).
    centre, half = tips.mean(axis=0), 0.6 * np.ptp(tips, axis=0).max()
    space.set_xlim(centre[0] - half, centre[0] + half)
    space.set_ylim(centre[1] - half, centre[1] + half)
    space.set_zlim(centre[2] - half, centre[2] + half)
    space.set_xlabel("x (mm)"), space.set_ylabel("y (mm)"), space.set_zlabel("z (mm)")
    space.set_title(f"{label}: tool tip and axis (workpiece)"), space.legend(fontsize=7)
    tip_ax, turn_ax = fig.add_subplot(1, 3, 2), fig.add_subplot(1, 3, 3)
    for name, before, tip, orientation in runs:
        tip_ax.plot(before["time"], tip * 1e3, lw=0.8, label=name)
        turn_ax.plot(before["time"], orientation * 1e6, lw=0.8, label=name)
    tip_ax.set_xlabel("time (s)"), tip_ax.set_ylabel("tip contour error (µm)")
    turn_ax.set_xlabel("time (s)"), turn_ax.set_ylabel("orientation contour error (µrad)")
    tip_ax.set_yscale("log"), turn_ax.set_yscale("log")
    # The first samples start on the path (errors near 0): the log scale starts lower.
    tip_ax.set_ylim(bottom=1e-2), turn_ax.set_ylim(bottom=1.0)
    tip_ax.legend(fontsize=8), turn_ax.legend(fontsize=8)
    tip_ax.set_title(f"{label}: true tip error"), turn_ax.set_title(f"{label}: true orientation error")
    fig.tight_layout(w_pad=3.0)  # room for the 3-D plot's z label
    fig.savefig(out / f"five_axis_{label.replace('.', '_')}.png", dpi=120)
    plt.close(fig)


def plot_limits(out, label, before):
    """Every joint's speed and acceleration of the reference, as a share of its limit."""
    with needs("plots"):
        import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ref = np.column_stack([before[f"interpolator.ref.{j}"] for j in FIVE_AXIS_JOINTS])
    t = before["time"]
    speed = np.abs(np.diff(ref, axis=0)) / STEP / JOINT_VMAX
    accel = np.abs(np.diff(ref, 2, axis=0)) / STEP ** 2 / JOINT_AMAX
    fig, (v_ax, a_ax) = plt.subplots(1, 2, figsize=(12, 4))
    for i, j in enumerate(FIVE_AXIS_JOINTS):
        v_ax.plot(t[1:], speed[:, i], lw=0.8, label=j)
        a_ax.plot(t[2:], accel[:, i], lw=0.8, label=j)
    for ax, what in ((v_ax, "speed / vmax"), (a_ax, "acceleration / amax")):
        ax.axhline(1.0, color="k", ls="--", lw=0.8, label="limit")
        ax.set_xlabel("time (s)"), ax.set_ylabel(what), ax.set_ylim(0, 1.1)
        ax.legend(fontsize=7, ncol=3), ax.set_title(f"{label}: joints against their limits")
    fig.tight_layout()
    fig.savefig(out / f"five_axis_{label.replace('.', '_')}_limits.png", dpi=120)
    plt.close(fig)


def main(fmu_dir, out):
    """Runs every path and variant; returns rows (path, feed, variant, max tip, mean tip,
    max orientation, mean orientation, reductions of the four against no CCC)."""
    rows = []
    for label, path, text in PATHS:
        if text is not None:
            path = str(out / path)
            (out / label).write_text(text)
        stop = round(reference_duration(fmu_dir, path, FEED) + SETTLE, 9)
        runs = []
        for name, controller in VARIANTS:
            before, after, tip, orientation = run(fmu_dir, path, controller, stop)
            runs.append((name, before, tip, orientation))
            write_run_csv(out / f"five_axis_{label.replace('.', '_')}_{name.replace(' ', '_')}.csv",
                          before, after, tip, orientation)
            if label == "tilted_helix" and controller == {}:
                write_cross_check(out, "ContourCCC5X", before, after, CROSS_CHECK_INPUTS,
                                  CROSS_CHECK_OUTPUTS, STEP)
        plot(out, label, runs)
        if text is not None:
            plot_limits(out, label, runs[0][1])
        base = runs[0]
        for name, _, tip, orientation in runs:
            figures = (tip.max(), tip.mean(), orientation.max(), orientation.mean())
            reference = (base[2].max(), base[2].mean(), base[3].max(), base[3].mean())
            reductions = tuple(100 * (1 - f / r) for f, r in zip(figures, reference))
            rows.append((label, FEED, name, *figures, *reductions))
    return rows


def print_table(rows):
    print("Five-axis closed loop through the FMUs (PathInterpolator5X -> ContourCCC5X <- "
          "FiveAxisPlant), Ts = 1 ms;")
    print("true contour errors: tool tip in um, tool orientation in urad; reductions of "
          "max and mean against no CCC")
    print(f"{'path':13} {'feed':>5}  {'controller':38} {'tip max':>8} {'tip mean':>8} "
          f"{'ori max':>8} {'ori mean':>8} {'red. tip %':>11} {'red. ori %':>11}")
    for label, feed, name, tmax, tmean, omax, omean, rtmax, rtmean, romax, romean in rows:
        print(f"{label:13} {feed:5.0f}  {name:38} {tmax * 1e3:8.3f} {tmean * 1e3:8.3f} "
              f"{omax * 1e6:8.1f} {omean * 1e6:8.1f} {rtmax:5.1f}/{rtmean:5.1f} "
              f"{romax:5.1f}/{romean:5.1f}")
