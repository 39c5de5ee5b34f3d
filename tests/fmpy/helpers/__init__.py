"""Helpers of the FMU tests (tests/fmpy), imported as `helpers.<module>`:

- checkout: the checkout's root and cargo's target folder;
- fmu_slave: one FMU instance through fmpy with its log captured (contour_fmu.engines.fmu_log);
- plant_reference: an independent scipy model of the XYServoPlant axis;
- campaign_faults: batch functions that kill their Dask worker or interrupt a campaign;
- cosim_run.py: one FMU in libcosim, a script the tests run in a subprocess by its path.
"""
