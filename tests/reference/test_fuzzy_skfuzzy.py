"""The Rust Mamdani engine (contour-core/src/control/fuzzy.rs) against scikit-fuzzy (docs/design/two-axis.md §4.3).

scikit-fuzzy builds the same system from its own parts: triangular sets sampled on a
20001-point universe, `min` for AND, clipping (`min`) implication, `max` accumulation
and centroid defuzzification. The rule tables below are transcribed here from docs/design/two-axis.md §4.3
independently of `contour-core/src/control/rules.rs`.

Fairness notes (checked against the scikit-fuzzy 0.5 sources):
- The universe is [-3, 3] and every grid input lies on it, so defining NB and PB as
  triangles that peak at the universe edges (`trimf([-3, -3, -2])`, `trimf([2, 3, 3])`)
  is the same as the flat shoulders of the Rust sets: beyond +-3 nothing is evaluated.
  `trimf` gives exactly 1 at a == b, and `interp_membership` is exact at the edges.
- scikit-fuzzy fuzzifies by linear interpolation of the sampled sets, inserts the points
  where each clip level cuts its set into the output universe, and integrates the
  sampled aggregate with exact trapezoid moments. What remains is discretisation: the
  set peaks (integers) are not grid points of linspace(-3, 3, 20001) (step 3e-4), and
  crossings of two slopes between grid points are cut off; both are O(step).
  On a 24001-point universe (step 1/4000) every set peak and every slope crossing (at
  half-integers) is a grid point, scikit-fuzzy's aggregate is then exactly piecewise
  linear, and the two must agree to rounding; the last test checks that on a sample.
"""

import os
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

skfuzzy = pytest.importorskip("skfuzzy")
from skfuzzy import control as ctrl  # noqa: E402

# scikit-fuzzy 0.5 calls np.maximum(a, b, out) positionally, which numpy 2.4 deprecates.
pytestmark = pytest.mark.filterwarnings("ignore:Passing more than 2 positional:DeprecationWarning")

NAMES = ["NB", "NM", "NS", "ZO", "PS", "PM", "PB"]
UNIVERSE_POINTS = 20001
GRID = 61
TOLERANCE = 2e-3

# Rows E = NB..PB, columns EC = NB..PB (docs/design/two-axis.md §4.3).
TABLES = {
    "dkp": """
        PB PB PM PM PS ZO ZO
        PB PB PM PS PS ZO NS
        PM PM PM PS ZO NS NS
        PM PM PS ZO NS NM NM
        PS PS ZO NS NS NM NM
        PS ZO NS NM NM NM NB
        ZO ZO NM NM NM NB NB
    """,
    "dki": """
        NB NB NM NM NS ZO ZO
        NB NB NM NS NS ZO ZO
        NB NM NS NS ZO PS PS
        NM NM NS ZO PS PM PM
        NM NS ZO PS PS PM PB
        ZO ZO PS PS PM PB PB
        ZO ZO PS PM PM PB PB
    """,
    "dkd": """
        PS NS NB NB NB NM PS
        PS NS NB NM NM NS ZO
        ZO NS NM NM NS NS ZO
        ZO NS NS NS NS NS ZO
        ZO ZO ZO ZO ZO ZO ZO
        PB NS PS PS PS PS PB
        PB PM PM PM PS PS PB
    """,
}
OUTPUTS = list(TABLES)


def _table(text):
    rows = [line.split() for line in text.strip().splitlines()]
    assert len(rows) == 7 and all(len(r) == 7 for r in rows)
    return rows


def _variable(kind, label, universe):
    var = kind(universe, label)
    for k, name in enumerate(NAMES):
        centre = k - 3
        var[name] = skfuzzy.trimf(universe, [max(centre - 1, -3), centre, min(centre + 1, 3)])
    return var


def build_simulation(points=UNIVERSE_POINTS):
    """The docs/design/two-axis.md §4.3 system in scikit-fuzzy: 49 rules, each firing all three outputs."""
    universe = np.linspace(-3.0, 3.0, points)
    e = _variable(ctrl.Antecedent, "E", universe)
    ec = _variable(ctrl.Antecedent, "EC", universe)
    outs = {name: _variable(ctrl.Consequent, name, universe) for name in OUTPUTS}
    for out in outs.values():
        out.defuzzify_method = "centroid"
    tables = {name: _table(text) for name, text in TABLES.items()}
    rules = []
    for i, ename in enumerate(NAMES):
        for j, cname in enumerate(NAMES):
            consequents = tuple(outs[name][tables[name][i][j]] for name in OUTPUTS)
            rules.append(ctrl.Rule(e[ename] & ec[cname], consequents, and_func=np.fmin))
    return ctrl.ControlSystemSimulation(ctrl.ControlSystem(rules), cache=False)


