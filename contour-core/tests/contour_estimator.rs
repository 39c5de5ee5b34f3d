//! Accuracy of the free-curve two-circle estimator against the true contour error.
//!
//! Reference samples come from the feed-rate interpolator at Ts = 1 ms. Dense chords:
//! 0.01 mm and 0.1 mm (F = 10 and 100 mm/s; the paper's circle feed 10π mm/s gives
//! 0.0314 mm). Sparse chords, as on controllers with coarse interpolation: 0.5 and 1 mm
//! (F = 500 and 1000 mm/s). For every newest command point R_k the actual point is put on
//! the path normal at a point lagging 0…5 samples (fractional lags too) behind R_k,
//! displaced by ±1, ±10, ±50, ±100 µm. The estimator state depends only on the reference
//! samples, so all displacements are evaluated against the same state.
//!
//! Ground truth: the global true contour error, i.e. the nearest point of the whole path,
//! independent of the estimator: [`TrueErrorIndex`] for every point, and the brute-force
//! [`true_error`] (dense sampling of the whole path + Newton) for about 100 points of every
//! run, which must agree with it to 1e-9 mm.
//!
//! Self-crossings and near approaches ("∞" crosses itself and starts and ends at its
//! crossing; the trident crosses itself twice and starts 0.2 mm from its end). Near them a
//! point displaced from one branch can be nearer another branch, and the estimator — by
//! design — reports the error to the branch being followed. The test points are chosen so
//! that this cannot happen, by geometry fixed before any error is computed: the clearance
//! of a foot point c is its distance to the path outside an arc-length window of ±2 mm
//! around c, and a displacement d is used only if |d| < clearance(c)/3. Then the point
//! c + d·n is |d| from c and at least clearance − |d| > 2|d| from every other branch, so
//! its nearest point is c. The test asserts, for every point, that the global true error
//! equals the construction's d (to 1e-9 mm): the nearest point is never on another branch
//! of a built-in path. Near the crossings the points are still evaluated, with the smaller
//! displacements only.
//!
//! Bounds. The two-axis paper (docs/design/overview.md, source [A], *Measurement and Control* 2022;
//! its estimator after Chen et al.) reports the estimation deviation as below 0.0184 mm on
//! the "∞" curve (its Fig. 14) and within 0.00221 mm on the trident (Fig. 19), without
//! stating the interpolation chord. It gives no number for the circle or line. The
//! principled bound: a circle through three samples spaced h apart interpolates the path's
//! normal offset like a quadratic through three nodes, so where the curvature κ varies with
//! arc length the offset between path and circle inside the span is
//! (κ'/6)·(s − s0)(s − s1)(s − s2), at most κ'·h³/(9√3) for equal spacing (κ' = dκ/ds;
//! the divided-difference form holds for a κ that is only Lipschitz, as at the knots of a
//! cubic NURBS). The estimated distance inherits that offset (the tangent error of the
//! circle adds only d·δθ²/2, below 0.02 µm here). Every run asserts twice this leading
//! term, 2·max|κ'|·h³/(9√3) + 1e-9 mm (rounding), with max|κ'| measured on the path by
//! finite differences; the measured deviations sit at 0.43–0.48 of it on the NURBS, i.e.
//! at the leading term, at every chord. On circles and lines κ' = 0, so the estimator must
//! be exact to rounding at any chord.
//!
//! The paper's figures are the floor to beat at every chord for the points that lag the
//! command by at least one sample, which is where a closed loop lives (the actual point
//! trails by about 1/(Kpp·Ts) ≈ 35 samples). A point less than one sample behind has its
//! foot between the two newest samples, where only one circle exists and its h³ term is not
//! cancelled: those points are held to the derived bound only (trident at a 1 mm chord:
//! 3.36 µm against 7.78 µm; 1.2 µm for lags ≥ 1 against the paper's 2.21 µm). Both maxima
//! are printed.

use contour_core::contour::planar::{
    true_error, Estimator, EstimatorKind, FreeCurveEstimator, TrueErrorIndex,
};
use contour_core::contour::ContourEstimator;
use contour_core::geometry::Vector2;
use contour_core::math;
use contour_core::path::planar::{builtin, Path};
use contour_core::path::{Curve, Interpolator};

const TS: f64 = 1e-3;
const LAGS: [f64; 7] = [0.0, 0.3, 1.0, 1.5, 2.0, 3.7, 5.0];
const DISPLACEMENTS: [f64; 8] = [0.001, -0.001, 0.01, -0.01, 0.05, -0.05, 0.1, -0.1];

