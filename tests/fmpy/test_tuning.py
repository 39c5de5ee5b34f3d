"""ccc-tune: bad input, reproducibility across thread counts, and tuned factors applied
to the ContourCCC2D FMU in the fmpy closed loop."""

import json
import os
import subprocess

import numpy as np
import pytest

from contour_fmu import repo
from contour_fmu.demo import paper as paper_demo
from contour_fmu.tuned import start_values
from helpers.checkout import REPO, target_dir

PAPER = {"fuzzy.ke": 1.0, "fuzzy.kde": 1.2, "fuzzy.kp": 87.0, "fuzzy.ki": 8.5, "fuzzy.kd": 4.0}


@pytest.fixture(scope="session")
def ccc_tune():
    subprocess.run(["cargo", "build", "--quiet", "--release", "-p", repo.TUNER_PACKAGE, "--bin", "ccc-tune"],
                   cwd=REPO, check=True)
    return str(target_dir() / "release" / "ccc-tune")


def tune(program, out, *args):
    return subprocess.run([program, "--out", str(out), *map(str, args)], capture_output=True, text=True)


@pytest.mark.parametrize("args, words", [
    (["--lower", "0,0,0,0"], "--lower needs 5 comma-separated values"),
    (["--lower", "-1,0,0,0,0"], "the fuzzy factors cannot be negative"),
    (["--lower", "5,0,0,0,0", "--upper", "1,10,1000,3000,50"], "bounds of dimension 0 must be finite with lower < upper"),
    (["--upper", "1,nan,1,1,1"], "bounds of dimension 1"),
    (["--swarm", "0"], "the swarm needs at least one particle"),
    (["--iters", "0"], "at least one iteration"),
    (["--swarm", "-3"], "--swarm '-3'"),
    (["--path", "spiral"], "unknown path 'spiral'"),
    (["--path", "/nonexistent/path.json"], "/nonexistent/path.json"),
    (["--path", "/"], "--path"),
    (["--algorithm", "genetic"], "unknown algorithm 'genetic'"),
    (["--fitness", "median"], "unknown fitness 'median'"),
    (["--plant", "granite"], "unknown plant 'granite'"),
    (["--threads", "0"], "--threads must be at least 1"),
    (["--bogus", "1"], "unknown option '--bogus'"),
    (["--loop", "/nonexistent/loop.ssd"], "--loop: /nonexistent/loop.ssd: cannot read it"),
    (["--plant", "/nonexistent/Plant.fmu"], "/nonexistent/Plant.fmu: no such FMU"),
    (["--parameter-set", "circle"], "--parameter-set and --start need a loop of FMUs"),
    (["--start", "controller.estimator=4"], "--parameter-set and --start need a loop of FMUs"),
])
def test_bad_input_is_refused_and_nothing_is_written(ccc_tune, tmp_path, args, words):
    out = tmp_path / "tuned.json"
    done = tune(ccc_tune, out, "--swarm", 2, "--iters", 1, *args)
    assert done.returncode != 0
    assert words in done.stderr, done.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("args, words", [
    (["--parameter-set", "granite"], "--parameter-set: "),
    (["--start", "controller.estimator"], "is not UNIT.VARIABLE=VALUE"),
    (["--start", "estimator=4"], "is not UNIT.VARIABLE=VALUE"),
    (["--start", "controller.nonesuch=4"], "nonesuch"),
    (["--start", "interpolator.accel=fast"], "interpolator.accel is a Real"),
    (["--settle", "-1"], "--settle must be zero or more seconds"),
    (["--settle", "nan"], "--settle must be zero or more seconds"),
    # A plan the interpolator refuses fails the planned run before any candidate.
    (["--start", "interpolator.accel=2000", "--start", "interpolator.jerk=-1"], "the planned run"),
])
def test_bad_loop_settings_are_refused_and_nothing_is_written(ccc_tune, fmu_dir, tmp_path, args,
                                                              words):
    out = tmp_path / "tuned.json"
    done = tune(ccc_tune, out, "--swarm", 2, "--iters", 1, "--loop", fmu_dir / "two_axis.ssd",
                *args)
    assert done.returncode != 0
    assert words in done.stderr, done.stderr
    assert list(tmp_path.iterdir()) == []


def test_unwritable_output_leaves_nothing_behind(ccc_tune, tmp_path):
    out = tmp_path / "missing-folder" / "tuned.json"
    done = tune(ccc_tune, out, "--swarm", 2, "--iters", 1)
    assert done.returncode != 0 and "cannot write" in done.stderr
    assert list(tmp_path.iterdir()) == []


def test_same_seed_gives_the_same_file_on_one_and_two_threads(ccc_tune, tmp_path):
    files = []
    for threads in (1, 2):
        out = tmp_path / f"tuned_{threads}.json"
        done = tune(ccc_tune, out, "--path", "infinity", "--swarm", 8, "--iters", 4, "--seed", 42, "--threads", threads)
        assert done.returncode == 0, done.stderr
        files.append(out.read_bytes())
    assert files[0] == files[1]
    other = tmp_path / "tuned_other.json"
    assert tune(ccc_tune, other, "--path", "infinity", "--swarm", 8, "--iters", 4, "--seed", 43).returncode == 0
    assert other.read_bytes() != files[0]
    document = json.loads(files[0])
    assert len(document["history_mm"]) == 4
    assert document["settings"]["seed"] == 42 and document["settings"]["swarm"] == 8


