"""Campaign: a campaign's result rows on disk, written as they arrive.

OUT/rows/ holds one Parquet file per finished batch, each written under a temporary name
and renamed, so a campaign killed at any moment leaves only whole files: nothing written
is lost, and --resume reads them back. The newest small files are merged as the campaign
goes (`compact`), so a million runs leave a handful of files, not one per batch. A run may appear in several files (a lost batch
rerun by --resume); its newest row counts. OUT/campaign.json records the campaign's
digest: --resume refuses an output folder of another campaign, or of other FMUs.
At the end OUT/results.parquet holds every run's row, sorted by run id.
"""

import json
import os
from pathlib import Path

from ..extras import needs

with needs("campaign"):
    import pyarrow as pa
    import pyarrow.parquet as pq

# A row's outcome. ok, error (an FMU returned an error), crashed (an FMU killed the
# native engine's process; the message names the signal) and timeout (an FMU call did not
# return within the campaign's timeout) are final: they repeat when rerun. lost (the batch
# died with its worker twice) and failed (the batch raised outside any run, twice) are run
# again by --resume.
FINAL = ("ok", "error", "crashed", "timeout")
STATUSES = ("ok", "error", "crashed", "timeout", "lost", "failed")
# Row files are merged as the campaign goes: once this many of the newest files each hold
# fewer than SMALL_FILE_ROWS rows, they become one.
COMPACT_AFTER = 16
SMALL_FILE_ROWS = 100_000

_ARROW_TYPES = {"Real": pa.float64(), "Integer": pa.int64(), "Enumeration": pa.int64(),
                "Boolean": pa.bool_(), "String": pa.string()}


class OutputInUse(RuntimeError):
    """OUT holds results that this campaign must not overwrite or append to."""


def schema(campaign):
    fields = [("run_id", pa.int64()), ("variant", pa.string()), ("path", pa.string())]
    for name in campaign.swept:
        unit, variable = name.split(".", 1)
        fields.append((name, _ARROW_TYPES[campaign.units[unit].variables[variable].type]))
    fields += [(m, pa.float64()) for m in campaign.metrics]
    fields += [("status", pa.string()), ("message", pa.string()), ("attempts", pa.int64()),
               ("wall_time_s", pa.float64()), ("worker", pa.string())]
    return pa.schema(fields)


class ResultStore:
    """OUT's rows. One process writes to an OUT at a time: the first write takes an
    exclusive lock on OUT/.lock, held until `close` (a second writer is refused when it
    opens the store)."""

    def __init__(self, out, campaign, resume=False):
        self.out, self.campaign = Path(out), campaign
        self.rows_dir = self.out / "rows"
        self.schema = schema(campaign)
        self.marker = self.out / "campaign.json"
        self.lock = None
        if self.out.exists() and not self.out.is_dir():
            raise OutputInUse(f"--out {self.out} is a file, not a folder")
        if (self.out / ".lock").is_file() and not _lockable(self.out / ".lock"):
            raise OutputInUse(f"another process is writing campaign results to {self.out}")
        existing = self.parts()
        if self.marker.is_file() or existing:
            if not resume:
                raise OutputInUse(f"{self.out} already holds campaign results: add --resume to "
                                  "finish that campaign, or choose another --out")
            try:
                recorded = json.loads(self.marker.read_text())
            except (OSError, ValueError):
                recorded = {}
            if recorded.get("digest") != campaign.digest:
                raise OutputInUse(
                    f"{self.out} holds results of another campaign (its file, its FMUs, its runs "
                    f"or this package's version differ: digest {str(recorded.get('digest', '?'))[:12]}, "
                    f"this one {campaign.digest[:12]}); choose another --out")

    def parts(self):
        return sorted(self.rows_dir.glob("part-*.parquet")) if self.rows_dir.is_dir() else []

    def _take(self):
        """Creates OUT, takes its lock and writes campaign.json (atomically)."""
        import fcntl

        self.rows_dir.mkdir(parents=True, exist_ok=True)
        self.lock = open(self.out / ".lock", "a")
        try:
            fcntl.flock(self.lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            raise OutputInUse(f"another process is writing campaign results to {self.out}") from None
        _write_atomically(self.marker, json.dumps(
            {"name": self.campaign.name, "source": str(self.campaign.source),
             "digest": self.campaign.digest, "runs": len(self.campaign.runs)}, indent=1).encode() + b"\n")

    def close(self):
        """Releases OUT's lock (the rows stay readable)."""
        if self.lock is not None:
            self.lock.close()
            self.lock = None

    def write(self, rows):
        """Adds rows (dicts with every schema column but the run's own); durable on return.
        The first write creates the folder (nothing is written before a run finishes)."""
        if self.lock is None:
            self._take()
        runs = self.campaign.runs
        complete = []
        for row in rows:
            run = runs[row["run_id"]]
            complete.append({**row, "variant": run.variant, "path": run.path, **run.swept})
        table = pa.Table.from_pylist(complete, schema=self.schema)
        number = 1 + max((int(p.stem.split("-")[1]) for p in self.parts()), default=-1)
        _write_durably(self.rows_dir / f"part-{number:06d}.parquet", table)
        self.compact()

    def compact(self, after=COMPACT_AFTER):
        """Merges the newest row files into the oldest of them once `after` of them are
        small: a finished campaign is a handful of files, not one per batch. Safe at any
        moment: the merged file replaces the first of them, then the rest go; a kill in
        between leaves their rows twice, the same rows, and the newest counts."""
        parts = self.parts()
        small = []
        for part in reversed(parts):
            if pq.ParquetFile(part).metadata.num_rows >= SMALL_FILE_ROWS:
                break
            small.append(part)
        if len(small) < after:
            return
        small.reverse()
        merged = pa.concat_tables([pq.read_table(p, schema=self.schema) for p in small])
        _write_durably(small[0], merged)
        for part in small[1:]:
            part.unlink()

    def table(self):
        """Every run's newest row, sorted by run id (a pyarrow Table)."""
        parts = self.parts()
        if not parts:
            return self.schema.empty_table()
        table = pa.concat_tables([pq.read_table(p, schema=self.schema) for p in parts])
        newest = {}
        for i, run_id in enumerate(table.column("run_id").to_pylist()):
            newest[run_id] = i
        order = [newest[r] for r in sorted(newest)]
        return table.take(order)

    def finished(self):
        """Run ids whose newest row is final (ok or error)."""
        table = self.table()
        return {r for r, s in zip(table.column("run_id").to_pylist(),
                                  table.column("status").to_pylist()) if s in FINAL}

    def consolidate(self):
        """Merges the small row files, writes OUT/results.parquet; returns the table."""
        if self.lock is not None:
            self.compact(after=2)
        table = self.table()
        self.out.mkdir(parents=True, exist_ok=True)
        temporary = self.out / "results.parquet.tmp"
        pq.write_table(table, temporary)
        os.replace(temporary, self.out / "results.parquet")
        return table


def _lockable(path):
    """Whether no other process holds the lock on `path`."""
    import fcntl

    with open(path, "a") as f:
        try:
            fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            return False
        fcntl.flock(f, fcntl.LOCK_UN)
        return True


def _write_durably(target, table):
    """Writes a Parquet file under a temporary name, syncs it and renames it: readers see
    the old file or the whole new one."""
    temporary = target.with_suffix(".tmp")
    pq.write_table(table, temporary)
    with open(temporary, "rb") as f:
        os.fsync(f.fileno())
    os.replace(temporary, target)


def _write_atomically(path, data):
    temporary = path.with_suffix(".tmp")
    temporary.write_bytes(data)
    os.replace(temporary, path)
