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
