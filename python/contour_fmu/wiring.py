"""How the paper's closed loop is wired, shared by every master (fmpy, libcosim,
container): interpolator -> controller <- plant. Kept free of imports so a process can
use it without loading fmpy."""

CLOSED_LOOP_CONNECTIONS = [
    ("interpolator", "ref.x", "controller", "ref.x"),
    ("interpolator", "ref.y", "controller", "ref.y"),
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
    + [("plant", f"pos.{j}", "controller", f"pos.{j}") for j in FIVE_AXIS_JOINTS]
    + [("controller", f"u.{j}", "plant", f"u.{j}") for j in FIVE_AXIS_JOINTS]
)

# The plant starts at the path's start joints.
FIVE_AXIS_PATH_START = [("interpolator", f"ref.{j}", "plant", f"pos0.{j}") for j in FIVE_AXIS_JOINTS]
