"""Reference checks: the truth that the demos, campaigns and tests measure the FMUs
against, computed in Python independently of the Rust code.

- reference_paths [reference]: the built-in two-axis paths rebuilt (geomdl) and the true
  contour error to them;
- five_axis_truth: the five-axis forward kinematics written out again and the true tip
  and orientation errors;
- gcode: the package's one G-code reader, the programmed part in closed form and the
  exact distance to it (the part demo's truth), and a program's mirror image.

This file imports nothing.
"""
