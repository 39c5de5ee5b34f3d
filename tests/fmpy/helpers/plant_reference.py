"""An independent model of the XYServoPlant axis (docs/design/two-axis.md §4.5) for scipy.

Written in the motor's own coordinates (angle, speed, PI integral of the speed error),
not in the screw coordinates the Rust code uses, and integrated by solve_ivp at tight
tolerance, one communication interval at a time with the command held (zero-order hold,
as a co-simulation master applies it).
"""

import numpy as np
from scipy.integrate import solve_ivp

PAPER_AXIS = dict(J=0.015, B=1.2, CT=0.57, lead=10.0, Kvp=8.26, Kvi=661.0)


def axis_rhs(params, v_cmd):
    J, B, CT, lead, Kvp, Kvi = (params[k] for k in ("J", "B", "CT", "lead", "Kvp", "Kvi"))
    w_cmd = v_cmd * 2.0 * np.pi / lead  # rad/s

    def rhs(_t, s):
        theta, w, integral = s
        current = Kvp * (w_cmd - w) + Kvi * integral
        return [w, (CT * current - B * w) / J, w_cmd - w]

    return rhs


def simulate_axis(params, times, commands, x0=0.0):
    """Positions (mm) and velocities (mm/s) at `times`, the command commands[k] held on
    [times[k], times[k+1])."""
    lead = params["lead"]
    state = np.array([x0 * 2.0 * np.pi / lead, 0.0, 0.0])
    positions, velocities = [x0], [0.0]
    for k in range(len(times) - 1):
        sol = solve_ivp(
            axis_rhs(params, commands[k]),
            (times[k], times[k + 1]),
            state,
            method="DOP853",
            rtol=1e-12,
            atol=1e-12,
        )
        state = sol.y[:, -1]
        positions.append(state[0] * lead / (2.0 * np.pi))
        velocities.append(state[1] * lead / (2.0 * np.pi))
    return np.array(positions), np.array(velocities)