/// Half-width of the arc-length window around a foot point that counts as its own branch
/// (mm). Far above the largest displacement, below the built-in paths' 4.2 mm minimum
/// radius, so the window holds one branch only.
const WINDOW: f64 = 2.0;
/// Vertex spacing of the polyline the clearance is computed on (mm).
const CLEARANCE_CHORD: f64 = 0.05;
/// Brute-force checks of the index per run (about).
const BRUTE_CHECKS: usize = 100;

/// The estimation deviations the paper reports (mm), where it reports one.
fn paper_bound(name: &str) -> Option<f64> {
    match name {
        "infinity" => Some(0.0184),
        "trident" => Some(0.00221),
        _ => None,
    }
}

/// Precomputed geometry of one path: the index, the clearance of its points and max |dκ/ds|.
struct Geometry {
    path: Path,
    index: TrueErrorIndex,
    /// Polyline vertices' parameters and clearances (mm).
    vertex_u: Vec<f64>,
    clearance: Vec<f64>,
    /// max |dκ/ds| over the path, 1/mm².
    kappa_slope: f64,
}

fn seg_dist(p: Vector2, a: Vector2, b: Vector2) -> f64 {
    let (abx, aby) = (b[0] - a[0], b[1] - a[1]);
    let l2 = abx * abx + aby * aby;
    let t = if l2 > 0.0 {
        (((p[0] - a[0]) * abx + (p[1] - a[1]) * aby) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    math::hypot(p[0] - a[0] - t * abx, p[1] - a[1] - t * aby)
}

fn curvature(path: &Path, u: f64) -> f64 {
    let e = path.eval(u);
    let s = math::hypot(e.d1[0], e.d1[1]);
    (e.d1[0] * e.d2[1] - e.d1[1] * e.d2[0]) / (s * s * s)
}

impl Geometry {
    fn new(name: &str) -> Self {
        let path = builtin::by_name(name).unwrap();
        let mut it = Interpolator::new(path.clone(), CLEARANCE_CHORD / TS, TS).unwrap();
        let mut vertex_u = vec![it.parameter()];
        let mut pts = vec![it.point()];
        while !it.step().done {
            vertex_u.push(it.parameter());
            pts.push(it.point());
        }
        vertex_u.push(it.parameter());
        pts.push(it.point());
        let n = pts.len();
        // Vertex i sits at arc length ≈ i·CLEARANCE_CHORD (chords within 0.1 %).
        let w = (WINDOW / CLEARANCE_CHORD).ceil() as usize + 1;
        let clearance: Vec<f64> = (0..n)
            .map(|i| {
                let mut best = f64::INFINITY;
                for j in 0..n - 1 {
                    if j + 1 + w > i && j < i + w {
                        continue; // segment j..j+1 inside the window around i
                    }
                    // Cheap reject: the segment is within one chord of its first vertex.
                    let (dx, dy) = (pts[j][0] - pts[i][0], pts[j][1] - pts[i][1]);
                    if math::hypot(dx, dy) - CLEARANCE_CHORD >= best {
                        continue;
                    }
                    best = best.min(seg_dist(pts[i], pts[j], pts[j + 1]));
                }
                best
            })
            .collect();
        // max |dκ/ds| by difference quotients between neighbouring vertices: κ is
        // continuous (cubic NURBS with simple knots, arcs, lines), so each quotient is a
        // mean of κ' and none exceeds max |κ'|; with this spacing they miss it by O(h·κ'').
        let kappa: Vec<f64> = vertex_u.iter().map(|&u| curvature(&path, u)).collect();
        let mut kappa_slope: f64 = 0.0;
        for i in 0..n - 1 {
            let ds = {
                let (dx, dy) = (pts[i + 1][0] - pts[i][0], pts[i + 1][1] - pts[i][1]);
                math::hypot(dx, dy)
            };
            if ds > 0.5 * CLEARANCE_CHORD {
                kappa_slope = kappa_slope.max((kappa[i + 1] - kappa[i]).abs() / ds);
            }
        }
        Geometry {
            index: TrueErrorIndex::new(&path),
            path,
            vertex_u,
            clearance,
            kappa_slope,
        }
    }

    /// A lower bound of the clearance of the path point at parameter `u`: the smaller of the
    /// two enclosing vertices' clearances, less one vertex spacing (moving along the path by
    /// δ changes the distance to the other branches by at most δ).
    fn clearance_at(&self, u: f64) -> f64 {
        let i = self.vertex_u.partition_point(|&v| v <= u).max(1) - 1;
        let j = (i + 1).min(self.vertex_u.len() - 1);
        self.clearance[i].min(self.clearance[j]) - CLEARANCE_CHORD
    }

    /// The principled bound at chord `h` (see the module docs), mm.
    fn circle_fit_bound(&self, h: f64) -> f64 {
        2.0 * self.kappa_slope * h.powi(3) / (9.0 * 3f64.sqrt()) + 1e-9
    }
}

#[derive(Default)]
struct Stats {
    max_dev: f64,
    /// Over the points lagging at least one sample behind the command.
    max_dev_lagging: f64,
    peak_true: f64,
    max_normal_dev: f64,
    points: usize,
    /// Points whose displacement was left out because the foot is near another branch.
    clipped: usize,
    brute_checked: usize,
}

fn normal_at(path: &Path, u: f64) -> (Vector2, Vector2) {
    let e = path.eval(u);
    let s = math::hypot(e.d1[0], e.d1[1]);
    (e.p, Vector2::new(-e.d1[1] / s, e.d1[0] / s))
}

fn run(
    geo: &Geometry,
    feed: f64,
    mut est: impl ContourEstimator,
    stride: usize,
    lags: &[f64],
) -> Stats {
    let path = &geo.path;
    let mut it = Interpolator::new(path.clone(), feed, TS).unwrap();
    let mut us = vec![it.parameter()];
    let mut refs = vec![it.point()];
    while !it.step().done {
        us.push(it.parameter());
        refs.push(it.point());
    }
    let mut st = Stats::default();
    let evaluated = refs.len() / stride * lags.len() * DISPLACEMENTS.len();
    let brute_every = (evaluated / BRUTE_CHECKS).max(1);
    for k in 0..refs.len() {
        // The estimator must see every reference sample; evaluate a subset of them.
        if (k as f64) < lags[lags.len() - 1] + 2.0 || k % stride != 0 {
            est.estimate(refs[k], refs[k]);
            continue;
        }
        for &lag in lags {
            let j = lag.floor() as usize;
            let frac = lag - j as f64;
            let u = us[k - j] - frac * (us[k - j] - us[k - j - 1]);
            let (c, n) = normal_at(path, u);
            let clearance = geo.clearance_at(u);
            for &d in &DISPLACEMENTS {
                if d.abs() >= clearance / 3.0 {
                    st.clipped += 1;
                    continue;
                }
                let p = Vector2::new(c[0] - d * n[0], c[1] - d * n[1]); // d right of travel
                let e = est.estimate(refs[k], p);
                let t = geo.index.error(p, u);
                // The nearest point of the whole path is the constructed foot: never on
                // another branch.
                assert!(
                    (t.error - d).abs() < 1e-9,
                    "F={feed}: true error {} vs d {d} at u={u} (clearance {clearance})",
                    t.error
                );
                if st.points % brute_every == 0 {
                    let b = true_error(path, p);
                    assert!(
                        (b.error - t.error).abs() < 1e-9,
                        "brute force {} vs index {} at u={u}",
                        b.error,
                        t.error
                    );
                    st.brute_checked += 1;
                }
                let dev = (e.error - t.error).abs();
                st.max_dev = st.max_dev.max(dev);
                if lag >= 1.0 {
                    st.max_dev_lagging = st.max_dev_lagging.max(dev);
                }
                st.peak_true = st.peak_true.max(t.error.abs());
                let dn = math::hypot(e.normal[0] - t.normal[0], e.normal[1] - t.normal[1]);
                st.max_normal_dev = st.max_normal_dev.max(dn);
                st.points += 1;
            }
        }
    }
    st
}

fn check(geo: &Geometry, name: &str, feed: f64, stride: usize) -> Stats {
    check_lags(geo, name, feed, stride, &LAGS)
}

fn check_lags(geo: &Geometry, name: &str, feed: f64, stride: usize, lags: &[f64]) -> Stats {
    let st = run(geo, feed, FreeCurveEstimator::default(), stride, lags);
    let chord = feed * TS;
    let bound = geo.circle_fit_bound(chord);
    let paper = paper_bound(name);
    println!(
        "{name:8} chord {chord:.4} mm (F={feed:.2}): max |est − true| {:.3e} µm, lag ≥ 1: {:.3e} µm; \
         bound 2κ'h³/9√3 {:.3e} µm; paper {}; {} points, {} displacements left out near other \
         branches, {} brute-force checks; max |κ'| {:.4}/mm², peak |true| {:.0} µm, max \
         normal deviation {:.2e}",
        st.max_dev * 1e3,
        st.max_dev_lagging * 1e3,
        bound * 1e3,
        paper.map_or("-".to_string(), |b| format!("{} µm", b * 1e3)),
        st.points,
        st.clipped,
        st.brute_checked,
        geo.kappa_slope,
        st.peak_true * 1e3,
        st.max_normal_dev
    );
    assert!(st.points > 500, "{name}: only {} points", st.points);
    assert!(st.brute_checked >= BRUTE_CHECKS / 2);
    // Near-branch exclusions stay a small part of the test.
    assert!(
        st.clipped * 20 < st.points,
        "{name}: {} of {} left out",
        st.clipped,
        st.points
    );
    assert!(
        st.max_dev <= bound,
        "{name} chord {chord}: deviation {} mm > circle-fit bound {bound} mm",
        st.max_dev
    );
    if let Some(paper) = paper {
        assert!(
            st.max_dev_lagging < paper,
            "{name} chord {chord}: deviation {} mm (lag >= 1 sample) not below the paper's \
             {paper} mm",
            st.max_dev_lagging
        );
    }
    assert!(
        st.max_normal_dev < 2e-2,
        "{name}: normal off by {}",
        st.max_normal_dev
    );
    st
}

/// Dense chords: the estimator is far inside every bound; at most 0.5 µm and 1 % of the
/// largest error.
fn check_dense(geo: &Geometry, name: &str, feed: f64, stride: usize) {
    let st = check(geo, name, feed, stride);
    assert!(
        st.max_dev <= 0.5e-3,
        "{name}: deviation {} mm > 0.5 µm",
        st.max_dev
    );
    assert!(
        st.max_dev <= 0.01 * st.peak_true,
        "{name}: deviation > 1 % of peak"
    );
    assert!(st.max_normal_dev < 1e-2);
}

/// Sparse chords (coarse interpolation): 0.5 and 1 mm, every command point evaluated.
fn check_sparse(geo: &Geometry, name: &str) {
    for feed in [500.0, 1000.0] {
        check(geo, name, feed, 1);
    }
}

// Debug builds are slow: the 0.01 mm runs evaluate every 7th command point, the others
// every one.
#[test]
fn free_curve_circle() {
    let geo = Geometry::new("circle");
    assert!(geo.kappa_slope < 1e-9, "{}", geo.kappa_slope);
    check_dense(&geo, "circle", 10.0, 7);
    check_dense(&geo, "circle", 10.0 * std::f64::consts::PI, 7);
    check_dense(&geo, "circle", 100.0, 1);
    check_sparse(&geo, "circle");
}

#[test]
fn free_curve_infinity() {
    let geo = Geometry::new("infinity");
    check_dense(&geo, "infinity", 10.0, 7);
    let st = check(&geo, "infinity", 100.0, 1);
    assert!(st.max_dev <= 0.5e-3);
    // The path crosses itself: points near the crossing were evaluated with smaller
    // displacements only.
    assert!(st.clipped > 0);
    check_sparse(&geo, "infinity");
}

#[test]
fn free_curve_trident() {
    let geo = Geometry::new("trident");
    check_dense(&geo, "trident", 10.0, 7);
    let st = check(&geo, "trident", 100.0, 1);
    assert!(st.max_dev <= 0.5e-3);
    assert!(st.clipped > 0);
    check_sparse(&geo, "trident");
}

#[test]
fn free_curve_straight_line() {
    let geo = Geometry::new("line");
    assert_eq!(geo.kappa_slope, 0.0);
    check_dense(&geo, "line", 10.0, 7);
    check_dense(&geo, "line", 100.0, 1);
    check_sparse(&geo, "line");
}

/// In closed loop a P position loop (Kpp = 28.5 s⁻¹) lags 1/(Kpp·Ts) ≈ 35 samples behind
/// the command whatever the feed: the walk back must reach that far.
#[test]
fn free_curve_closed_loop_lag() {
    let lags = [20.0, 35.0, 35.5, 60.0];
    for name in ["trident", "infinity"] {
        let geo = Geometry::new(name);
        let st = check_lags(&geo, name, 10.0 * std::f64::consts::PI, 5, &lags);
        assert!(st.max_dev <= 0.5e-3);
    }
}

#[test]
fn exact_estimators_match_true_error_on_their_paths() {
    for (name, kind) in [
        ("line", EstimatorKind::Line),
        ("arc", EstimatorKind::Arc),
        ("circle", EstimatorKind::Arc),
    ] {
        let path = builtin::by_name(name).unwrap();
        let mut est = Estimator::for_path(kind, &path);
        for k in 1..200 {
            let u = k as f64 / 200.0;
            let (c, n) = normal_at(&path, u);
            for d in [-0.3, 0.02, 1.5] {
                let p = Vector2::new(c[0] - d * n[0], c[1] - d * n[1]); // d right of travel
                let e = est.estimate(path.point((u + 0.01).min(1.0)), p);
                let t = true_error(&path, p);
                assert!(
                    (e.error - t.error).abs() < 1e-12,
                    "{name}: {} vs {}",
                    e.error,
                    t.error
                );
                assert!((e.normal[0] - t.normal[0]).abs() < 1e-12);
                assert!((e.error - d).abs() < 1e-12);
            }
        }
    }
}
