"""Campaign: what a campaign measures on each run, computed from the run's trace.

This is the fmpy engine's code; the native engine's batches measure the same metrics in
Rust where they run (`contour-cosim batch --metrics`), the two written independently.
True errors are computed in Python, independently of the controller: for the two-axis
loop the distance to the built-in path (contour_fmu.checks.reference_paths), for the
five-axis loop the tip and orientation errors against the interpolator's own reference
(contour_fmu.checks.five_axis_truth). The estimated_* metrics are what the controller
itself reported (its contourError outputs): available on any path.

Lengths are in mm, angles in rad.
"""

import functools
from dataclasses import dataclass

import numpy as np

from ..extras import needs
from ..loops.wiring import FIVE_AXIS_JOINTS

STATISTICS = ("max", "mean")


@dataclass(frozen=True)
class LoopMetrics:
    quantities: dict  # quantity -> (unit, description)
    estimates: dict  # estimated quantity -> controller output

    @property
    def names(self):
        return tuple(f"{q}.{s}" for q in (*self.quantities, *self.estimates) for s in STATISTICS)


METRICS = {
    "two_axis": LoopMetrics(
        quantities={"contour_error": ("mm", "true contour error, distance to the built-in path")},
        estimates={"estimated_contour_error": "contourError"},
    ),
    "five_axis": LoopMetrics(
        quantities={"tip_error": ("mm", "true tool-tip contour error"),
                    "orientation_error": ("rad", "true tool-orientation contour error")},
        estimates={"estimated_tip_error": "contourError.tip",
                   "estimated_orientation_error": "contourError.orientation"},
    ),
}

# How far the native engine's true errors may be from this module's (mm, rad); the
# estimated_* metrics agree to the bit. contour-cosim measures two-axis distances to the
# exact path, reference_paths to a 200 001-point polygon, off by up to its sagitta (6e-8 mm
# measured on the built-in paths; 3e-10 mm against a 2 000 001-point polygon). Both
# measure five-axis errors to the same chords, in another order of rounding.
ENGINE_AGREEMENT = {"contour_error": 2e-7, "tip_error": 1e-12, "orientation_error": 1e-12}

# The paths whose geometry reference_paths knows (with the FMU's default line.*/arc.*).
TWO_AXIS_TRUTH_PATHS = ("circle", "line", "arc", "infinity", "trident")
PIVOTS = ("pivot.A.y", "pivot.A.z", "pivot.C.x", "pivot.C.y")


def unit_of(metric):
    """"mm", "rad" of a metric name."""
    quantity = metric.rsplit(".", 1)[0].removeprefix("estimated_")
    for loop in METRICS.values():
        if quantity in loop.quantities:
            return loop.quantities[quantity][0]
    raise KeyError(metric)


def agreement(metric):
    """The largest difference allowed between the two engines' values of `metric`."""
    return ENGINE_AGREEMENT.get(metric.rsplit(".", 1)[0], 0.0)


def check_metrics(loop, metrics, interpolator_values=None, interpolator_variables=None):
    """Raises ValueError for an unknown metric, or for a true two-axis contour error on a
    path whose geometry is not known in Python."""
    known = METRICS[loop].names
    if not isinstance(metrics, list) or not metrics:
        raise ValueError(f"metrics: expected a non-empty array, some of {', '.join(known)}")
    unknown = [m for m in metrics if m not in known]
    if unknown:
        raise ValueError(f"metrics: unknown {', '.join(map(repr, unknown))} for the {loop} loop "
                         f"(expected some of {', '.join(known)})")
    if len(set(metrics)) != len(metrics):
        raise ValueError("metrics: a metric named twice")
    if interpolator_variables is None or loop != "two_axis":
        return
    if not any(m.startswith("contour_error.") for m in metrics):
        return
    path = interpolator_values.get("path", interpolator_variables["path"].start)
    moved = sorted(k for k in interpolator_values if k.startswith(("line.", "arc.")))
    if path not in TWO_AXIS_TRUTH_PATHS or moved:
        raise ValueError(
            f"contour_error.* needs a built-in path ({', '.join(TWO_AXIS_TRUTH_PATHS)}) with "
            f"its default geometry (path = {path!r}{', sets ' + ', '.join(moved) if moved else ''}); "
            "use estimated_contour_error.* there")


@functools.lru_cache(maxsize=None)
def _two_axis_reference(path):
    with needs("campaign"):
        from ..checks.reference_paths import ContourReference

    return ContourReference(path)


def errors(loop, trace, interpolator_values, interpolator_variables):
    """{quantity: per-sample error array} of every quantity of the loop that this trace
    can give (true ones only on a known path)."""
    found = {}
    for quantity, output in METRICS[loop].estimates.items():
        found[quantity] = np.abs(trace[f"controller.{output}"])
    if loop == "two_axis":
        path = interpolator_values.get("path", interpolator_variables["path"].start)
        if path in TWO_AXIS_TRUTH_PATHS:
            pos = np.column_stack([trace["plant.pos.x"], trace["plant.pos.y"]])
            found["contour_error"] = _two_axis_reference(path).distance(pos)
    else:
        from ..checks.five_axis_truth import contour_errors

        def pivot(name):
            value = interpolator_values.get(name, interpolator_variables[name].start)
            return 0.0 if value is None else float(value)

        joints = lambda unit, name: np.column_stack(  # noqa: E731
            [trace[f"{unit}.{name}.{j}"] for j in FIVE_AXIS_JOINTS])
        tip, orientation = contour_errors(
            joints("interpolator", "ref"), joints("plant", "pos"),
            a_pivot=(0.0, pivot("pivot.A.y"), pivot("pivot.A.z")),
            c_pivot=(pivot("pivot.C.x"), pivot("pivot.C.y"), 0.0))
        found["tip_error"], found["orientation_error"] = tip, orientation
    return found


def compute(loop, metrics, trace, interpolator_values, interpolator_variables):
    """{metric: value} of the requested metrics."""
    per_sample = errors(loop, trace, interpolator_values, interpolator_variables)
    result = {}
    for metric in metrics:
        quantity, statistic = metric.rsplit(".", 1)
        values = per_sample[quantity]
        result[metric] = float(values.max() if statistic == "max" else values.mean())
    return result
