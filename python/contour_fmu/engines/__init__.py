"""Engines: what runs the FMUs, each on the loops of contour_fmu.loops.

- master: the fmpy master (Gauss-Seidel or Jacobi on fmpy's FMU2Slave), closed_loop() and
  five_axis_closed_loop(); contour_fmu.master.closed_loop is its documented entry point;
- stepping: the fixed-step loop of the master and the campaigns' fmpy runner;
- fmu_log: fmpy logger callbacks that collect the FMUs' messages (FmuLog);
- native: the one wrapper of contour-cosim, the native master (a run, or a batch process
  for many runs);
- container_build: a loop packed into one FMU with fmpy's container;
- libcosim, ecos [engines extra]: a loop in libcosim and in ecos, each in its own process
  (python -m contour_fmu.engines.libcosim / .ecos [--loop five_axis]).

This file imports nothing.
"""
