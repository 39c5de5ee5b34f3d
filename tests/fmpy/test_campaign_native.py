"""Campaigns on the native engine (issue 25, steps 3 and 4; issue 43, item 1): the same rows
as on fmpy, the true errors within metrics.ENGINE_AGREEMENT (contour-cosim measures them,
fmpy's in Python) and the controller's estimates to the bit; a
foreign plant FMU that segfaults or hangs costs its run only, recorded as "crashed" or
"timeout", which --resume does not run again; workers that cannot run contour-cosim stop the
campaign before any run; batches sized by work; row files merged as the campaign goes."""

import math

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from contour_fmu.campaign import load
from contour_fmu.campaign.execute import BatchSizer, RunnerUnavailable, execute
from contour_fmu.campaign.metrics import agreement
from contour_fmu.campaign.store import ResultStore
from helpers import faulty_fmu

CIRCUMSTANTIAL = ("wall_time_s", "worker", "attempts")

# 2 variants × 2 paths: the circle to its end (the end signal) and a stretch of the trident.
ENGINES = """
name = "engines"
loop = "two_axis"
stop = "end_of_path"
settle = 0.02
max_stop = {max_stop}
engine = "{engine}"
metrics = ["contour_error.max", "contour_error.mean", "estimated_contour_error.max"]
batch_size = 3

[fmus]
directory = "{fmus}"

[[paths]]
path = "circle"

[[paths]]
path = "infinity"
feed = 60.0

[[variants]]
name = "no CCC"
parameters = {{ "controller.ccc.enable" = false }}

[[variants]]
name = "fuzzy-PID CCC"
"""


def campaign(tmp_path, text, **fields):
    file = tmp_path / f"{fields.get('engine', 'c')}-{len(list(tmp_path.iterdir()))}.toml"
    file.write_text(text.format(**fields))
    return load(file)


def columns(table):
    return {k: v for k, v in table.to_pydict().items() if k not in CIRCUMSTANTIAL}


def assert_same_rows(native, fmpy):
    """Every column equal, the metrics within their agreement (0 for the estimates)."""
    assert native.keys() == fmpy.keys()
    for name in fmpy:
        if name.rsplit(".", 1)[-1] in ("max", "mean") and name in METRIC_NAMES:
            tolerance = agreement(name)
            for a, b in zip(native[name], fmpy[name]):
                assert a == b if tolerance == 0 else abs(a - b) <= tolerance, (name, a, b)
        else:
            assert native[name] == fmpy[name], name


METRIC_NAMES = {f"{q}.{s}" for q in ("contour_error", "estimated_contour_error", "tip_error",
                                      "orientation_error", "estimated_tip_error",
                                      "estimated_orientation_error") for s in ("max", "mean")}


def test_the_native_and_fmpy_engines_give_the_same_rows(fmus, cosim, tmp_path):
    tables = {}
    for engine in ("native", "fmpy"):
        c = campaign(tmp_path, ENGINES, engine=engine, fmus=fmus, max_stop=600.0)
        tables[engine] = execute(c, tmp_path / engine, serial=True, show_progress=False).consolidate()
    native, fmpy = columns(tables["native"]), columns(tables["fmpy"])
    assert native["status"] == ["ok"] * 4
    assert_same_rows(native, fmpy)
    assert 0.001 < max(native["contour_error.max"]) < 1.0  # mm: real runs
    # A run that cannot end fails on both, as an error row.
    for engine in ("native", "fmpy"):
        c = campaign(tmp_path, ENGINES, engine=engine, fmus=fmus, max_stop=0.5)
        table = execute(c, tmp_path / f"{engine}-short", serial=True, show_progress=False).consolidate()
        statuses = table.column("status").to_pylist()
        assert statuses[:2] == ["error", "error"], (engine, table.column("message").to_pylist())
        assert "0.5" in table.column("message").to_pylist()[0]


