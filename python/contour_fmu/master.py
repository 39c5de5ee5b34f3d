"""Entry point: `contour_fmu.master.closed_loop`, as the README and docs/usage.md call it;
the fmpy master itself is contour_fmu.engines.master."""

from .engines.master import closed_loop  # noqa: F401
