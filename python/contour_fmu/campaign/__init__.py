"""Campaign: campaigns of closed-loop co-simulations on Dask: a TOML file names the loop,
its FMUs, fixed and swept parameters, paths and metrics; every run becomes one Parquet row.

    python -m contour_fmu.campaign run FILE --out DIR [--scheduler ADDRESS] [--workers N]
                                                      [--resume] [--serial]
    python -m contour_fmu.campaign replay FILE --run ID [--out DIR]

Modules: spec (the file, checked and expanded into runs), runner (what a worker does:
extract, instantiate, reset, step, measure), metrics, store (the Parquet rows),
execute (Dask or serial), report (summary and plots), __main__ (the command line, also
`contour-fmu campaign`). Running, replaying and reporting need the campaign extra; spec
and runner need only the core.
"""

from .spec import CampaignError, load  # noqa: F401
