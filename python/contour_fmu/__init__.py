"""Plumbing: contour-fmu's Python side, the package index: run the eight FMUs that
`fmu-build` packages in their closed loops (two-axis and five-axis).

By role, one folder each (imported on demand; this package imports nothing itself, so the
loops stay usable without fmpy). The core needs fmpy, numpy and attrs; a module marked
[extra] needs that extra of python/pyproject.toml (contour_fmu.extras) and says so when it
is missing:

- loops/: the loop wiring, the shipped SSP files (two_axis.ssd, five_axis.ssd), ssp (the
  format) and wiring (the loops by name, shared by every engine);
- engines/: what runs the FMUs, master (the fmpy master, closed_loop()), stepping,
  fmu_log, native (contour-cosim, the native master), container_build (fmpy's container),
  libcosim and ecos [engines];
- demo/ [plots, reference]: python -m contour_fmu.demo, the paper's comparison, the part,
  ballbar and five-axis demos;
- checks/: the truth computed independently of the Rust code, reference_paths
  [reference], five_axis_truth and gcode (the package's one G-code reader);
- campaign/ [campaign]: many closed-loop runs (swept plant parameters, feeds, paths,
  variants) on Dask, one Parquet row each, with a summary and plots
  (python -m contour_fmu.campaign run FILE --out DIR);
- plumbing here: cli (the console script `contour-fmu`: demo, campaign run|replay,
  libcosim, ecos), repo (where the checkout, its FMUs and programs are), extras (which
  module needs which extra), tuned (a ccc-tune result as ContourCCC2D start values),
  output_files (the demos' CSV and cross-check files), and master
  (contour_fmu.master.closed_loop, the documented entry point of engines.master).
"""

__version__ = "0.1.0"