@pytest.mark.parametrize("path, feed", paper_demo.PATHS)
def test_tuned_factors_beat_the_papers_through_the_fmu(ccc_tune, fmu_dir, tmp_path, path, feed):
    out = tmp_path / "tuned.json"
    done = tune(ccc_tune, out, "--path", path, "--feed", repr(feed), "--fitness", "max",
                "--swarm", 20, "--iters", 25, "--seed", 3)
    assert done.returncode == 0, done.stderr
    document = json.loads(out.read_text())
    _, _, paper = paper_demo.run_path(fmu_dir, path, feed, PAPER)
    _, _, tuned = paper_demo.run_path(fmu_dir, path, feed, start_values(out))
    # The FMU closed loop scores the factors exactly as the in-process objective did.
    assert abs(tuned.max() - document["fitness_mm"]) < 1e-6
    # 500 evaluations (a tenth of the paper's budget): 23 % to 73 % lower on these paths.
    assert tuned.max() < 0.85 * paper.max(), (tuned.max(), paper.max())
    history = document["history_mm"]
    assert all(later <= earlier for earlier, later in zip(history, history[1:]))


@pytest.mark.parametrize("spelling", ["circle", "Circle", " CIRCLE "])
def test_the_circle_tunes_at_the_papers_feed_however_it_is_spelled(ccc_tune, tmp_path, spelling):
    out = tmp_path / "tuned.json"
    done = tune(ccc_tune, out, "--path", spelling, "--swarm", 1, "--iters", 1)
    assert done.returncode == 0, done.stderr
    # The paper's circle: 10 mm radius, one turn in 2 s.
    assert json.loads(out.read_text())["settings"]["feed_mm_per_s"] == 10 * np.pi


def test_tuning_through_the_fmus_finds_the_in_process_optimum_bit_for_bit(ccc_tune, fmu_dir, tmp_path):
    """ccc-tune --loop (every candidate through the shipped two-axis SSP file and its FMUs
    in contour-cosim) and --plant (the same loop, the plant FMU named): the same history,
    factors and fitness as the in-process tuner with the same seed, because the FMU loop
    reproduces the in-process one bit for bit."""
    budget = ["--path", "trident", "--swarm", 6, "--iters", 3, "--seed", 5, "--threads", 2]
    results = {}
    for name, extra in (("in_process", []), ("loop", ["--loop", fmu_dir / "two_axis.ssd"]),
                        ("plant", ["--plant", fmu_dir / "XYServoPlant.fmu"])):
        out = tmp_path / f"{name}.json"
        done = tune(ccc_tune, out, *budget, *extra)
        assert done.returncode == 0, done.stderr
        results[name] = json.loads(out.read_text())
    for name in ("loop", "plant"):
        for key in ("factors", "fitness_mm", "history_mm"):
            assert results[name][key] == results["in_process"][key], (name, key)
        assert results[name]["settings"]["loop"] == str(fmu_dir / "two_axis.ssd")
    assert "loop" not in results["in_process"]["settings"]
    assert 0 < results["loop"]["fitness_mm"] < 0.01  # mm: a few µm on the trident


def test_the_ccc_tunes_on_top_of_feed_forward_on_a_planned_part_through_the_fmus(ccc_tune, fmu_dir,
                                                                                 tmp_path):
    """--parameter-set: the shipped loop's feed-forward and plan (its `circle` set), the
    corners part with exact stops (tests/fmpy/test_feed_forward_corners.py) planned with a
    jerk limit. A run lasts until the planned reference ends plus --settle, and the fitness
    the tuner reports for its factors is the largest distance, in closed form, from the
    positions of the same loop run in fmpy with those factors to the programmed lines and
    arcs."""
    from test_feed_forward_corners import CORNERS
    from contour_fmu.checks.gcode import distance, read_program
    from contour_fmu.demo.part import plan
    from contour_fmu.engines.master import closed_loop
    from contour_fmu.loops.wiring import LOOPS

    program = tmp_path / "corners.ngc"
    program.write_text(CORNERS)
    out = tmp_path / "tuned.json"
    done = tune(ccc_tune, out, "--loop", fmu_dir / "two_axis.ssd", "--parameter-set", "circle",
                "--path", program, "--start", "interpolator.jerk=5e4",
                "--start", "controller.estimator=4", "--fitness", "max",
                "--swarm", 12, "--iters", 6, "--seed", 2)
    assert done.returncode == 0, done.stderr
    document = json.loads(out.read_text())
    settings = document["settings"]
    assert settings["parameter_set"] == "circle" and settings["settle_s"] == 0.25
    interpolator = {"path": str(program), "feed": 50.0, "accel": 2000.0, "jerk": 5e4}
    duration, _ = plan(fmu_dir, interpolator)
    assert abs(settings["run_s"] - (duration + 0.25)) <= 2e-3, (settings["run_s"], duration)
    steps = round(settings["run_s"] / 1e-3)

    def largest_error(factors):
        controller = {**LOOPS["two_axis"].feed_forward, "estimator": 4, "path": str(program),
                      **factors}
        before, _ = closed_loop(fmu_dir, stop=settings["run_s"], interpolator=interpolator,
                                controller=controller)
        positions = np.column_stack([before["plant.pos.x"], before["plant.pos.y"]])[:steps]
        return distance(read_program(CORNERS), positions)[0].max()

    tuned = largest_error(start_values(out))
    assert abs(tuned - document["fitness_mm"]) < 1e-9, (tuned, document["fitness_mm"])
    # The shipped loop's own factors (the paper's) leave 0.381 um at the exact stops; the
    # swarm's best is no worse.
    assert tuned <= largest_error(PAPER) < 0.4e-3