def _skfuzzy_chunk(pairs, points=UNIVERSE_POINTS):
    """scikit-fuzzy outputs for a block of (E, EC) pairs, in one array-input compute."""
    sim = build_simulation(points)
    sim.input["E"] = pairs[:, 0]
    sim.input["EC"] = pairs[:, 1]
    sim.compute()
    return np.stack([np.asarray(sim.output[name], dtype=float) for name in OUTPUTS], axis=1)


def skfuzzy_grid(grid):
    ee, cc = np.meshgrid(grid, grid, indexing="ij")
    pairs = np.column_stack([ee.ravel(), cc.ravel()])
    # About 25 ms per point in scikit-fuzzy: split the points over the cores.
    workers = max(1, min(4, os.cpu_count() or 1))
    chunks = np.array_split(pairs, 4 * workers)
    with ProcessPoolExecutor(max_workers=workers) as pool:
        parts = list(pool.map(_skfuzzy_chunk, chunks))
    flat = np.concatenate(parts, axis=0)
    return {name: flat[:, k].reshape(len(grid), len(grid)) for k, name in enumerate(OUTPUTS)}


@pytest.fixture(scope="module")
def rust_grid(rust_json):
    data = rust_json("fuzzy_dump", GRID)
    return {key: np.asarray(value, dtype=float) for key, value in data.items()}


def test_grid_spans_universe(rust_grid):
    grid = rust_grid["grid"]
    assert grid[0] == -3.0 and grid[-1] == 3.0  # the universe edges are hit exactly
    np.testing.assert_allclose(grid, np.linspace(-3.0, 3.0, GRID), rtol=0, atol=1e-12)


def test_hand_computed_points(rust_grid):
    """Points where a single rule fires at full strength, worked by hand: a set clipped
    at 1 has its centroid at its centre, and the edge sets (half triangles) at +-(3 - 1/3)."""
    idx = {-3.0: 0, -1.0: 20, 0.0: 30, 2.0: 50, 3.0: 60}
    cases = [
        ("dkp", -3.0, -3.0, 3.0 - 1.0 / 3.0),  # PB
        ("dkp", 3.0, 3.0, -3.0 + 1.0 / 3.0),  # NB
        ("dkp", 0.0, 0.0, 0.0),  # ZO
        ("dki", -1.0, 2.0, 1.0),  # NS/PM -> PS
        ("dkd", 0.0, 0.0, -1.0),  # NS
        ("dkd", 3.0, -3.0, 3.0 - 1.0 / 3.0),  # PB
        ("dkd", 2.0, -1.0, 1.0),  # PM/NS -> PS
    ]
    for name, e, ec, want in cases:
        got = rust_grid[name][idx[e], idx[ec]]
        assert abs(got - want) < 1e-12, (name, e, ec, got, want)


def test_engine_matches_skfuzzy_on_grid(rust_grid):
    # Every other point of the 0.1 grid (961 of scikit-fuzzy's 25 ms points instead of
    # 3721: 70 s of the test run): the 0.2 grid still puts five points on every slope of
    # every set, and the test below compares single points of the full grid.
    grid = rust_grid["grid"][::2]
    reference = skfuzzy_grid(grid)
    worst = {}
    for name in OUTPUTS:
        ours, theirs = rust_grid[name][::2, ::2], reference[name]
        assert ours.shape == theirs.shape == (len(grid), len(grid)) == (31, 31)
        # A flat or constant surface would mean a broken system on either side.
        assert theirs.max() - theirs.min() > 4.0
        dev = np.abs(ours - theirs)
        i, j = np.unravel_index(np.argmax(dev), dev.shape)
        worst[name] = (float(dev.max()), float(grid[i]), float(grid[j]))
    print("max |rust - skfuzzy| per output (dev, E, EC):", worst)
    for name, (dev, e, ec) in worst.items():
        assert dev < TOLERANCE, f"{name}: deviation {dev:.3g} at E={e}, EC={ec}"


def test_engine_matches_skfuzzy_exactly_when_kinks_are_on_its_grid(rust_grid):
    grid = rust_grid["grid"]
    rng = np.random.default_rng(20240604)
    idx = rng.integers(0, GRID, size=(150, 2))
    idx[:4] = [[0, 0], [0, GRID - 1], [GRID - 1, 0], [GRID - 1, GRID - 1]]  # corners
    pairs = np.column_stack([grid[idx[:, 0]], grid[idx[:, 1]]])
    theirs = _skfuzzy_chunk(pairs, points=24001)
    for k, name in enumerate(OUTPUTS):
        ours = rust_grid[name][idx[:, 0], idx[:, 1]]
        dev = np.max(np.abs(ours - theirs[:, k]))
        assert dev < 1e-9, f"{name}: deviation {dev:.3g} on the kink-aligned universe"