FIVE_AXIS = """
name = "five-axis engines"
loop = "five_axis"
stop = 0.8
engine = "{engine}"
metrics = ["tip_error.max", "tip_error.mean", "orientation_error.max", "orientation_error.mean",
           "estimated_tip_error.max", "estimated_orientation_error.mean"]
batch_size = 3

[fmus]
directory = "{fmus}"

[[paths]]
path = "tilted_helix"

[[paths]]
path = "figure_eight"

[[paths]]
path = "blade.cl"
feed = 20.0

[[variants]]
name = "no CCC"
parameters = {{ "controller.ccc.enable" = false, "interpolator.pivot.A.z" = -25.0 }}

[[variants]]
name = "five-axis CCC"
"""


def test_five_axis_rows_agree_between_the_engines(fmus, cosim, tmp_path):
    """The tool-tip and orientation errors, measured in Rust by contour-cosim and in Python
    (five_axis_truth) on the fmpy engine, within 1e-12 mm and rad; the controller's
    estimates to the bit; on the helix, the figure-eight and a CAM file, with a moved pivot."""
    tables = {engine: execute(campaign(tmp_path, FIVE_AXIS, engine=engine, fmus=fmus),
                              tmp_path / engine, serial=True, show_progress=False).consolidate()
              for engine in ("native", "fmpy")}
    native, fmpy = columns(tables["native"]), columns(tables["fmpy"])
    assert native["status"] == ["ok"] * 6, native["message"]
    assert_same_rows(native, fmpy)
    assert min(native["tip_error.max"]) > 1e-4 and min(native["orientation_error.max"]) > 1e-6


FAULTY = """
name = "faulty plant"
loop = "two_axis"
stop = 0.3
timeout = 1.0
metrics = ["contour_error.max"]
batch_size = 2

[fmus]
directory = "{fmus}"
plant = "{plant}"

[[paths]]
path = "circle"

[[variants]]
name = "fine"

[[variants]]
name = "segfault"
parameters = {{ "plant.fault" = 1, "plant.fault_time" = 0.1 }}

[[variants]]
name = "hang"
parameters = {{ "plant.fault" = 2, "plant.fault_time" = 0.2 }}

[[variants]]
name = "fatal"
parameters = {{ "plant.fault" = 4, "plant.fault_time" = 0.1 }}

[[variants]]
name = "fine again"
parameters = {{ "plant.fault_time" = 0.1 }}
"""


def test_a_plant_that_segfaults_or_hangs_costs_its_run_only(fmus, cosim, tmp_path):
    """On two Dask workers: the segfault is "crashed" with its signal, the hang "timeout"
    after the campaign's 1 s, fmi2Fatal an error (and a new process for the next run, since
    the FMU may not be called again); the runs after them in the same batches run;
    --resume runs none of them again."""
    faulty_fmu.build(tmp_path)
    c = campaign(tmp_path, FAULTY, fmus=fmus, plant=tmp_path / "Faulty.fmu")
    out = tmp_path / "out"
    table = execute(c, out, workers=2, show_progress=False).consolidate()
    rows = table.to_pydict()
    assert rows["status"] == ["ok", "crashed", "timeout", "error", "ok"], rows["message"]
    assert "killed by SIGSEGV (signal 11)" in rows["message"][1]
    assert "did not return within 1 s" in rows["message"][2]
    assert "plant: fmi2DoStep returned Fatal at t = 0.1" in rows["message"][3]
    assert all(math.isnan(rows["contour_error.max"][k]) for k in (1, 2, 3))
    # The ideal axes follow the circle closely: real values, equal for equal runs.
    assert 0 < rows["contour_error.max"][0] == rows["contour_error.max"][4] < 1.0
    files = sorted(p.name for p in (out / "rows").iterdir())
    again = execute(c, out, resume=True, serial=True, show_progress=False).consolidate()
    assert sorted(p.name for p in (out / "rows").iterdir()) == files  # nothing ran
    assert again.column("status").to_pylist() == rows["status"]


