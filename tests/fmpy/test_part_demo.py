"""The part demo (contour_fmu.demo.part) on the shipped G-code part
examples/parts/bracket.ngc, through the FMUs in fmpy: the program has every feature the
demo is about (read here on its own), the fuzzy CCC lowers the largest true contour error
on the part and on its mirror image, the planned reference stays within the tolerance of
the programmed part, and the mirrored program's reference is the original's mirrored."""

import math
import re

import numpy as np
import pytest

from contour_fmu.demo import part as part_demo
from helpers.checkout import REPO
from test_two_axis_fmus import distance_to_pieces

PROGRAM = REPO / "examples" / "parts" / "bracket.ngc"


@pytest.fixture(scope="module")
def result(fmu_dir, tmp_path_factory):
    out = tmp_path_factory.mktemp("part_demo")
    return part_demo.part_demo(fmu_dir, out, PROGRAM), out


def blocks():
    """The program's blocks without comments, upper case, with their line numbers."""
    found = []
    for number, line in enumerate(PROGRAM.read_text().splitlines(), start=1):
        code = re.sub(r"\([^)]*\)", "", line).split(";")[0].strip().upper()
        if code and code != "%":
            found.append((number, code))
    return found


def words(letter, code):
    return [float(v) for v in re.findall(rf"{letter}\s*([-+]?\d*\.?\d+)", code)]


def test_the_shipped_program_has_every_feature_of_the_demo():
    text = PROGRAM.read_text()
    lines = text.splitlines()
    assert lines[0] == "%" and lines[-1] == "%"
    assert all(line.startswith("(") for line in lines[1:4]), "a comment header says what it is"
    code = blocks()
    gs = [(n, g) for n, c in code for g in words("G", c)]
    arcs = [(n, c) for n, c in code if {2.0, 3.0} & set(words("G", c))]
    assert {2.0, 3.0} <= {g for _, g in gs}, "clockwise and counter-clockwise arcs"
    assert len(arcs) >= 3
    # A small radius, given by R.
    radii = [abs(r) for _, c in arcs for r in words("R", c)]
    assert any(0.5 <= r <= 1.0 for r in radii), radii
    # An exact stop (G61), then G64 again; a corner blended within G64 P.
    g61 = [n for n, g in gs if g == 61.0]
    g64 = [n for n, g in gs if g == 64.0]
    assert g61 and any(n > g61[0] for n in g64)
    assert any(words("P", c) and words("P", c)[0] > 0 for _, c in code if 64.0 in words("G", c))
    # F words (more than one feed), the CAM preamble and the end of the program.
    assert len({f for _, c in code for f in words("F", c)}) >= 2
    preamble = {g for _, g in gs}
    assert {21.0, 90.0, 17.0, 54.0} <= preamble
    assert any(30.0 in words("M", c) or 2.0 in words("M", c) for _, c in code)


def test_the_program_parses_into_tangent_and_non_tangent_arc_joins(result):
    res, _ = result
    assert res.duration > 0.0
    # The reader skipped the preamble with one warning per kind (G49 G94 G54 T M6 S M3-M5
    # M7-M9); G40 turns cutter compensation off, G80 is a motion code and the Z-only moves
    # are standstills of the table (contour-core/tests/cam_programs.rs times them).
    assert len(res.warnings) == 8, res.warnings
    assert not any("Z-only" in w or "G80" in w for w in res.warnings)
    pieces = res.pieces
    # Each arc: its ends on its circle; an R arc's radius is its R word.
    kinds = []
    for k, p in enumerate(pieces):
        if p.kind != "arc":
            continue
        assert abs(np.linalg.norm(p.start - p.centre) - p.radius) < 1e-12
        assert abs(np.linalg.norm(p.end - p.centre) - p.radius) < 1e-12
        before = pieces[k - 1]
        assert before.kind == "line"
        incoming = (before.end - before.start) / before.length
        radial = (p.start - p.centre) / p.radius
        kinds.append("tangent" if abs(incoming @ radial) < 1e-12 else "non-tangent")
    assert "tangent" in kinds and "non-tangent" in kinds
    assert min(p.radius for p in pieces if p.kind == "arc") <= 1.0


