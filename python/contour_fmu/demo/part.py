"""Demo: the part demo, a G-code part contour on the XY table, planned within acceleration
and jerk limits, without and with the fuzzy-PID CCC, on the part and on its mirror image.

PathInterpolator2D plans the program (`path` = the file, `accel`, `jerk`, `tolerance`),
ContourCCC2D measures against the same planned geometry (`estimator` = program, the same
`path` and `tolerance`), XYServoPlant follows; contour_fmu.engines.master.closed_loop
steps them. The shipped program is examples/parts/bracket.ngc: lines, a line into a tangent R10 arc
and out of it, a concave arc entered at 90° (a non-tangent join), a 0.8 mm radius, a
corner blended within G64 P0.01, an exact stop (G61, then G64 again), two corners blended
within the `tolerance` parameter (bare G64), F words and a CAM preamble that the reader
skips with one warning per kind.

**The limits** (the table is docs/design/two-axis.md §4.5's XYServoPlant: per axis a
motor with J = 0.015 kg·m², B = 1.2 N·m·s/rad, CT = 0.57 N·m/A on a 10 mm-lead ball screw,
its drive a 50 Hz velocity loop; ContourCCC2D's position loop Kpp = 28.5 /s):

- `accel` = 2000 mm/s² (0.2 g, in the 0.1-0.5 g of small precision XY tables). On this
  drive it takes J·a·2π/lead = 18.8 N·m, 33 A, while the viscous friction alone takes
  40 A to hold the program's 30 mm/s (42 A at the paper's 31.4 mm/s circle): the peak is
  below twice the current of cutting at feed, what a servo drive's peak rating (two to
  three times its continuous one) gives. Twice it would ask for 2.7 times.
- `jerk` = 1e5 mm/s³ (the top of the usual 1e4-1e5): the acceleration ramps up in
  a/j = 20 ms, six time constants of the 50 Hz velocity loop (3.2 ms), so the drive
  follows the ramp, and within the position loop's lag 1/Kpp = 35 ms. A lower jerk would
  slow the tangent joins further: the planner passes a curvature jump Δκ at
  v² Δκ ≤ jerk·Ts (about 9 mm/s into the R0.8 radius, 32 mm/s into R10).
- `tolerance` = 0.02 mm for bare G64 (the program's P0.01 is tighter): the blends stay
  within a finishing tolerance band of a precision part.

These are the limits of docs/design/two-axis.md §4.9's planned square, so the figures
there and here compare.

**The truth.** The true contour error is the distance from the plant's position to the
*programmed* geometry, lines and arcs in closed form, read from the program by the
package's one G-code reader (contour_fmu.checks.gcode: `read_program`, the subset the
demo's programs use) without the FMUs. It includes the blends' own departure from the programmed corners (within P or
the tolerance). The controller's `contourError` is measured against the *planned*
geometry (blends included); the table gives both and how far the estimate is from the
truth.

**The mirror image** (`mirror_program`: y → −y, J → −J, G2 ↔ G3, written to
OUT/paths/) runs clockwise; the demo checks that its planned reference is the original's
mirrored, sample by sample.

Writes to OUT: one CSV per run (part_<name>[_mirrored]_<controller>.csv), the mirrored
program (paths/<name>_mirrored.ngc) and part_<name>.png (the part with each run's
deviation magnified, and the true error along the part with its joins marked).

usage: python -m contour_fmu.demo.part [--fmu-dir DIR] [--out DIR] [--program FILE.ngc]
"""

import argparse
import math
import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from .. import repo
from ..checks.gcode import distance, joins, mirror_program, point_at, read_program, starts
from ..engines.fmu_log import FmuLog
from ..engines.master import closed_loop, set_value
from ..loops.wiring import LOOPS
from ..output_files import write_csv

STEP = 1e-3
SETTLE = 0.25  # s run after the planned duration: the position loop's lag (35 ms) settles
ACCEL = 2000.0  # mm/s², see the docstring
JERK = 1e5  # mm/s³
TOLERANCE = 0.02  # mm, bare G64's blends
FEED = 30.0  # mm/s before the program's first F (the shipped program sets F on its first cut)
ESTIMATOR_PROGRAM = 4  # ContourCCC2D's `estimator` item `program`

