"""The core of contour_fmu works without any extra installed, and a module of a missing
extra names the extra to install: a subprocess whose imports of the extras' modules fail
as if they were not installed."""

import json
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from contour_fmu.extras import EXTRAS, MissingExtra, modules, needs, require
from contour_fmu.engines.master import closed_loop

BLOCKED = modules(*EXTRAS)

# Makes every import of a blocked module fail as a missing one does; then runs the body.
PRELUDE = """
import importlib.abc, json, sys
BLOCKED = set(sys.argv[1].split(","))

class NotInstalled(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path, target=None):
        if name.split(".")[0] in BLOCKED:
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return None

sys.meta_path.insert(0, NotInstalled())
"""


def without_extras(body, *args):
    """Runs `body` with the extras' modules blocked; returns its last line of output as JSON."""
    done = subprocess.run([sys.executable, "-c", PRELUDE + textwrap.dedent(body), ",".join(BLOCKED),
                           *map(str, args)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_the_blocked_modules_are_every_extras_dependency():
    assert set(BLOCKED) == {"dask", "distributed", "pyarrow", "tqdm", "libcosimpy", "ecospy",
                            "matplotlib", "geomdl", "scipy"}


def test_the_core_runs_the_closed_loop_without_any_extra(fmu_dir):
    result = without_extras("""
        import contour_fmu, contour_fmu.loops.ssp, contour_fmu.loops.wiring, contour_fmu.engines.stepping
        import contour_fmu.engines.fmu_log, contour_fmu.engines.native, contour_fmu.tuned, contour_fmu.repo
        import contour_fmu.output_files, contour_fmu.checks.five_axis_truth, contour_fmu.checks.gcode
        import contour_fmu.engines.container_build, contour_fmu.cli
        import contour_fmu.campaign, contour_fmu.campaign.spec, contour_fmu.campaign.runner
        from pathlib import Path
        from contour_fmu.master import closed_loop  # the documented entry point
        before, after = closed_loop(Path(sys.argv[2]), stop=0.05)
        loaded = sorted({m.split(".")[0] for m in sys.modules} & BLOCKED)
        print(json.dumps({"loaded": loaded, "pos.x": list(before["plant.pos.x"]),
                          "u.x": list(after["controller.u.x"])}))
    """, fmu_dir)
    assert result["loaded"] == []
    before, after = closed_loop(fmu_dir, stop=0.05)
    assert np.array_equal(result["pos.x"], before["plant.pos.x"])
    assert np.array_equal(result["u.x"], after["controller.u.x"])


def test_a_module_of_a_missing_extra_names_the_extra():
    result = without_extras("""
        import importlib
        from contour_fmu.extras import MissingExtra
        found = {}
        for module in ["contour_fmu.checks.reference_paths", "contour_fmu.demo.__main__",
                       "contour_fmu.engines.libcosim", "contour_fmu.engines.ecos",
                       "contour_fmu.campaign.store", "contour_fmu.campaign.execute"]:
            try:
                importlib.import_module(module)
                found[module] = None
            except MissingExtra as e:
                found[module] = str(e)
        from contour_fmu.campaign import report
        try:
            report.sensitivity([1.0, 2.0, 3.0], [1.0, 2.0, 4.0])
        except MissingExtra as e:
            found["report.sensitivity"] = str(e)
        print(json.dumps(found))
    """)
    extras = {"contour_fmu.checks.reference_paths": "reference",
              "contour_fmu.demo.__main__": "plots,reference",
              "contour_fmu.engines.libcosim": "engines", "contour_fmu.engines.ecos": "engines",
              "contour_fmu.campaign.store": "campaign", "contour_fmu.campaign.execute": "campaign",
              "report.sensitivity": "campaign"}
    for module, extra in extras.items():
        assert result[module] is not None, module
        assert f"pip install 'contour-fmu[{extra}]'" in result[module], (module, result[module])
    assert result["contour_fmu.campaign.store"].startswith("no module named 'pyarrow'")


@pytest.mark.parametrize("argv, extra", [
    (["campaign", "run", "campaign.toml", "--out", "out"], "campaign"),
    (["campaign", "replay", "campaign.toml", "--run", "0"], "campaign"),
    (["demo"], "plots,reference"),
    (["libcosim", "fmus", "1000000", "10"], "engines"),
    (["ecos", "fmus", "0.001", "10"], "engines"),
])
def test_the_command_line_names_the_missing_extra(argv, extra):
    result = without_extras("""
        import contextlib, io
        from contour_fmu import cli
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            status = cli.main(json.loads(sys.argv[2]))
        print(json.dumps({"status": status, "stderr": err.getvalue()}))
    """, json.dumps(argv))
    assert result["status"] == 2
    assert result["stderr"].count("\n") == 1, result["stderr"]
    assert f"pip install 'contour-fmu[{extra}]'" in result["stderr"]


def test_the_command_line_helps_without_any_extra():
    result = without_extras("""
        import contextlib, io
        from contour_fmu import cli
        shown = {}
        for argv in (["--help"], ["campaign", "--help"], ["campaign", "run", "--help"]):
            out = io.StringIO()
            with contextlib.redirect_stdout(out):
                try:
                    cli.main(argv)
                except SystemExit as e:
                    shown[" ".join(argv)] = (e.code, out.getvalue())
        print(json.dumps(shown))
    """)
    assert [code for code, _ in result.values()] == [0, 0, 0]
    assert "campaign" in result["--help"][1] and "--scheduler" in result["campaign run --help"][1]


def test_needs_passes_other_import_errors_through():
    with pytest.raises(ModuleNotFoundError) as other:
        with needs("plots"):
            import contour_fmu_no_such_module  # noqa: F401
    assert not isinstance(other.value, MissingExtra)
    require("campaign", "engines")  # this venv has them all
