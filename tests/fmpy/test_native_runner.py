"""The native master, contour-cosim (issue 25, step 2): the shipped loops' SSP files run
through the FMUs give the trajectories of contour_fmu.engines.master (fmpy) bit for bit, in both
coupling schemes; libcosim reading the same SSP file agrees with its Jacobi run within the
engines' known difference (libcosim's steps from integer nanoseconds); what it cannot run is
refused before any run, naming the file."""

import json
import shutil
import subprocess
import sys
import time
import zipfile

import numpy as np
import pytest

from contour_fmu import repo
from contour_fmu.engines import native
from contour_fmu.engines.master import CLOSED_LOOP_RECORD, FIVE_AXIS_RECORD, closed_loop, five_axis_closed_loop
from contour_fmu.loops.wiring import LOOPS
from helpers import faulty_fmu

STEP = 1e-3


@pytest.fixture(scope="module")
def loops(fmus, cosim):
    """The shipped SSP files beside the module's private copy of the FMUs."""
    for name in ("two_axis", "five_axis"):
        shutil.copy2(native.SHIPPED / f"{name}.ssd", fmus / f"{name}.ssd")
    return fmus


CASES = {
    # loop: (master function, recorded columns, path, stop)
    "two_axis": (closed_loop, CLOSED_LOOP_RECORD, "trident", 1.5),
    "five_axis": (five_axis_closed_loop, FIVE_AXIS_RECORD, "tilted_helix", 0.6),
}


@pytest.mark.parametrize("scheme", ["gauss-seidel", "jacobi"])
@pytest.mark.parametrize("loop", list(CASES))
def test_native_runner_equals_the_fmpy_master_bit_for_bit(loops, loop, scheme):
    master, record, path, stop = CASES[loop]
    before, after = master(loops, path=path, stop=stop, step=STEP, scheme=scheme)
    rows = native.run(loops / f"{loop}.ssd", start={"interpolator": {"path": path}}, step=STEP,
                      stop=stop, scheme=scheme, record=record)
    ours_before, ours_after = native.as_before_after(rows, STEP)
    assert len(ours_before) == len(before) == round(stop / STEP)
    for column in before.dtype.names:
        assert np.array_equal(ours_before[column], before[column]), column
        assert np.array_equal(ours_after[column], after[column]), column
    # Not trivially equal: the loop moved, and the two schemes differ.
    assert np.ptp(rows[f"plant.{record[2][1] if loop == 'two_axis' else 'pos.X'}"]) > 5.0


def test_the_schemes_differ_and_a_parameter_set_equals_the_initial_copies(loops):
    """The Gauss-Seidel and Jacobi runs are different trajectories (the comparison above
    can tell them apart), and the five-axis path's parameter set starts the plant where the
    initial copies do (and sets the controller's feed-forward, as the wiring reads it)."""
    ssd = loops / "five_axis.ssd"
    record = [("plant", "pos.X"), ("plant", "pos.Y"), ("controller", "u.X")]
    gs = native.run(ssd, parameter_set="tilted_helix", stop=0.2, record=record)
    jacobi = native.run(ssd, parameter_set="tilted_helix", stop=0.2, record=record, scheme="jacobi")
    copied = native.run(ssd, start={"interpolator": {"path": "tilted_helix"},
                                    "controller": LOOPS["five_axis"].feed_forward},
                        stop=0.2, record=record)
    assert np.abs(gs["plant.pos.X"] - jacobi["plant.pos.X"]).max() > 1e-4
    for column in gs.dtype.names:
        assert np.array_equal(gs[column], copied[column]), column
    assert abs(gs["plant.pos.Y"][0] + 46.98) < 0.1  # the helix does not start at the origin


def libcosim(fmu_dir, loop, steps):
    done = subprocess.run(
        [sys.executable, "-m", "contour_fmu.engines.libcosim", "--loop", loop, "--ssp",
         str(fmu_dir), "1000000", str(steps)],
        capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])["series"]


@pytest.mark.parametrize("loop, steps, tolerance", [("two_axis", 2000, 1e-6), ("five_axis", 500, 1e-6)])
def test_native_jacobi_equals_libcosim_on_the_same_ssp(loops, loop, steps, tolerance):
    """libcosim reads the SSP file itself and applies its first parameter set. Its sample n
    is the state at t_n (row n here). The difference is libcosim's: it steps from integer
    nanoseconds, so its h differs from 1e-3 in the last bits at some steps
    (test_libcosim_closed_loop.py)."""
    series = libcosim(loops, loop, steps)
    default = "circle" if loop == "two_axis" else "tilted_helix"
    record = [tuple(c.split(".", 1)) for c in series]
    rows = native.run(loops / f"{loop}.ssd", parameter_set=default, stop=steps * STEP,
                      scheme="jacobi", record=record)
    positions = [c for c in series if c.startswith("plant.pos.")]
    for column in positions:
        assert np.abs(rows[column][1:] - np.asarray(series[column])).max() <= tolerance, column
    # One step of misalignment would be far larger.
    assert max(np.abs(rows[c][:-1] - np.asarray(series[c])).max() for c in positions) > 1e3 * tolerance


