"""Loop wiring: the two-axis and five-axis loops as every master runs them, read from the
shipped SSP files (contour_fmu/loops/*.ssd, through contour_fmu.loops.ssp): their FMUs,
connections and initial copies, by name with what each engine records (LOOPS), and the
NC -> drive -> mechanics wiring of a foreign plant. Standard library only, so an engine's
own process can use it without loading fmpy."""

import argparse
from dataclasses import dataclass
from pathlib import Path

from .ssp import SystemStructure, shipped

TWO_AXIS = shipped("two_axis")
FIVE_AXIS = shipped("five_axis")

# Every step: the reference (with its velocity and acceleration, for the controller's
# feed-forward), the measured position, the command.
CLOSED_LOOP_CONNECTIONS = TWO_AXIS.connections
# Once in initialization mode: the plant starts where the path does.
PATH_START = TWO_AXIS.initial_copies

FIVE_AXIS_JOINTS = ("X", "Y", "Z", "A", "C")

# The five-axis loop: PathInterpolator5X -> ContourCCC5X <- FiveAxisPlant.
FIVE_AXIS_CONNECTIONS = FIVE_AXIS.connections
# The plant starts at the path's start joints.
FIVE_AXIS_PATH_START = FIVE_AXIS.initial_copies
# The controller's parameters that make up a loop's feed-forward.
FEED_FORWARD_SETTINGS = ("feedForward", "accelerationFeedForward", "feedForwardLookAhead")


# NC -> drive -> the user's mechanics, for each of X and Y: the interpolator and the
# controller, one ServoDrive per axis ("drive_x", "drive_y") and one mechanical axis FMU
# per axis ("axis_x", "axis_y": force or torque in as `force_input`, position and velocity
# out as `position_output`, `velocity_output`). Nothing is computed between the FMUs.
def drive_loop_connections(force_input="F", position_output="x", velocity_output="v"):
    connections = [
        (source, output, "controller", input)
        for source, output, destination, input in CLOSED_LOOP_CONNECTIONS
        if source == "interpolator"
    ]
    for a in ("x", "y"):
        connections += [
            (f"axis_{a}", position_output, "controller", f"pos.{a}"),
            ("controller", f"u.{a}", f"drive_{a}", "u"),
            (f"axis_{a}", velocity_output, f"drive_{a}", "vel"),
            (f"drive_{a}", "effort", f"axis_{a}", force_input),
        ]
    return connections


def drive_loop_start(position_start="x0"):
    """The mechanics start where the path does."""
    return [("interpolator", f"ref.{a}", f"axis_{a}", position_start) for a in ("x", "y")]


# --- the loops by name, for the engines (libcosim, ecos, the container, campaigns) ---------


@dataclass(frozen=True)
class Loop:
    structure: SystemStructure  # the FMUs and their wiring, from the loop's SSP file
    recorded: list  # Real outputs every engine records (contour_fmu.engines.master too)
    more_outputs: list  # further outputs a container FMU exposes
    parameters: list  # start values a container FMU exposes (besides the path_start targets)
    container_name: str

    @property
    def units(self):
        """Instance name -> FMU file: interpolator, controller, plant."""
        return self.structure.units

    @property
    def connections(self):
        """(source unit, output, destination unit, input), at every step."""
        return self.structure.connections

    @property
    def path_start(self):
        """Output at t_0 -> parameter: the plant starts where the path does."""
        return self.structure.initial_copies

    @property
    def feed_forward(self):
        """The controller's feed-forward settings every parameter set of the loop's SSP file
        holds: fitted to the loop's plant and step, and where the controller has it, the
        interpolator's look-ahead (docs/design/two-axis.md §4.12b)."""
        shared = None
        for values in self.structure.parameter_sets.values():
            settings = {k: v for k, v in values.get("controller", {}).items()
                        if k in FEED_FORWARD_SETTINGS}
            shared = settings if shared is None else shared
            if settings != shared:
                raise ValueError(f"{self.structure.file}: the parameter sets differ in the "
                                 f"controller's feed-forward ({shared} and {settings})")
        if not shared:
            raise ValueError(f"{self.structure.file}: no parameter set gives the controller "
                             f"feedForward and accelerationFeedForward")
        return shared

    def variants(self, ccc_label="fuzzy CCC"):
        """The four controllers the demos compare: (label, controller start values)."""
        return [("no CCC", {"ccc.enable": False}),
                (ccc_label, {}),
                ("feed-forward", {"ccc.enable": False, **self.feed_forward}),
                (f"{ccc_label} + feed-forward (shipped)", dict(self.feed_forward))]

    @property
    def title(self):
        """E.g. "PathInterpolator2D -> ContourCCC2D <- XYServoPlant"."""
        file = {unit: Path(name).stem for unit, name in self.units.items()}
        return f"{file['interpolator']} -> {file['controller']} <- {file['plant']}"


