"""The closed loops an outside engine (libcosim, ecos, fmpy's container) can run, by name:
which FMUs and how they are wired (the shipped SSP files, contour_fmu.wiring), what is
recorded. One table, so that each engine runs either loop from the same code. It imports
nothing that loads fmpy or an engine, so an engine's own process can use it.
"""

import argparse
from dataclasses import dataclass
from pathlib import Path

from .ssp import SystemStructure
from .wiring import FIVE_AXIS, FIVE_AXIS_JOINTS, TWO_AXIS


@dataclass(frozen=True)
class Loop:
    structure: SystemStructure  # the FMUs and their wiring, from the loop's SSP file
    recorded: list  # Real outputs every engine records; contour_fmu.master records them too
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