def test_a_candidate_whose_plant_hangs_is_ended_recorded_and_the_tuning_goes_on(ccc_tune, tmp_path):
    """A C plant FMU that spins forever in every third run of its process: each hung
    candidate's worker ends after --timeout, the candidate scores as a run that cannot
    start (twice the divergence penalty, above any run), the JSON lists it with the
    worker's message, and the tuning goes on with a new worker to a finite best."""
    from helpers import faulty_fmu

    faulty_fmu.build(tmp_path)
    out = tmp_path / "tuned.json"
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    args = ["--plant", tmp_path / "Faulty.fmu", "--path", "circle", "--start", "plant.fault=5",
            "--start", "plant.fault_time=0.5", "--timeout", 0.5, "--swarm", 4, "--iters", 3,
            "--seed", 7, "--threads", 1, "--out", out]
    done = subprocess.run([ccc_tune, *map(str, args)], capture_output=True, text=True,
                          env={**os.environ, "TMPDIR": str(scratch)})
    assert done.returncode == 0, done.stderr
    # The hung workers ended at once, without cleaning up; their folders went with them.
    assert list(scratch.iterdir()) == []
    document = json.loads(out.read_text())
    failed = document["failed_candidates"]
    # 12 candidates, one worker at a time: runs 3, 6, 9 and 12 of a worker hang, and each
    # hang starts a new worker: candidates 3, 6, 9 and 12 hang.
    assert len(failed) == 4, failed
    for f in failed:
        assert f["reason"] == "timeout: an FMU call did not return within 0.5 s", f
        assert len(f["factors"]) == 5
    assert document["settings"]["timeout_s"] == 0.5
    assert 0 < document["fitness_mm"] < 1.0  # mm: a real run's, not the penalty
    assert document["history_mm"][-1] == document["fitness_mm"]


@pytest.mark.parametrize("timeout", ["0", "-1", "nan", "inf"])
def test_a_timeout_that_is_no_time_is_refused(ccc_tune, fmu_dir, tmp_path, timeout):
    out = tmp_path / "tuned.json"
    done = tune(ccc_tune, out, "--loop", fmu_dir / "two_axis.ssd", "--timeout", timeout,
                "--swarm", 2, "--iters", 1)
    assert done.returncode != 0
    assert "--timeout must be a positive number of seconds" in done.stderr, done.stderr
    assert list(tmp_path.iterdir()) == []


def test_a_plant_that_prints_cannot_corrupt_the_answers_and_one_that_crashes_fails_the_run(
        ccc_tune, tmp_path):
    """The workers answer on a standard output set aside before any FMU loads: a C plant
    that prints a line on standard output at every step tunes as a quiet one would (the
    same factors, fitness and history: its ideal axes do not depend on the printing). A
    plant that dies of SIGSEGV in every run fails every candidate: ccc-tune then writes
    nothing and says how the first one ended."""
    from helpers import faulty_fmu

    faulty_fmu.build(tmp_path)
    plant = ["--plant", tmp_path / "Faulty.fmu", "--path", "circle", "--swarm", 3, "--iters", 2,
             "--seed", 4, "--threads", 2]
    documents = {}
    for name, fault in (("quiet", faulty_fmu.NONE), ("chatty", faulty_fmu.CHATTY)):
        out = tmp_path / f"{name}.json"
        done = tune(ccc_tune, out, *plant, "--start", f"plant.fault={fault}",
                    "--start", "plant.fault_time=0.1")
        assert done.returncode == 0, done.stderr
        documents[name] = json.loads(out.read_text())
    for key in ("factors", "fitness_mm", "history_mm", "failed_candidates"):
        assert documents["chatty"][key] == documents["quiet"][key], key
    assert documents["quiet"]["failed_candidates"] == []
    out = tmp_path / "crashed.json"
    done = tune(ccc_tune, out, *plant, "--start", f"plant.fault={faulty_fmu.SEGFAULT}",
                "--start", "plant.fault_time=0.1")
    assert done.returncode != 0
    assert "every candidate failed; the first: the worker ended" in done.stderr, done.stderr
    assert "SIGSEGV" in done.stderr, done.stderr
    assert not out.exists()