def refused(cosim, *args):
    done = subprocess.run([str(cosim), *map(str, args)], capture_output=True, text=True)
    assert done.returncode == 2, (done.returncode, done.stderr)
    assert done.stdout == ""
    return done.stderr


def test_bad_loops_are_refused_before_any_run_naming_the_file(loops, cosim, tmp_path):
    shipped = (loops / "two_axis.ssd").read_text()
    for name in ("PathInterpolator2D", "ContourCCC2D", "XYServoPlant"):
        shutil.copy2(loops / f"{name}.fmu", tmp_path / f"{name}.fmu")
    cases = [
        (shipped.replace('source="XYServoPlant.fmu"', 'source="Missing.fmu"'),
         "component plant: ", "Missing.fmu: no such FMU"),
        # A connector (and its connection) naming a variable the FMU does not have.
        (shipped.replace('<ssd:Connector name="u.x" kind="input">', '<ssd:Connector name="u.z" kind="input">')
         .replace('endElement="plant" endConnector="u.x"', 'endElement="plant" endConnector="u.z"'),
         "plant (XYServoPlant.fmu) has no variable \"u.z\""),
        # A type mismatch: the interpolator's Boolean `done` onto the controller's Real ref.x.
        (shipped.replace('<ssd:Connector name="ref.x" kind="output"><ssc:Real/>',
                         '<ssd:Connector name="done" kind="output"><ssc:Boolean/>')
         .replace('startConnector="ref.x" endElement="controller"', 'startConnector="done" endElement="controller"')
         .replace('startConnector="ref.x" endElement="plant"', 'startConnector="done" endElement="plant"'),
         "connection interpolator.done -> controller.ref.x: a Boolean onto a Real"),
        (shipped.replace('<ssc:Real/></ssd:Connector>', '<ssc:Integer/></ssd:Connector>', 1),
         "connector interpolator.ref.x is declared Integer, but the FMU's variable is a Real"),
        (shipped[:400], "not a readable system structure description"),
    ]
    for i, (text, *words) in enumerate(cases):
        file = tmp_path / f"case{i}.ssd"
        file.write_text(text)
        message = refused(cosim, "run", file, "--stop", 0.1)
        assert str(file) in message, message
        for w in words:
            assert w in message, message
    # A malformed archive, and an archive without its structure description.
    broken = tmp_path / "broken.ssp"
    broken.write_bytes(b"PK\x03\x04 not really a zip")
    assert f"{broken}: not an SSP archive" in refused(cosim, "run", broken)
    empty = tmp_path / "empty.ssp"
    with zipfile.ZipFile(empty, "w") as z:
        z.writestr("README", "nothing")
    assert f"{empty}: the archive holds no SystemStructure.ssd" in refused(cosim, "run", empty)
    # A corrupt FMU: not a zip.
    (tmp_path / "XYServoPlant.fmu").write_bytes(b"not a zip")
    file = tmp_path / "corrupt.ssd"
    file.write_text(shipped)
    message = refused(cosim, "run", file, "--stop", 0.1)
    assert "XYServoPlant.fmu: not an FMU (not a readable zip archive" in message and str(file) in message


def test_an_ssp_archive_runs_as_the_ssd_beside_its_fmus(loops, tmp_path):
    archive = tmp_path / "two_axis.ssp"
    with zipfile.ZipFile(archive, "w") as z:
        z.writestr("SystemStructure.ssd", (loops / "two_axis.ssd").read_text().replace(
            'source="', 'source="resources/'))
        for name in ("PathInterpolator2D", "ContourCCC2D", "XYServoPlant"):
            z.write(loops / f"{name}.fmu", f"resources/{name}.fmu")
    record = [("plant", "pos.x"), ("controller", "u.y")]
    a = native.run(archive, parameter_set="infinity", stop=0.3, record=record)
    b = native.run(loops / "two_axis.ssd", parameter_set="infinity", stop=0.3, record=record)
    assert all(np.array_equal(a[c], b[c]) for c in a.dtype.names)


