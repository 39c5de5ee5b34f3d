"""contour-fmu's Python side: run the six FMUs that `fmu-build` packages in their closed
loops (two-axis and five-axis).

Modules (imported on demand; this package imports nothing itself, so `wiring` stays usable
without fmpy). The core needs fmpy, numpy and attrs; a module marked [extra] needs that extra of
python/pyproject.toml (contour_fmu.extras) and says so when it is missing:

- wiring: the paper's loop as a list of connections, shared by every master;
- master: a fixed-step Gauss-Seidel or Jacobi master on fmpy's FMU2Slave, closed_loop();
- stepping: the fixed-step loop of the master and the campaigns;
- fmu_log: fmpy logger callbacks that collect the FMUs' messages (FmuLog);
- tuned: a ccc-tune result as ContourCCC2D start values;
- reference_paths [reference]: the built-in paths rebuilt in Python and the true contour
  error;
- demo [plots, reference]: the paper's comparison through the FMUs (python -m
  contour_fmu.demo);
- loops: the two-axis and five-axis loops by name, for the outside engines below;
- container_build: a loop packed into one FMU with fmpy's container;
- cosim_closed_loop, ecos_closed_loop [engines]: a loop in libcosim and in ecos (run as
  python -m contour_fmu.cosim_closed_loop / .ecos_closed_loop [--loop five_axis]);
- campaign [campaign]: many closed-loop runs (swept plant parameters, feeds, paths,
  variants) on Dask, one Parquet row each, with a summary and plots
  (python -m contour_fmu.campaign run FILE --out DIR);
- cli: the console script `contour-fmu` (demo, campaign run|replay, libcosim, ecos);
- extras: which module needs which extra;
- repo: where the checkout, its FMUs and ccc-tune are.
"""

__version__ = "0.1.0"
