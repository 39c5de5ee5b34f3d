"""Demo: CL data shaped like a five-axis CAM system's output, for the five-axis demo and the
tests: the tool normal to a surface, through or beside vertical (docs/design/five-axis.md
§5.3b).

Each function returns APT text (`GOTO/x,y,z,i,j,k`, mm, workpiece frame)."""

import math


def _goto(poses):
    return "".join(f"GOTO/{x:.6f},{y:.6f},{z:.6f},{i:.12f},{j:.12f},{k:.12f}\n"
                   for x, y, z, i, j, k in poses)


def tilting_pass(beside_deg=0.0, length=60.0, step=0.5, tilt_deg=30.0):
    """A straight pass along x whose tool axis tilts from +tilt to −tilt about y, passing
    `beside_deg` to the side of vertical (0: through it)."""
    n = round(length / step)
    e = math.radians(beside_deg)
    poses = []
    for i in range(n + 1):
        f = i / n
        th = math.radians(tilt_deg * (1 - 2 * f))
        poses.append((-length / 2 + length * f, 0.0, 0.0,
                      math.sin(th) * math.cos(e), math.sin(e), math.cos(th) * math.cos(e)))
    return _goto(poses)


def dome_raster(radius=40.0, stepover=2.0, passes=2, step=0.5, within_deg=45.0, offset=0.0):
    """A finishing raster over a hemisphere, the tool normal to the surface: 2·passes + 1
    passes along x, zigzag, `stepover` apart, the middle one `offset` mm beside the apex,
    `step` mm between CL points, within `within_deg` of the apex."""
    poses = []
    for k, j in enumerate(range(-passes, passes + 1)):
        y = stepover * j + offset
        half = math.sqrt((radius * math.sin(math.radians(within_deg))) ** 2 - y * y)
        steps = math.ceil(2 * half / step)
        for i in range(steps + 1):
            f = i / steps if k % 2 == 0 else 1 - i / steps
            x = -half + 2 * half * f
            z = math.sqrt(radius * radius - x * x - y * y)
            poses.append((x, y, z, x / radius, y / radius, z / radius))
    return _goto(poses)