def test_runs_sent_ahead_of_a_crash_run_on_the_next_child(fmus, cosim, tmp_path):
    """The native engine sends a run line ahead of the answer it waits for: in one batch,
    the run after a segfault, an fmi2Fatal or a hang, which the ended child had taken but
    not run, runs on the next child and gives the same row as the first run."""
    faulty_fmu.build(tmp_path)
    fine = 'parameters = {{ "plant.fault_time" = 0.1 }}'
    variants = [("fine", ""), ("segfault", 'parameters = {{ "plant.fault" = 1, "plant.fault_time" = 0.1 }}'),
                ("fine 2", fine), ("fatal", 'parameters = {{ "plant.fault" = 4, "plant.fault_time" = 0.1 }}'),
                ("fine 3", fine), ("hang", 'parameters = {{ "plant.fault" = 2, "plant.fault_time" = 0.2 }}'),
                ("fine 4", fine)]
    text = FAULTY[:FAULTY.index("[[variants]]")].replace("batch_size = 2", "batch_size = 7")
    text += "".join(f'[[variants]]\nname = "{name}"\n{extra}\n\n' for name, extra in variants)
    c = campaign(tmp_path, text, fmus=fmus, plant=tmp_path / "Faulty.fmu")
    rows = execute(c, tmp_path / "out", serial=True, show_progress=False).consolidate().to_pydict()
    assert rows["status"] == ["ok", "crashed", "ok", "error", "ok", "timeout", "ok"], rows["message"]
    assert len(set(rows["contour_error.max"][k] for k in (0, 2, 4, 6))) == 1


def test_workers_that_cannot_run_contour_cosim_stop_the_campaign_before_any_run(
        fmus, tmp_path, monkeypatch):
    broken = tmp_path / "contour-cosim"
    broken.write_text("#!/bin/sh\necho 'cannot execute binary file: Exec format error' >&2\nexit 126\n")
    broken.chmod(0o755)
    monkeypatch.setenv("CONTOUR_COSIM", str(broken))
    c = campaign(tmp_path, ENGINES, engine="native", fmus=fmus, max_stop=600.0)
    with pytest.raises(RunnerUnavailable, match="cannot run contour-cosim .exit status 126.*"
                                                 "Exec format error.*engine = \"fmpy\""):
        execute(c, tmp_path / "out", workers=1, show_progress=False)
    assert not (tmp_path / "out" / "rows").exists() or not any((tmp_path / "out" / "rows").iterdir())


def test_auto_batches_hold_about_a_second_of_work_and_shrink_at_the_end():
    fixed = BatchSizer(7, workers=2)
    assert fixed.size(1000) == 7
    auto = BatchSizer(None, workers=2)
    assert auto.size(1000) == 2  # nothing measured yet
    auto.observe([{"wall_time_s": 0.004}] * 10 + [{"wall_time_s": float("nan")}])
    assert auto.size(100_000) == 250  # 1 s / 4 ms
    assert auto.size(600) == 150  # a quarter of what is left: both workers busy to the end
    assert auto.size(1) == 1


def test_row_files_are_merged_as_the_campaign_goes(fmus, tmp_path):
    """40 batches of 3 rows: never more than 16 files (a merge at the 16th), one once the
    campaign is consolidated; every row kept in order, so a rerun row still counts over
    its older copy."""
    c = campaign(tmp_path, ENGINES, engine="native", fmus=fmus, max_stop=600.0)
    store = ResultStore(tmp_path / "out", c)
    metrics = {m: 0.5 for m in c.metrics}
    for batch in range(40):
        store.write([{"run_id": (3 * batch + i) % 4, "status": "ok", "message": f"{batch}",
                      "attempts": 1, "wall_time_s": 0.1, "worker": "w", **metrics} for i in range(3)])
        assert len(store.parts()) < 16
    assert len(store.parts()) == 40 - 31 + 1  # merged at the 16th and the 31st write
    store.consolidate()
    assert len(store.parts()) == 1
    table = store.table().to_pydict()
    # Run r's newest row is from the last batch that held it.
    newest = {r: max(b for b in range(40) for i in range(3) if (3 * b + i) % 4 == r) for r in range(4)}
    assert table["message"] == [str(newest[r]) for r in range(4)]
    everything = pa.concat_tables([pq.read_table(p) for p in store.parts()])
    assert everything.num_rows == 120
    store.close()
    assert np.array_equal(table["run_id"], [0, 1, 2, 3])
