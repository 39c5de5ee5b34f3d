"""The console script `contour-fmu` (installed with the package): every command's --help,
and short runs that give what `python -m` of the same module gives."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pyarrow.parquet as pq
import pytest

SCRIPT = Path(sys.executable).with_name("contour-fmu")

CAMPAIGN = """
name = "two runs"
loop = "two_axis"
step = 0.001
stop = 0.05
metrics = ["contour_error.max", "estimated_contour_error.max"]

[fmus]
directory = "{fmus}"

[[paths]]
path = "circle"
feed = 31.41592653589793

[sweep]
method = "grid"

[sweep.parameters]
"plant.x.J" = {{ factors = [0.9, 1.1] }}
"""


def run(*args, cwd=None):
    command = [str(SCRIPT if SCRIPT.exists() else shutil.which("contour-fmu")), *map(str, args)]
    return subprocess.run(command, capture_output=True, text=True, timeout=300, cwd=cwd,
                          env={**os.environ, "MPLBACKEND": "Agg"})


def module(name, *args, cwd=None):
    return subprocess.run([sys.executable, "-m", name, *map(str, args)], capture_output=True,
                          text=True, timeout=300, cwd=cwd)


@pytest.mark.parametrize("args, words", [
    ([], ["demo", "campaign", "libcosim", "ecos"]),
    (["demo"], ["usage: contour-fmu demo", "--fmu-dir", "--tune", "--params", "--ccc-tune"]),
    (["campaign"], ["usage: contour-fmu campaign", "run", "replay"]),
    (["campaign", "run"], ["usage: contour-fmu campaign run", "--out", "--scheduler", "--serial",
                           "--workers", "--resume", "--fmu-dir", "--no-progress"]),
    (["campaign", "replay"], ["usage: contour-fmu campaign replay", "--run", "--out", "--fmu-dir"]),
    (["libcosim"], ["usage: contour-fmu libcosim", "--loop", "fmu_dir", "step", "steps"]),
    (["ecos"], ["usage: contour-fmu ecos", "--loop", "fmu_dir", "step", "steps"]),
], ids=["contour-fmu", "demo", "campaign", "campaign run", "campaign replay", "libcosim", "ecos"])
def test_every_command_answers_help(tmp_path, args, words):
    done = run(*args, "--help", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    for word in words:
        assert word in done.stdout, (word, done.stdout)


def test_an_unknown_command_is_refused():
    done = run("simulate")
    assert done.returncode == 2 and "invalid choice: 'simulate'" in done.stderr


def test_the_demo_refuses_missing_fmus_before_running(tmp_path):
    done = run("demo", "--fmu-dir", tmp_path, "--out", tmp_path / "out", cwd=tmp_path)
    assert done.returncode == 2 and "fmu-build" in done.stderr, done.stderr
    assert done.stderr.startswith("usage: contour-fmu demo")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("engine, name, step", [
    ("libcosim", "contour_fmu.engines.libcosim", "1000000"),
    ("ecos", "contour_fmu.engines.ecos", "0.001"),
])
def test_an_engine_run_is_the_modules(fmus, engine, name, step):
    args = ("--loop", "two_axis", fmus, step, 40, "plant.pos0.x=0.0", "plant.pos0.y=0.0")
    ours, theirs = run(engine, *args), module(name, *args)
    assert ours.returncode == 0 and theirs.returncode == 0, ours.stderr + theirs.stderr
    result = json.loads(ours.stdout.strip().splitlines()[-1])
    assert result == json.loads(theirs.stdout.strip().splitlines()[-1])
    assert len(result["series"]["plant.pos.x"]) == 40


def test_a_campaign_run_and_replay(fmus, tmp_path):
    campaign = tmp_path / "campaign.toml"
    campaign.write_text(CAMPAIGN.format(fmus=fmus))
    done = run("campaign", "run", campaign, "--out", tmp_path / "out", "--serial", "--no-progress")
    assert done.returncode == 0, done.stderr
    assert "2 of 2 runs recorded (2 ok)" in done.stdout
    table = pq.read_table(tmp_path / "out" / "results.parquet").to_pydict()
    assert table["status"] == ["ok", "ok"]

    done = run("campaign", "replay", campaign, "--run", 1, "--out", tmp_path / "ours")
    assert done.returncode == 0, done.stderr
    assert f"contour_error.max = {table['contour_error.max'][1]!r}" in done.stdout
    done = module("contour_fmu.campaign", "replay", campaign, "--run", 1, "--out", tmp_path / "theirs")
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "ours" / "run1.csv").read_text() == (tmp_path / "theirs" / "run1.csv").read_text()
