"""The PSO search box of ccc-tune keeps every fuzzy-scheduled gain inside the contour
loop's 6 dB gain margin (docs/design/two-axis.md §4.4), computed from the plant's physics by
contour_loop.py (scipy), and is not needlessly tighter than that."""

import json
import subprocess
from pathlib import Path

import pytest
from fmpy import read_model_description

from contour_fmu.repo import TUNER_PACKAGE
from contour_loop import critical

REPO = Path(__file__).resolve().parents[2]

# Largest defuzzified increment each table reaches on its folded half (E′ ≤ 0): ΔKp′ = PB
# alone (centroid of the half triangle on [2, 3] is 3 − 1/3), ΔKi′ = PM alone (2; rows NB…ZO
# of the ΔKi′ table hold no PB), ΔKd′ = PS alone (1; no PM or PB in those rows).
LARGEST_INCREMENT = {"kp": 8 / 3, "ki": 2.0, "kd": 1.0}


@pytest.fixture(scope="module")
def box(tmp_path_factory):
    out = tmp_path_factory.mktemp("box") / "box.json"
    subprocess.run(["cargo", "run", "--quiet", "--release", "-p", TUNER_PACKAGE, "--bin", "ccc-tune", "--",
                    "--swarm", "1", "--iters", "1", "--out", str(out)],
                   cwd=REPO, check=True, capture_output=True)
    settings = json.loads(out.read_text())["settings"]
    names = ("ke", "kde", "kp", "ki", "kd")
    return dict(zip(names, settings["lower"])), dict(zip(names, settings["upper"]))


def base_gains():
    """Kp0, Ki0, Kd0 as the ContourCCC2D FMU declares them."""
    md = read_model_description(str(REPO / "modelDescription" / "ContourCCC2D.xml"))
    start = {v.name: float(v.start) for v in md.modelVariables if v.start is not None
             and v.name in ("ccc.Kp0", "ccc.Ki0", "ccc.Kd0")}
    return dict(kp=start["ccc.Kp0"], ki=start["ccc.Ki0"], kd=start["ccc.Kd0"])


@pytest.mark.parametrize("gain,unstable", [("kp", 1e5), ("ki", 1e7), ("kd", 1e3)])
def test_scheduled_gain_keeps_a_6_db_margin(box, gain, unstable):
    lower, upper = box
    base = base_gains()
    largest = base[gain] + LARGEST_INCREMENT[gain] * upper[gain]
    limit = critical(gain, base, unstable)
    assert largest <= 0.5 * limit, f"{gain}: {largest} vs critical {limit}"
    assert largest >= 0.45 * limit, f"{gain}: box tighter than the margin needs"
    assert lower[gain] == 0.0


def test_input_factors_saturate_no_finer_than_three_scale_counts(box):
    _, upper = box
    for name in ("ke", "kde"):
        assert 3.0 / upper[name] == pytest.approx(0.3)  # µm (per sample) at saturation
