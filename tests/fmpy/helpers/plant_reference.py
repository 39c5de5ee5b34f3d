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


def friction_torque(speed, coulomb, stiction, stribeck):
    """Sliding friction at `speed` > 0 (axis units/s): Tc + (Ts - Tc) exp(-(v/vs)^2)."""
    breakaway = max(coulomb, stiction)
    if stribeck > 0.0 and breakaway > coulomb:
        return coulomb + (breakaway - coulomb) * np.exp(-((speed / stribeck) ** 2))
    return coulomb


def simulate_axis_with_friction(params, times, commands, coulomb, stiction, stribeck):
    """The same axis with Coulomb, static and Stribeck friction at the motor (N.m; the
    Stribeck velocity in mm/s), as a hybrid system: sliding either way (the friction
    opposing the motor's speed) or stuck (speed 0 while the drive's torque is within the
    breakaway torque), solve_ivp with events at the speed's zero crossings and at
    breakaway. Positions and velocities (mm, mm/s) at `times`."""
    J, B, CT, lead, Kvp, Kvi = (params[k] for k in ("J", "B", "CT", "lead", "Kvp", "Kvi"))
    k = 2.0 * np.pi / lead
    breakaway = max(coulomb, stiction)

    def drive_torque(w_cmd, s):
        return CT * (Kvp * (w_cmd - s[1]) + Kvi * s[2])

    def sliding(w_cmd, direction):
        def rhs(_t, s):
            f = direction * friction_torque(abs(s[1]) / k, coulomb, stiction, stribeck)
            return [s[1], (drive_torque(w_cmd, s) - B * s[1] - f) / J, w_cmd - s[1]]

        def stops(_t, s):
            return s[1]

        stops.terminal, stops.direction = True, -direction
        return rhs, [stops]

    def stuck(w_cmd):
        def rhs(_t, _s):
            return [0.0, 0.0, w_cmd]

        def breaks_forward(_t, s):
            return drive_torque(w_cmd, s) - breakaway

        def breaks_backward(_t, s):
            return drive_torque(w_cmd, s) + breakaway

        breaks_forward.terminal, breaks_forward.direction = True, 1
        breaks_backward.terminal, breaks_backward.direction = True, -1
        return rhs, [breaks_forward, breaks_backward]

    def mode_at_rest(w_cmd, s):
        torque = drive_torque(w_cmd, s)
        if abs(torque) <= breakaway:
            return 0
        return 1 if torque > 0 else -1

    state = np.array([0.0, 0.0, 0.0])
    mode = 0
    positions, velocities = [0.0], [0.0]
    for n in range(len(times) - 1):
        w_cmd = commands[n] * k
        t, end = times[n], times[n + 1]
        if mode == 0:
            mode = mode_at_rest(w_cmd, state)
        while t < end:
            rhs, events = stuck(w_cmd) if mode == 0 else sliding(w_cmd, mode)
            sol = solve_ivp(rhs, (t, end), state, method="DOP853", rtol=1e-12, atol=1e-12,
                            events=events)
            state, t = sol.y[:, -1].copy(), sol.t[-1]
            if sol.status == 1:  # an event: the motor stopped, or it broke away
                state[1] = 0.0
                torque = drive_torque(w_cmd, state)
                if mode == 0:
                    mode = 1 if torque > 0 else -1
                else:
                    mode = mode_at_rest(w_cmd, state)
        positions.append(state[0] / k)
        velocities.append(state[1] / k)
    return np.array(positions), np.array(velocities)
