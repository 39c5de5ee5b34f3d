"""Loop wiring: the closed loops every master runs, as SSP 1.0 files and what is read from
them.

- two_axis.ssd, five_axis.ssd (si/: the SI build's copies): the shipped loops, package
  data, copied beside the FMUs by make fmus;
- ssp: the SSP format, read and written (python -m contour_fmu.loops.ssp writes si/);
- wiring: the loops as the masters run them (TWO_AXIS, FIVE_AXIS, LOOPS by name with what
  each engine records, the drive loop's wiring).

Standard library only, and this file imports nothing, so `python -m contour_fmu.loops.ssp`
runs its module once.
"""