PROGRAM = Path("examples") / "parts" / "bracket.ngc"


def default_program():
    """<repo>/examples/parts/bracket.ngc, or None outside a checkout."""
    try:
        root = repo.find_root()
    except repo.RepoNotFound:
        return None
    return None if root is None else root / PROGRAM

# No CCC, the fuzzy-PID CCC with the FMU's defaults (the paper's fuzzy factors 1, 1.2, 87,
# 8.5, 4), feed-forward alone and both: the shipped loop (contour_fmu/loops/two_axis.ssd).
VARIANTS = LOOPS["two_axis"].variants("fuzzy-PID CCC")
COLOURS = ("tab:orange", "tab:blue", "tab:green", "tab:red")  # one per variant

# --- the runs -----------------------------------------------------------------------------

def interpolator_values(program, accel=ACCEL, jerk=JERK, tolerance=TOLERANCE):
    return {"path": str(Path(program).resolve()), "accel": accel, "jerk": jerk,
            "tolerance": tolerance, "feed": FEED}


def plan(fmu_dir, interpolator):
    """Initializes PathInterpolator2D alone: (plannedDuration, the reader's warnings)."""
    fmu = str(Path(fmu_dir) / "PathInterpolator2D.fmu")
    md = read_model_description(fmu)
    directory = extract(fmu)
    log = FmuLog()
    slave = FMU2Slave(guid=md.guid, unzipDirectory=directory,
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="probe")
    try:
        slave.instantiate(callbacks=log.callbacks, loggingOn=True)
        slave.setDebugLogging(True, ["logStatusWarning"])
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        variables = {v.name: v for v in md.modelVariables}
        for name, value in interpolator.items():
            set_value(slave, variables[name], value)
        slave.exitInitializationMode()
        duration = slave.getReal([variables["plannedDuration"].valueReference])[0]
        slave.terminate()
    finally:
        slave.freeInstance()
        shutil.rmtree(directory, ignore_errors=True)
    return duration, log.warnings()


@dataclass
class Run:
    label: str
    before: np.ndarray
    after: np.ndarray
    true: np.ndarray  # |true contour error| per sample (mm), of pos(t_k)
    along: np.ndarray  # path position of the tool's foot point (mm)
    reference: np.ndarray  # the reference's distance to the programmed geometry (mm)

    @property
    def estimate(self):
        """ContourCCC2D's contourError computed at t_k from pos(t_k) (mm, signed)."""
        return self.after["controller.contourError"]

    def figures(self):
        """max and mean |true error|, max |contourError|, max |estimate - true| (mm)."""
        return (self.true.max(), self.true.mean(), np.abs(self.estimate).max(),
                np.abs(np.abs(self.estimate) - self.true).max())


def run(fmu_dir, program, pieces, label, controller, stop, interpolator):
    path = str(Path(program).resolve())
    before, after = closed_loop(
        Path(fmu_dir), path=path, stop=stop, interpolator=interpolator,
        controller={"estimator": ESTIMATOR_PROGRAM, "path": path,
                    "tolerance": interpolator["tolerance"], **controller})
    pos = np.column_stack([before["plant.pos.x"], before["plant.pos.y"]])
    ref = np.column_stack([before["interpolator.ref.x"], before["interpolator.ref.y"]])
    true, along = distance(pieces, pos)
    return Run(label, before, after, true, along, distance(pieces, ref)[0])


@dataclass
class PartResult:
    name: str
    duration: float
    warnings: list
    pieces: list
    mirrored_pieces: list
    runs: list  # Run on the part, one per variant
    mirrored_runs: list  # Run on the mirror image, one per variant
    mirror_mismatch: float  # max |mirrored file's reference - mirrored original's| (mm)
    interpolator: dict

    def rows(self):
        """(which, controller, max, mean, max |contourError|, max |estimate - true|,
        max of the reference's own distance to the programmed part, reductions of the max
        and of the mean against no CCC in %), errors in mm."""
        rows = []
        for which, runs in (("part", self.runs), ("mirror", self.mirrored_runs)):
            base = runs[0].true
            for r in runs:
                rows.append((which, r.label, *r.figures(), r.reference.max(),
                             100 * (1 - r.true.max() / base.max()),
                             100 * (1 - r.true.mean() / base.mean())))
        return rows


