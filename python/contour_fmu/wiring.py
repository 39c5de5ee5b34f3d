"""How the paper's closed loop is wired, shared by every master (fmpy, libcosim,
container): interpolator -> controller <- plant. Kept free of imports so a process can
use it without loading fmpy."""

CLOSED_LOOP_CONNECTIONS = [
    ("interpolator", "ref.x", "controller", "ref.x"),
    ("interpolator", "ref.y", "controller", "ref.y"),
    # The reference's velocity and acceleration, for the controller's feed-forward
    # (feedForward, accelerationFeedForward > 0).
    ("interpolator", "vref.x", "controller", "vref.x"),
    ("interpolator", "vref.y", "controller", "vref.y"),
    ("interpolator", "aref.x", "controller", "aref.x"),
    ("interpolator", "aref.y", "controller", "aref.y"),
    ("plant", "pos.x", "controller", "pos.x"),
    ("plant", "pos.y", "controller", "pos.y"),
    ("controller", "u.x", "plant", "u.x"),
    ("controller", "u.y", "plant", "u.y"),
]

# The plant starts where the path does.
PATH_START = [
    ("interpolator", "ref.x", "plant", "pos0.x"),
    ("interpolator", "ref.y", "plant", "pos0.y"),
]

FIVE_AXIS_JOINTS = ("X", "Y", "Z", "A", "C")

# The five-axis loop: PathInterpolator5X -> ContourCCC5X <- FiveAxisPlant.
FIVE_AXIS_CONNECTIONS = (
    [("interpolator", f"ref.{j}", "controller", f"ref.{j}") for j in FIVE_AXIS_JOINTS]
    # The reference's joint velocities and accelerations, for the feed-forward
    # (feedForward, accelerationFeedForward > 0).
    + [("interpolator", f"vref.{j}", "controller", f"vref.{j}") for j in FIVE_AXIS_JOINTS]
    + [("interpolator", f"aref.{j}", "controller", f"aref.{j}") for j in FIVE_AXIS_JOINTS]
    + [("plant", f"pos.{j}", "controller", f"pos.{j}") for j in FIVE_AXIS_JOINTS]
    + [("controller", f"u.{j}", "plant", f"u.{j}") for j in FIVE_AXIS_JOINTS]
)

# The plant starts at the path's start joints.
FIVE_AXIS_PATH_START = [("interpolator", f"ref.{j}", "plant", f"pos0.{j}") for j in FIVE_AXIS_JOINTS]

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
