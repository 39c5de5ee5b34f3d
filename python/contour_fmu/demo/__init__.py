"""Demos: the paper's comparison and the parts, through the FMUs, as `python -m
contour_fmu.demo` (__main__, also `contour-fmu demo`) runs them one after the other.

- paper: the paper's comparison on the circle, infinity and trident, with and without
  CCC, tuned or not, and on each path's mirror image;
- part: a G-code part planned within acceleration and jerk limits (its truth from
  contour_fmu.checks.gcode, the package's one G-code reader);
- ballbar: the circular test of ISO 230-4 on the plant with friction (contour-eval);
- five_axis: the five-axis loop on the built-in paths, the blade and the domes (its truth
  from contour_fmu.checks.five_axis_truth);
- cam_paths: five-axis CL data shaped like a CAM system's (the domes; the tests use them).

Each demo runs alone too: python -m contour_fmu.demo.part / .ballbar. They need the plots
and reference extras. This file imports nothing.
"""