def _per_joint(unit, prefix):
    return [(unit, f"{prefix}.{j}") for j in FIVE_AXIS_JOINTS]


LOOPS = {
    "two_axis": Loop(
        structure=TWO_AXIS,
        recorded=[
            ("interpolator", "ref.x"), ("interpolator", "ref.y"),
            ("plant", "pos.x"), ("plant", "pos.y"),
            ("controller", "u.x"), ("controller", "u.y"), ("controller", "contourError"),
            ("controller", "ccc.Kp"),
        ],
        more_outputs=[
            ("interpolator", "done"), ("controller", "err.x"), ("controller", "err.y"),
            ("controller", "ccc.Ki"), ("controller", "ccc.Kd"),
            ("plant", "vel.x"), ("plant", "vel.y"),
        ],
        parameters=[("interpolator", "path"), ("interpolator", "feed"),
                    ("controller", "ccc.enable"), ("controller", "fuzzy.enable")],
        container_name="ContourLoop",
    ),
    "five_axis": Loop(
        structure=FIVE_AXIS,
        recorded=(_per_joint("interpolator", "ref") + _per_joint("plant", "pos")
                  + _per_joint("controller", "u")
                  + [("controller", name) for name in (
                      "contourError.tip", "contourError.orientation", "evaluation.tip",
                      "evaluation.orientation", "evaluation.delay")]),
        more_outputs=([("interpolator", "done")] + _per_joint("controller", "err")
                      + _per_joint("plant", "vel")),
        parameters=[("interpolator", "path"), ("interpolator", "feed"),
                    ("controller", "ccc.enable"), ("controller", "fuzzy.enable")],
        container_name="ContourLoop5X",
    ),
}


def engine_arguments(argv, description, step, prog=None):
    """Parses an engine's command line: [--loop NAME] FMU_DIR STEP STEPS
    [UNIT.VARIABLE=VALUE ...]. `step` is (its type, its help); `prog` the program's name
    in the usage (default: argparse's). Returns the namespace with `loop` as a Loop and
    `assignments` as (unit, variable, text) triples."""
    parser = argparse.ArgumentParser(prog=prog, description=description)
    parser.add_argument("--loop", choices=list(LOOPS), default="two_axis",
                        help="which closed loop to run (default: two_axis)")
    parser.add_argument("fmu_dir", type=Path, help="folder holding the loop's FMUs")
    parser.add_argument("step", type=step[0], help=step[1])
    parser.add_argument("steps", type=int, help="number of communication steps")
    parser.add_argument("assignments", nargs="*", metavar="UNIT.VARIABLE=VALUE",
                        help="start values, set in initialization mode")
    args = parser.parse_intermixed_args(argv)
    args.loop = LOOPS[args.loop]
    triples = []
    for assignment in args.assignments:
        target, text = assignment.split("=", 1)
        triples.append((*target.split(".", 1), text))
    args.assignments = triples
    return args
