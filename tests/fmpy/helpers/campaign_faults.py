"""Batch functions that misbehave on purpose, for the campaign tests: they run the real
batch (the campaign engine's) but kill their Dask worker, or interrupt
the campaign, on the batches they are told. Pickled by value (the workers do not have the
tests on their path)."""

import os
import signal
from pathlib import Path

from contour_fmu.campaign.execute import engine_batch


class KillWorker:
    """SIGKILLs the worker process running a batch that holds `run_id`: on the first
    attempt only (a marker file records it), or on every attempt."""

    def __init__(self, run_id, marker_dir, every_attempt=False):
        self.run_id, self.marker = run_id, Path(marker_dir) / f"killed-{run_id}"
        self.every_attempt = every_attempt

    def __call__(self, job, runs, archives=None):
        if any(run_id == self.run_id for run_id, _ in runs):
            if self.every_attempt or not self.marker.exists():
                self.marker.touch()
                os.kill(os.getpid(), signal.SIGKILL)
        return engine_batch(job)(job, runs, archives)


class InterruptAfter:
    """Runs `batches` batches, then raises KeyboardInterrupt as Ctrl-C would."""

    def __init__(self, batches):
        self.left = batches

    def __call__(self, job, runs, archives=None):
        if self.left == 0:
            raise KeyboardInterrupt
        self.left -= 1
        return engine_batch(job)(job, runs, archives)