def part_demo(fmu_dir, out, program=None, variants=VARIANTS, accel=ACCEL, jerk=JERK,
              tolerance=TOLERANCE, write=True):
    """Runs the part and its mirror image through the FMUs for every variant; returns a
    PartResult. With `write`, the CSVs, the mirrored program and the plot go to `out`."""
    program = Path(program) if program is not None else repo.root() / PROGRAM
    out = Path(out)
    name = program.stem
    text = program.read_text()
    pieces = read_program(text, program.name)
    mirrored = out / "paths" / f"{name}_mirrored{program.suffix}"
    mirrored.parent.mkdir(parents=True, exist_ok=True)
    mirrored.write_text(mirror_program(text, program.name))
    mirrored_pieces = read_program(mirrored.read_text(), mirrored.name)

    interpolator = interpolator_values(program, accel, jerk, tolerance)
    duration, warnings = plan(fmu_dir, interpolator)
    stop = round(math.ceil((duration + SETTLE) / STEP) * STEP, 9)
    runs, mirrored_runs = [], []
    for label, controller in variants:
        runs.append(run(fmu_dir, program, pieces, label, controller, stop, interpolator))
        mirrored_runs.append(run(fmu_dir, mirrored, mirrored_pieces, label, controller, stop,
                                 interpolator_values(mirrored, accel, jerk, tolerance)))
    # contour-core plans the mirrored file as the mirror image of the original's plan.
    a, b = runs[0].before, mirrored_runs[0].before
    mismatch = max(np.abs(b["interpolator.ref.x"] - a["interpolator.ref.x"]).max(),
                   np.abs(b["interpolator.ref.y"] + a["interpolator.ref.y"]).max())
    result = PartResult(name, duration, warnings, pieces, mirrored_pieces, runs, mirrored_runs,
                        float(mismatch), interpolator)
    if write:
        for which, group in (("", runs), ("_mirrored", mirrored_runs)):
            for r in group:
                columns = {n: r.before[n] for n in r.before.dtype.names}
                columns["controller.contourError"] = r.estimate
                columns["trueContourError"] = r.true
                columns["referenceError"] = r.reference
                columns["pathPosition"] = r.along
                write_csv(out / f"part_{name}{which}_{r.label.replace(' ', '_')}.csv", columns)
        plot(out, result)
    return result


# --- output -------------------------------------------------------------------------------

JOIN_STYLE = {"tangent": ("0.6", ":"), "stop": ("tab:red", "-"), "blend": ("tab:green", "--")}


