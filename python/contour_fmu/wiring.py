"""How the loops are wired, shared by every master (fmpy, libcosim, container, the
campaigns): interpolator -> controller <- plant, as the shipped SSP files describe them
(contour_fmu/loops/*.ssd, read by contour_fmu.ssp). Standard library only, so a process
can use it without loading fmpy."""

from .ssp import shipped

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