def test_bad_options_and_values_are_refused(loops, cosim):
    ssd = loops / "two_axis.ssd"
    for args, words in [
        (["--parameter-set", "spiral"], "no parameter set \"spiral\" (it has circle, line, arc"),
        (["--start", "plant.J.z=1"], "plant (XYServoPlant.fmu) has no variable \"J.z\""),
        (["--start", "table.x=1"], "no unit \"table\" (the loop has controller, plant, interpolator)"),
        (["--start", "plant.pos0.x=far"], "plant.pos0.x is a Real; \"far\" is not one"),
        (["--step", "0"], "communication step must be a positive number"),
        (["--stop", "nan"], "--stop wants a number of seconds"),
        (["--step", "1e-9", "--stop", "100"], "more than 10000000 steps"),
        (["--record", "interpolator.path"], "interpolator.path is a String; only numbers"),
        (["--until", "plant.pos.x"], "the end signal must be a Boolean"),
        (["--scheme", "newton"], "unknown coupling scheme \"newton\""),
    ]:
        ends = [] if "--stop" in args or "--until" in args else ["--stop", "1"]
        assert words in refused(cosim, "run", ssd, *ends, *args), args


def test_a_run_an_fmu_fails_reports_the_unit_the_call_and_the_fmus_message(loops):
    """An FMU that refuses a value fails the run with exit status 1, the FMU's own message
    quoted (its printf format applied)."""
    with pytest.raises(native.RunFailed) as failed:
        native.run(loops / "two_axis.ssd", start={"interpolator": {"path": "spiral"}}, stop=0.1)
    message = str(failed.value)
    # The path is planned on first use, here the initial copy of its first point.
    assert "interpolator: fmi2GetReal returned Error" in message, message
    assert "unknown path 'spiral': expected circle, line" in message, message  # formatted


def test_until_the_path_ends_then_settle(loops):
    """--until interpolator.done ends the run `settle` after the path's end, as the
    campaigns' runs end."""
    rows = native.run(loops / "two_axis.ssd", parameter_set="circle", until="interpolator.done",
                      settle=0.05, max_stop=5.0, record=[("interpolator", "done"), ("plant", "pos.x"),
                                                         ("interpolator", "plannedDuration")])
    first_done = int(np.argmax(rows["interpolator.done"] > 0))
    assert rows["interpolator.done"][first_done - 1] == 0
    assert len(rows) == first_done + 50 + 1
    # The circle takes 2 s at its feed, and the shipped set plans it: more to start and
    # stop within 2000 mm/s2 and 1e5 mm/s3; done at the first sample of the planned end.
    planned = rows["interpolator.plannedDuration"][-1]
    assert 2.03 < planned < 2.1
    assert planned <= rows["time"][first_done] < planned + 1e-3 + 1e-9
    with pytest.raises(native.RunFailed, match="the end signal never came within the longest run, 1"):
        native.run(loops / "two_axis.ssd", parameter_set="circle", until="interpolator.done",
                   max_stop=1.0)


@pytest.mark.parametrize("scheme", ["gauss-seidel", "jacobi"])
def test_a_foreign_fmu_runs_and_one_that_hangs_or_crashes_ends_the_run_clearly(cosim, tmp_path, scheme):
    """A C FMU built here (helpers/faulty_fmu.py): it runs; when its fmi2DoStep spins, the
    call's timeout ends the run as a timeout (exit status 3) within about the timeout; when
    it segfaults, the process dies of SIGSEGV, which the caller sees as a crash."""
    ssd = faulty_fmu.build(tmp_path)
    fine = native.run(ssd, step=0.01, stop=0.5, scheme=scheme,
                      start={"a": {"pos0.x": 1.0, "u.x": 2.0}, "b": {"u.x": -4.0}},
                      record=[("a", "pos.x"), ("b", "pos.x")])
    assert len(fine) == 51
    assert np.allclose(fine["a.pos.x"], 1.0 + 2.0 * fine["time"], rtol=0, atol=1e-12)
    assert np.allclose(fine["b.pos.x"], -4.0 * fine["time"], rtol=0, atol=1e-12)
    ring = ssd.read_text().replace("</ssd:Elements>", """</ssd:Elements><ssd:Connections>
        <ssd:Connection startElement="a" startConnector="pos.x" endElement="b" endConnector="u.x"/>
        </ssd:Connections>""")
    (tmp_path / "ring.ssd").write_text(ring)
    with pytest.raises(native.RunFailed, match=r"a.pos.x -> b.u.x: units differ \(mm onto mm/s\)"):
        native.run(tmp_path / "ring.ssd", stop=0.1)
    began = time.monotonic()
    with pytest.raises(native.Timeout, match="did not return within 0.5 s"):
        native.run(ssd, step=0.01, stop=1.0, scheme=scheme, timeout=0.5,
                   start={"b": {"fault": faulty_fmu.HANG, "fault_time": 0.3}})
    assert time.monotonic() - began < 5.0
    with pytest.raises(native.Crashed, match="killed by SIGSEGV") as crashed:
        native.run(ssd, step=0.01, stop=1.0, scheme=scheme,
                   start={"a": {"fault": faulty_fmu.SEGFAULT, "fault_time": 0.2}})
    assert crashed.value.signal == 11