def plot(out, result, magnify=20.0):
    from ..extras import needs

    with needs("plots"):
        import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (part_ax, error_ax) = plt.subplots(
        1, 2, figsize=(14, 5.2), gridspec_kw={"width_ratios": [1, 1.5]})
    pieces = result.pieces
    dense = []
    for p in pieces:
        u = np.linspace(0.0, 1.0, max(2, int(p.length / 0.05)))
        if p.kind == "line":
            dense.append(p.start + u[:, None] * (p.end - p.start))
        else:
            phi = p.start_angle + u * p.sweep
            dense.append(p.centre + p.radius * np.column_stack([np.cos(phi), np.sin(phi)]))
    dense = np.concatenate(dense)
    part_ax.plot(*dense.T, "k-", lw=1.0, label="programmed")
    for r, colour in zip(result.runs, COLOURS):
        pos = np.column_stack([r.before["plant.pos.x"], r.before["plant.pos.y"]])
        feet = _feet(pieces, pos)
        shown = feet + magnify * (pos - feet)
        part_ax.plot(*shown.T, "-", color=colour, lw=0.8,
                     label=f"{r.label}: deviation ×{magnify:g}")
    for s, kind in joins(pieces):
        x, y = point_at(pieces, s)
        part_ax.plot(x, y, "o", ms=4, mfc="none", color=JOIN_STYLE[kind][0])
    part_ax.set_aspect("equal"), part_ax.set_xlabel("x (mm)"), part_ax.set_ylabel("y (mm)")
    part_ax.set_title(f"{result.name}: the part and the tracking")
    part_ax.legend(fontsize=7, loc="center")

    for r, colour in zip(result.runs, COLOURS):
        order = np.argsort(r.before["time"])
        error_ax.plot(r.along[order], r.true[order] * 1e3, "-", color=colour, lw=0.8, label=r.label)
    for r, colour in zip(result.mirrored_runs, COLOURS):
        error_ax.plot(r.along, r.true * 1e3, ":", color=colour, lw=0.8, label=f"{r.label}, mirror")
    seen = set()
    for s, kind in joins(pieces):
        colour, style = JOIN_STYLE[kind]
        error_ax.axvline(s, color=colour, ls=style, lw=0.8,
                         label=None if kind in seen else {"tangent": "tangent join",
                                                          "stop": "exact stop",
                                                          "blend": "blended corner"}[kind])
        seen.add(kind)
    at = starts(pieces)
    error_ax.set_yscale("log")
    top = max(r.true.max() for r in result.runs) * 1e3
    error_ax.set_ylim(1e-2, top * 4)
    for p, s0, s1 in zip(pieces, at[:-1], at[1:]):
        text = p.label + (f"\nR{p.radius:g}" if p.kind == "arc" else "")
        error_ax.text((s0 + s1) / 2, top * 2.2, text, ha="center", va="center", fontsize=6)
    error_ax.set_xlim(0, at[-1])
    error_ax.set_xlabel("path position of the tool's nearest point on the part (mm)")
    error_ax.set_ylabel("|true contour error| (µm)")
    error_ax.set_title(f"{result.name}: true contour error along the part "
                       f"(accel {result.interpolator['accel']:g} mm/s², "
                       f"jerk {result.interpolator['jerk']:g} mm/s³)", fontsize=9)
    error_ax.legend(fontsize=7, ncol=3, loc="lower right")
    fig.tight_layout()
    fig.savefig(out / f"part_{result.name}.png", dpi=120)
    plt.close(fig)


def _feet(pieces, points):
    _, along = distance(pieces, points)
    return np.array([point_at(pieces, s) for s in along])


def print_table(result):
    print(f"Part program {result.name} through the FMUs (PathInterpolator2D -> ContourCCC2D "
          "<- XYServoPlant), Ts = 1 ms;")
    i = result.interpolator
    print(f"planned within accel {i['accel']:g} mm/s^2, jerk {i['jerk']:g} mm/s^3, bare G64 "
          f"within {i['tolerance'] * 1e3:g} um: {result.duration:.3f} s "
          f"(+{SETTLE:g} s settling); the reader skipped {len(result.warnings)} kinds of words")
    print("|true contour error| in um from the programmed part; est.: ContourCCC2D's contourError "
          "(estimator program, from the planned part); ref. off: the reference's own distance")
    print(f"{'':6} {'controller':38} {'max':>8} {'mean':>8} {'est. max':>9} {'|est-true|':>10} "
          f"{'ref. off':>8} {'max red. %':>10} {'mean red. %':>11}")
    for which, label, emax, emean, est, off, ref, rmax, rmean in result.rows():
        print(f"{which:6} {label:38} {emax * 1e3:8.3f} {emean * 1e3:8.3f} {est * 1e3:9.3f} "
              f"{off * 1e3:10.3f} {ref * 1e3:8.3f} {rmax:10.1f} {rmean:11.1f}")
    print(f"the mirrored program's reference against the original's mirrored: max "
          f"{result.mirror_mismatch:.3g} mm")


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m contour_fmu.demo.part",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--fmu-dir", type=Path, help="the FMUs (default: <repo>/target/fmu)")
    parser.add_argument("--out", type=Path, help="the output folder (default: <repo>/out)")
    parser.add_argument("--program", type=Path,
                        help=f"the G-code part (default: <repo>/{PROGRAM.as_posix()})")
    args = parser.parse_args(argv)
    try:
        fmu_dir = args.fmu_dir or repo.fmu_dir()
        out = args.out or repo.out_dir()
        program = args.program or repo.root() / PROGRAM
    except repo.RepoNotFound as e:
        parser.error(str(e))
    out.mkdir(parents=True, exist_ok=True)
    result = part_demo(fmu_dir, out, program)
    print_table(result)
    return result


if __name__ == "__main__":
    main()