@pytest.mark.parametrize("which", ["runs", "mirrored_runs"])
def test_the_ccc_lowers_the_largest_true_contour_error(result, which):
    res, _ = result
    without, ccc, alone, shipped = getattr(res, which)
    assert [r.label for r in (without, ccc, alone, shipped)] == [
        "no CCC", "fuzzy-PID CCC", "feed-forward", "fuzzy-PID CCC + feed-forward (shipped)"]
    assert ccc.true.max() < 0.75 * without.true.max()
    assert ccc.true.mean() < without.true.mean()
    # Against the programmed part the blends (within the tolerance, 20 um) are left, so
    # the shipped loop's error is about the plan's own (test_feed_forward_corners.py
    # measures it against the planned geometry).
    assert shipped.true.max() <= res.interpolator["tolerance"] * 1.1
    assert shipped.true.max() < 0.5 * ccc.true.max()
    # The module's distance is the other tests' closed form (test_two_axis_fmus).
    pieces = res.pieces if which == "runs" else res.mirrored_pieces
    for run in (without, ccc, alone, shipped):
        pos = np.column_stack([run.before["plant.pos.x"], run.before["plant.pos.y"]])
        want, _ = distance_to_pieces([p.as_tuple() for p in pieces], pos)
        assert np.abs(run.true - want).max() < 1e-12


def test_the_planned_reference_stays_within_the_tolerance_of_the_programmed_part(result):
    res, _ = result
    tolerance = res.interpolator["tolerance"]
    tuples = [p.as_tuple() for p in res.pieces]
    for run in res.runs + res.mirrored_runs:
        assert run.reference.max() <= tolerance + 1e-9
    run = res.runs[0]
    ref = np.column_stack([run.before["interpolator.ref.x"], run.before["interpolator.ref.y"]])
    off, _ = distance_to_pieces(tuples, ref)
    assert np.abs(off - run.reference).max() < 1e-12
    assert off.max() > 0.5 * tolerance  # bare G64 blends up to the tolerance
    # The corner of G64 P0.01 within its P; the exact stops reached (a sample within
    # jerk·Ts³/6 of the corner); the plan starts and ends at rest at the start point.
    corner = lambda x, y: np.linalg.norm(ref - [x, y], axis=1)  # noqa: E731
    near_p = corner(40.0, 36.0) < 0.5
    assert off[near_p].max() <= 0.01 + 1e-9 and corner(40.0, 36.0).min() > 0.003
    jerk_step = res.interpolator["jerk"] * 1e-9 / 6
    for x, y in [(50.0, 22.0), (0.0, 24.0)]:
        assert corner(x, y).min() <= jerk_step + 1e-12, (x, y)
    assert np.allclose(ref[[0, -1]], 0.0, atol=1e-12)
    # The run lasts the planned duration and the settling margin.
    assert abs(run.after["time"][-1] - (res.duration + part_demo.SETTLE)) <= 1e-3


def test_the_mirrored_program_plans_the_mirror_image_of_the_original(result):
    res, out = result
    mirrored = (out / "paths" / "bracket_mirrored.ngc").read_text()
    assert mirrored.startswith("%\n(mirror image of bracket.ngc")
    # The mirrored file's geometry, read on its own, is the original's mirrored.
    for p, q in zip(res.pieces, res.mirrored_pieces, strict=True):
        assert p.kind == q.kind
        assert np.allclose(q.start, p.start * [1, -1], atol=1e-12)
        assert np.allclose(q.end, p.end * [1, -1], atol=1e-12)
        if p.kind == "arc":
            assert np.allclose(q.centre, p.centre * [1, -1], atol=1e-12)
            assert q.sweep == pytest.approx(-p.sweep, abs=1e-12)
    # Sample by sample, contour-core plans it as the mirror image of the original's plan.
    assert res.mirror_mismatch <= 1e-9
    for a, b in zip(res.runs, res.mirrored_runs):
        assert np.abs(b.before["interpolator.ref.x"] - a.before["interpolator.ref.x"]).max() <= 1e-9
        assert np.abs(b.before["interpolator.ref.y"] + a.before["interpolator.ref.y"]).max() <= 1e-9
        # The controller does not care about the direction of travel.
        assert np.abs(b.true - a.true).max() < 1e-6


def test_the_demo_writes_its_csvs_and_plot(result):
    _, out = result
    for name in ["part_bracket_no_CCC.csv", "part_bracket_fuzzy-PID_CCC.csv",
                 "part_bracket_mirrored_no_CCC.csv", "part_bracket_mirrored_fuzzy-PID_CCC.csv",
                 "part_bracket.png"]:
        assert (out / name).stat().st_size > 0, name
    header = (out / "part_bracket_no_CCC.csv").read_text().splitlines()[0].split(",")
    assert {"time", "plant.pos.x", "trueContourError", "controller.contourError",
            "pathPosition"} <= set(header)
    assert math.isfinite(float((out / "part_bracket_no_CCC.csv").read_text().splitlines()[-1]
                               .split(",")[header.index("trueContourError")]))
