"""The contour_fmu package (python/) as installed: the tests import this checkout's code,
its pins (core and extras) agree with requirements/, it finds the checkout from anywhere,
and the demo's command line answers without a run."""

import importlib.metadata
import json
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

import contour_fmu
from contour_fmu import repo
from contour_fmu.extras import EXTRAS, INCLUDES
from helpers.checkout import REPO

PIN = re.compile(r"^([A-Za-z0-9._-]+)==([^\s#;]+)")


def canonical(name):
    return re.sub(r"[-_.]+", "-", name).lower()


def pins(filename):
    """{name: version} of a requirements file, following -r."""
    found = {}
    for line in (REPO / "requirements" / filename).read_text().splitlines():
        line = line.split(" #", 1)[0].strip()
        if not line or line.startswith("#"):
            continue
        if line.startswith("-r "):
            found.update(pins(line[3:].strip()))
            continue
        match = PIN.match(line)
        assert match, f"requirements/{filename}: not pinned with ==: {line!r}"
        found[canonical(match[1])] = match[2]
    return found


def pyproject():
    return tomllib.loads((REPO / "python" / "pyproject.toml").read_text())["project"]


SELF = re.compile(r"^contour-fmu\[([a-z,]+)\]$")  # an extra that includes others


def own(requirements):
    """({name: version}, [included extras]) of a list of pyproject requirements."""
    pinned, included = {}, []
    for requirement in requirements:
        if inner := SELF.match(requirement):
            included += inner[1].split(",")
            continue
        match = PIN.match(requirement)
        assert match, f"python/pyproject.toml: not pinned with ==: {requirement!r}"
        pinned[canonical(match[1])] = match[2]
    return pinned, included


def declared(extras):
    """{name: version} of the core and `extras` with the extras they include."""
    project = pyproject()
    found = own(project["dependencies"])[0]
    for extra in extras:
        pinned, included = own(project["optional-dependencies"][extra])
        found.update(pinned)
        found.update(declared(included))
    return found


def run_extras():
    """The extras of the run set: all but test."""
    return sorted(set(pyproject()["optional-dependencies"]) - {"test"})


def direct(filename):
    """{name: version} of a requirements file's own pins before its transitive ones."""
    text = (REPO / "requirements" / filename).read_text().split("# Transitive dependencies.")[0]
    return {canonical(m[1]): m[2] for m in map(PIN.match, text.splitlines()) if m}


def test_the_tests_import_this_checkouts_package():
    assert Path(contour_fmu.__file__).resolve().parent == REPO / "python" / "contour_fmu"
    assert importlib.metadata.version("contour-fmu") == pyproject()["version"] == contour_fmu.__version__


@pytest.mark.parametrize("filename, extras", [("run.txt", run_extras()), ("test.txt", ["test"])])
def test_pyproject_pins_are_the_requirements_pins(filename, extras):
    locked = pins(filename)
    for name, version in declared(extras).items():
        assert locked.get(name) == version, f"{name}=={version}"


def test_the_requirements_direct_pins_are_the_core_and_the_extras():
    assert direct("run.txt") == declared(run_extras())
    assert direct("test.txt") == own(pyproject()["optional-dependencies"]["test"])[0]
    # The test extra brings every other one: -e './python[test]' installs the whole package.
    assert sorted(own(pyproject()["optional-dependencies"]["test"])[1]) == run_extras()


def test_the_extras_of_contour_fmu_extras_are_pyprojects():
    optional = pyproject()["optional-dependencies"]
    assert sorted(EXTRAS) == run_extras()
    for extra, modules in EXTRAS.items():
        pinned, included = own(optional[extra])
        assert sorted(pinned) == sorted(modules), extra  # distributions named as their modules
        assert included == list(INCLUDES.get(extra, ())), extra
    assert pyproject()["scripts"] == {"contour-fmu": "contour_fmu.cli:main"}


def test_the_venv_holds_the_pinned_versions():
    for name, version in pins("test.txt").items():
        assert importlib.metadata.version(name) == version, name


def test_the_checkout_is_found_from_a_subfolder_from_outside_and_by_name(tmp_path, monkeypatch):
    monkeypatch.delenv(repo.ENV, raising=False)
    assert repo.find_root(REPO / "tests" / "fmpy") == REPO
    # Outside any checkout: the one the package is installed from (editable).
    assert repo.find_root(tmp_path) == REPO
    monkeypatch.setenv(repo.ENV, str(REPO))
    assert repo.find_root(tmp_path) == REPO
    monkeypatch.setenv(repo.ENV, str(tmp_path))
    with pytest.raises(repo.RepoNotFound, match=repo.ENV):
        repo.find_root()


def test_default_paths_follow_cargo_target_dir(tmp_path, monkeypatch):
    monkeypatch.delenv(repo.ENV, raising=False)
    monkeypatch.chdir(REPO)
    monkeypatch.delenv("CARGO_TARGET_DIR", raising=False)
    assert repo.fmu_dir() == REPO / "target" / "fmu"
    assert repo.ccc_tune() == REPO / "target" / "release" / "ccc-tune"
    assert repo.out_dir() == REPO / "out"
    monkeypatch.setenv("CARGO_TARGET_DIR", str(tmp_path))
    assert repo.fmu_dir() == tmp_path / "fmu"


def test_the_package_constants_name_the_crates_that_hold_the_targets():
    # What cargo says, not what we wrote down: a renamed crate or moved target fails here.
    done = subprocess.run(["cargo", "metadata", "--no-deps", "--format-version", "1"],
                          cwd=REPO, capture_output=True, text=True, check=True)
    targets = {(p["name"], t["name"]) for p in json.loads(done.stdout)["packages"]
               for t in p["targets"]}
    for target in ("ccc-tune", "pso_benchmarks", "pso_claim"):
        assert (repo.TUNER_PACKAGE, target) in targets
    for target in ("nurbs_dump", "fuzzy_dump", "closed_loop_dump"):
        assert (repo.LIBRARY_PACKAGE, target) in targets


def demo(*args, cwd):
    return subprocess.run([sys.executable, "-m", "contour_fmu.demo", *args], cwd=cwd,
                          capture_output=True, text=True, timeout=120)


def test_demo_help_runs_outside_the_checkout(tmp_path):
    done = demo("--help", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    for option in ("--fmu-dir", "--out", "--tune", "--params", "--ccc-tune"):
        assert option in done.stdout


def test_demo_refuses_missing_fmus_and_tuner_before_running(fmu_dir, tmp_path):
    out = tmp_path / "out"
    done = demo("--fmu-dir", str(tmp_path), "--out", str(out), cwd=tmp_path)
    assert done.returncode == 2 and "fmu-build" in done.stderr, done.stderr
    done = demo("--fmu-dir", str(fmu_dir), "--out", str(out), "--tune",
                "--ccc-tune", str(tmp_path / "ccc-tune"), cwd=REPO)
    assert done.returncode == 2 and "-p contour-tune --bin ccc-tune" in done.stderr, done.stderr
    assert not out.exists()