def test_what_an_fmu_prints_on_stdout_does_not_reach_the_results(cosim, tmp_path):
    """An FMU's printf goes to standard error: the CSV is the quiet run's, and the lines
    are on stderr."""
    ssd = faulty_fmu.build(tmp_path)
    start = {"a": {"pos0.x": 1.0, "u.x": 2.0}}
    quiet = native.run(ssd, step=0.01, stop=0.2, start=start, record=[("a", "pos.x")])
    chatty = {**start, "a": {**start["a"], "fault": faulty_fmu.CHATTY}}
    args = native.arguments(ssd, step=0.01, stop=0.2, start=chatty, record=[("a", "pos.x")])
    done = subprocess.run(args, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "chatty" not in done.stdout and done.stderr.count("chatty FMU at t =") == 20
    loud = native.run(ssd, step=0.01, stop=0.2, start=chatty, record=[("a", "pos.x")])
    assert np.array_equal(loud["a.pos.x"], quiet["a.pos.x"])


def batch_answers(cosim, ssd, runs, *options):
    """(first line, [(result line, rows or None)]) of `contour-cosim batch` on the run lines
    `runs` ([(id, [[unit, variable, text], ...])])."""
    lines = "".join(json.dumps({"run": i, "start": s}) + "\n" for i, s in runs)
    done = subprocess.run([str(cosim), "batch", str(ssd), *map(str, options)], input=lines.encode(),
                          capture_output=True)
    assert done.returncode == 0, done.stderr
    out = done.stdout
    first, out = out.split(b"\n", 1)
    header = json.loads(first)
    width, trajectory = len(header["columns"]), header.get("trajectory", True)
    answers = []
    while out:
        line, out = out.split(b"\n", 1)
        head = json.loads(line)
        table = None
        if head["status"] == "ok" and trajectory:
            size = (head["steps"] + 1) * width * 8
            table, out = np.frombuffer(out[:size], dtype="<f8").reshape(-1, width), out[size:]
        answers.append((head, table))
    return header, answers


TWO_AXIS_METRICS = ["contour_error.max", "contour_error.mean", "estimated_contour_error.max",
                    "estimated_contour_error.mean"]


def test_a_batch_measures_its_runs_as_the_campaigns_python_does(loops, cosim):
    """`batch --metrics` (issue 43, item 1): on the five built-in paths, with and without the
    CCC, the metrics of each run against the campaigns' Python metrics of the same run's
    trajectory: the true contour error within metrics.ENGINE_AGREEMENT (the Python one
    measures to a polygon), the controller's estimate to the bit; the run itself is the one
    a batch without metrics makes, bit for bit; without --trajectory only the result lines
    come back."""
    from contour_fmu.campaign.metrics import agreement, compute

    ssd = loops / "two_axis.ssd"
    runs = [(f"{path}-{ccc}", [["interpolator", "path", path], ["interpolator", "feed", "60"],
                               ["controller", "ccc.enable", ccc]])
            for path in ("circle", "line", "arc", "infinity", "trident") for ccc in ("false", "true")]
    record = ",".join(f"{u}.{n}" for u, n in LOOPS["two_axis"].recorded)
    common = ("--stop", "1.2", "--record", record)
    plain_header, plain = batch_answers(cosim, ssd, runs, *common)
    header, measured = batch_answers(cosim, ssd, runs, *common, "--metrics", ",".join(TWO_AXIS_METRICS),
                                     "--trajectory")
    assert header["columns"] == plain_header["columns"] and header["trajectory"] is True
    assert header["metrics"] == TWO_AXIS_METRICS
    variables = {"path": type("Start", (), {"start": "circle"})()}
    for (run, start), (head, table), (_, plain_table) in zip(runs, measured, plain):
        assert head["status"] == "ok", head
        assert np.array_equal(table, plain_table), run
        trace = {c: table[1:, i] if c.startswith("controller.") else table[:-1, i]
                 for i, c in enumerate(header["columns"])}
        expected = compute("two_axis", TWO_AXIS_METRICS, trace, {"path": start[0][2]}, variables)
        for metric, value in expected.items():
            got = head["metrics"][metric]
            assert abs(got - value) <= agreement(metric), (run, metric, got, value)
        if "circle" in run:  # the closed form: the exact distance, to rounding
            exact = np.abs(np.hypot(trace["plant.pos.x"] + 10.0, trace["plant.pos.y"]) - 10.0)
            assert head["metrics"]["contour_error.max"] == pytest.approx(exact.max(), abs=1e-13)
    assert measured[6][0]["metrics"]["contour_error.max"] > 0.01  # infinity without CCC: real errors
    header, rows_only = batch_answers(cosim, ssd, runs[:2], "--stop", "1.2", "--metrics", "contour_error.max")
    assert header["trajectory"] is False and header["columns"] == ["plant.pos.x", "plant.pos.y"]
    assert [table for _, table in rows_only] == [None, None]
    assert [head["metrics"]["contour_error.max"] for head, _ in rows_only] == [
        head["metrics"]["contour_error.max"] for head, _ in measured[:2]]


def test_a_five_axis_batch_measures_tip_and_orientation_errors(loops, cosim):
    """The five-axis metrics against the campaigns' Python ones (five_axis_truth) on the
    helix and the figure-eight, with the machine's pivots moved."""
    from contour_fmu.campaign.metrics import agreement, compute

    names = ["tip_error.max", "tip_error.mean", "orientation_error.max", "orientation_error.mean",
             "estimated_tip_error.max", "estimated_orientation_error.mean"]
    pivots = {"pivot.A.y": 2.0, "pivot.A.z": -40.0, "pivot.C.x": 1.5, "pivot.C.y": -0.5}
    starts = [["interpolator", k, repr(v)] for k, v in pivots.items()]
    runs = [(path, [["interpolator", "path", path], *starts]) for path in ("tilted_helix", "figure_eight")]
    header, measured = batch_answers(cosim, loops / "five_axis.ssd", runs, "--stop", "0.8", "--metrics",
                                     ",".join(names), "--trajectory")
    variables = {name: type("Start", (), {"start": 0.0})() for name in pivots}
    for (run, _), (head, table) in zip(runs, measured):
        assert head["status"] == "ok", head
        trace = {c: table[1:, i] if c.startswith("controller.") else table[:-1, i]
                 for i, c in enumerate(header["columns"])}
        expected = compute("five_axis", names, trace, pivots, variables)
        for metric, value in expected.items():
            assert abs(head["metrics"][metric] - value) <= agreement(metric), (run, metric)
        assert head["metrics"]["tip_error.max"] > 1e-3  # mm: a real lag


def test_batch_metrics_refused_or_unmeasurable_say_why(loops, cosim):
    ssd = loops / "two_axis.ssd"
    for args, words in [
        (["batch", "--metrics", "contour_error.median"], "unknown metric \"contour_error.median\""),
        (["batch", "--metrics", "contour_error.max,contour_error.max"], "named twice"),
        (["batch", "--metrics", "tip_error.max"],
         "--metrics tip_error.max, a metric of the five-axis loop: interpolator (PathInterpolator2D.fmu) "
         "has no variable \"ref.X\""),
        (["run", "--metrics", "contour_error.max"], "--metrics is an option of batch"),
        (["batch", "--trajectory"], "--trajectory goes with --metrics"),
    ]:
        assert words in refused(cosim, args[0], ssd, "--stop", "0.1", *args[1:]), args
    # The SI build measures in m; the metrics are in mm.
    si = repo.fmu_dir().parent / "fmu-si" / "two_axis.ssd"
    assert "plant.pos.x is in m; the metrics are in mm and rad" in refused(
        cosim, "batch", si, "--stop", "0.1", "--metrics", "contour_error.max")
    # A path the runner has no exact geometry for: an error row, which names the way out.
    program = repo.root() / "tests" / "data" / "cam" / "cambam" / "enclosure-labels.nc"
    _, answers = batch_answers(cosim, ssd, [(0, [["interpolator", "path", str(program)]]),
                                            (1, [["interpolator", "path", "circle"]])],
                               "--stop", "0.2", "--metrics", "contour_error.max,estimated_contour_error.max")
    (bad, _), (good, _) = answers
    assert bad["status"] == "error" and "use estimated_contour_error.* there" in bad["message"], bad
    assert "needs a built-in path" in bad["message"] and "metrics" not in bad
    assert good["status"] == "ok" and good["metrics"]["contour_error.max"] > 0
