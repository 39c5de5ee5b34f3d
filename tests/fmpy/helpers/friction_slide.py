"""A mechanical axis as a Modelica tool exports one, written for pythonfmu (an exporter
independent of ours): a slide of mass m on guideways with viscous and Coulomb friction,
force F in (N), position x (m) and velocity v (m/s) out, SI throughout.

    m v' = F - b v - Fc sign(v),   stuck (v = 0) while |F| <= Fc

Integrated in fixed substeps of `substep` seconds with the force held over the
communication step; a substep in which friction would reverse the motion ends at rest,
and the slide stays stuck until |F| exceeds Fc (no chattering). Exact for the linear part
(exponential of the viscous decay), so the substep only places the stops.
"""

import math

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real


class FrictionSlide(Fmi2Slave):
    author = "contour-fmu tests"
    description = "Slide with viscous and Coulomb friction: force in, position and velocity out (SI)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.m = 5921.8  # kg
        self.b = 4.737e5  # N s/m
        self.Fc = 0.0  # N
        self.x0 = 0.0  # m
        self.substep = 1e-5  # s
        self.F = 0.0
        self.x = 0.0
        self.v = 0.0
        for name in ("m", "b", "Fc", "x0", "substep"):
            self.register_variable(Real(name, causality=Fmi2Causality.parameter,
                                        variability=Fmi2Variability.tunable))
        self.register_variable(Real("F", causality=Fmi2Causality.input))
        for name in ("x", "v"):
            self.register_variable(Real(name, causality=Fmi2Causality.output))

    def exit_initialization_mode(self):
        self.x, self.v = self.x0, 0.0

    def do_step(self, current_time, step_size):
        n = max(1, math.ceil(step_size / self.substep - 1e-9))
        h = step_size / n
        decay = math.exp(-self.b / self.m * h)
        for _ in range(n):
            if self.v == 0.0 and abs(self.F) <= self.Fc:
                continue  # stuck
            direction = self.v if self.v != 0.0 else self.F
            net = self.F - math.copysign(self.Fc, direction)
            # m v' = net - b v with net held: v -> v_inf + (v - v_inf) e^(-b h / m)
            v_inf = net / self.b
            v_new = v_inf + (self.v - v_inf) * decay
            self.x += v_inf * h + (self.v - v_inf) * (1.0 - decay) * self.m / self.b
            if self.Fc > 0.0 and v_new * direction < 0.0:
                v_new = 0.0  # friction stops a motion, never reverses it
            self.v = v_new
        return True
