"""Issue 8: fmu-manipulation-toolbox's checker on every FMU, as an importer's tool sees it.

`fmutool -input X.fmu -check` runs the toolbox's checkers on the FMU's modelDescription.xml:
the FMI 2.0 XSD schema ("FMU Generic Conformity Checks") and the rules the schema cannot
express ("FMU Semantic Checks": unique names, causality/variability/initial/start
combinations, ModelStructure outputs and dependencies). Every error is logged at ERROR level
and makes fmutool exit non-zero (ExitCode.CHECK_FAILED). The CLI runs in a subprocess, as a
user would run it, through the venv's own interpreter.

The test fails on a non-zero exit, on any ERROR/CRITICAL line, or when a checker's verdict
line is missing. A broken copy of an FMU (an output dropped from <Outputs>, a duplicated
variable name) is checked too, to show that the checker and this harness do report.
"""

import re
import subprocess
import sys
import zipfile

import pytest

FMUS = ("PathInterpolator2D", "ContourCCC2D", "XYServoPlant", "PathInterpolator5X", "ContourCCC5X",
        "FiveAxisPlant")
CLI = "from fmu_manipulation_toolbox.cli.fmutool import fmutool; fmutool()"
VERDICTS = (
    "This FMU seems to be compliant with FMI-2.0.",
    "No semantic error against the FMI-2 standard.",
)


def check(fmu):
    done = subprocess.run([sys.executable, "-c", CLI, "-input", str(fmu), "-check"],
                          capture_output=True, text=True, timeout=120)
    # Strip colorama's colour codes; the log goes to stdout or stderr depending on version.
    out = re.sub(r"\x1b\[[0-9;]*m", "", done.stdout + done.stderr)
    return done.returncode, out


def problems(out):
    return [line for line in out.splitlines() if re.match(r"\s*(ERROR|CRITICAL)\b", line)]


@pytest.mark.parametrize("model", FMUS)
def test_checker_passes(fmu_dir, model):
    rc, out = check(fmu_dir / f"{model}.fmu")
    print(out)
    assert rc == 0, out
    assert not problems(out), out
    for verdict in VERDICTS:
        assert verdict in out, out


def rewrite(src, dst, edit):
    """Copies the FMU with its modelDescription.xml passed through `edit`."""
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "modelDescription.xml":
                new = edit(data.decode())
                assert new != data.decode(), "the edit changed nothing"
                data = new.encode()
            zout.writestr(item, data)


def drop_first_output(xml):
    return re.sub(r"(<Outputs>\s*)<Unknown [^>]*/>", r"\1", xml, count=1)


def duplicate_name(xml):
    names = re.findall(r'<ScalarVariable name="([^"]+)"', xml)
    return xml.replace(f'<ScalarVariable name="{names[1]}"', f'<ScalarVariable name="{names[0]}"', 1)


@pytest.mark.parametrize("edit", [drop_first_output, duplicate_name])
def test_checker_reports_a_broken_model_description(fmu_dir, tmp_path, edit):
    broken = tmp_path / "XYServoPlant.fmu"
    rewrite(fmu_dir / "XYServoPlant.fmu", broken, edit)
    rc, out = check(broken)
    print(out)
    assert rc != 0, out
    assert problems(out), out
