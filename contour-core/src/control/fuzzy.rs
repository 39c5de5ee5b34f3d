//! Mamdani fuzzy inference for the gain adaptation of docs/design/two-axis.md §4.3, with exact centroid
//! defuzzification.
//!
//! Sets: seven triangles NB … PB centred at −3 … 3 with half-width 1; NB and PB are flat
//! shoulders outside [−3, 3]. Inputs are clamped to [−3, 3], so on the universe every
//! point belongs to at most two adjacent sets and their memberships sum to one. Rule
//! strength is `min(μE, μEC)`, each rule clips its output set (`min`), the clipped sets
//! are aggregated with `max`, and the crisp output is the centroid of that aggregate on
//! [−3, 3].
//!
//! The aggregate is piecewise linear, so its centroid is computed analytically instead of
//! on a sampled universe: only neighbouring sets overlap, so the area and moment of the
//! union are those of the clipped sets minus those of the neighbour overlaps, all in
//! closed form (see [`centroid`]). Evaluation touches only stack arrays (no allocation),
//! which matters because it runs inside `fmi2DoStep` once per control sample.

use serde::{Deserialize, Serialize};

use super::lanes::F64x2;
use super::rules::{RuleTable, Term, FUZZY_PID_RULES};

/// Lower and upper edge of the normalised universe; inputs are clamped to it.
pub const UNIVERSE: (f64, f64) = (-3.0, 3.0);

/// The defuzzified adjustments ΔKp′, ΔKi′, ΔKd′, each in [−3, 3].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FuzzyOutput {
    /// Proportional-gain adjustment ΔKp′.
    pub dkp: f64,
    /// Integral-gain adjustment ΔKi′.
    pub dki: f64,
    /// Derivative-gain adjustment ΔKd′.
    pub dkd: f64,
}

/// Membership of `x` in `term` (shoulders included, so defined on the whole real line).
///
/// NaN gives 0 for every set.
pub fn membership(term: Term, x: f64) -> f64 {
    let c = term.centre();
    let x = match term {
        Term::NB => x.max(c),
        Term::PB => x.min(c),
        _ => x,
    };
    let m = 1.0 - (x - c).abs();
    if m > 0.0 {
        m
    } else {
        0.0
    }
}

/// The two neighbouring sets an input may activate: `(lower index, μ lower, μ upper)`
/// with the upper set at `lower + 1`. The lower index stops at 5 so the pair always
/// exists (at +3 the lower set just gets μ = 0), which keeps rule firing branch-free.
///
/// Clamping first makes the shoulders implicit. NaN is treated as 0 (the ZO centre) so
/// that a corrupt input can never index outside the tables; the controller validates its
/// inputs anyway.
#[inline]
fn fuzzify(x: f64) -> (usize, f64, f64) {
    let x = if x.is_nan() {
        0.0
    } else {
        x.clamp(UNIVERSE.0, UNIVERSE.1)
    };
    // s lies in [0, 6]; truncation is floor there and, unlike `floor`, needs no libm
    // call on baseline x86-64.
    let s = x - UNIVERSE.0;
    let k = (s as usize).min(5);
    let t = s - k as f64; // in [0, 1]
    (k, 1.0 - t, t)
}

/// Mamdani engine for the three fuzzy-PID outputs. It holds only its rule tables, so it
/// is cheap to copy and serialise together with the controller state.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct FuzzyEngine {
    tables: [RuleTable; 3],
}

impl Default for FuzzyEngine {
    /// The classical fuzzy-PID tables of docs/design/two-axis.md §4.3.
    fn default() -> Self {
        Self::new(FUZZY_PID_RULES)
    }
}

impl FuzzyEngine {
    /// An engine with custom rule tables (in output order ΔKp′, ΔKi′, ΔKd′).
    pub fn new(tables: [RuleTable; 3]) -> Self {
        Self { tables }
    }

    /// The rule tables in use.
    pub fn tables(&self) -> &[RuleTable; 3] {
        &self.tables
    }

    /// All three outputs for normalised inputs `e`, `ec` (clamped to [−3, 3]).
    ///
    /// Fuzzification and the rule strengths are shared by the three outputs.
    #[inline]
    pub fn evaluate(&self, e: f64, ec: f64) -> FuzzyOutput {
        let (fe, fc) = (fuzzify(e), fuzzify(ec));
        let [kp, ki, kd] = &self.tables;
        let (p, i, d) = (
            clip_levels(kp, fe, fc),
            clip_levels(ki, fe, fc),
            clip_levels(kd, fe, fc),
        );
        // ΔKp′ and ΔKi′ side by side in the two lanes of one vector register, ΔKd′ in both
        // of another (plain loops: closures here were left uninlined).
        let (mut pi, mut dd) = ([F64x2::splat(0.0); 7], [F64x2::splat(0.0); 7]);
        for set in 0..7 {
            pi[set] = F64x2([p[set], i[set]]);
            dd[set] = F64x2::splat(d[set]);
        }
        let [dkp, dki] = centroids(pi).0;
        let [dkd, _] = centroids(dd).0;
        FuzzyOutput { dkp, dki, dkd }
    }

    /// The clip level of every output set for one table: `levels[j]` is the largest
    /// strength of the rules that fire set `j`. Exposed for tests and plots.
    ///
    /// # Panics
    /// If `output` is not 0 (ΔKp′), 1 (ΔKi′) or 2 (ΔKd′).
    pub fn clip_levels(&self, output: usize, e: f64, ec: f64) -> [f64; 7] {
        clip_levels(&self.tables[output], fuzzify(e), fuzzify(ec))
    }
}

/// One output of one rule table for normalised inputs `e`, `ec`.
pub fn evaluate_table(table: &RuleTable, e: f64, ec: f64) -> f64 {
    infer(table, fuzzify(e), fuzzify(ec))
}

#[inline(always)]
fn clip_levels(table: &RuleTable, fe: (usize, f64, f64), fc: (usize, f64, f64)) -> [f64; 7] {
    let mut h = [0.0_f64; 7];
    let (ie, le, ue) = fe;
    let (ic, lc, uc) = fc;
    // Only the 2 × 2 block of rules around the inputs can fire; a rule of strength 0
    // leaves its level unchanged, so no case analysis is needed.
    // The memberships are in [0, 1], never NaN or −0 (`fuzzify`), where plain
    // comparisons give f64::min's and max's bits without their NaN checks.
    let lesser = |a: f64, b: f64| if b < a { b } else { a };
    for (i, j, strength) in [
        (ie, ic, lesser(le, lc)),
        (ie, ic + 1, lesser(le, uc)),
        (ie + 1, ic, lesser(ue, lc)),
        (ie + 1, ic + 1, lesser(ue, uc)),
    ] {
        let slot = &mut h[table[i][j].index()];
        *slot = if strength > *slot { strength } else { *slot };
    }
    h
}

#[inline]
fn infer(table: &RuleTable, fe: (usize, f64, f64), fc: (usize, f64, f64)) -> f64 {
    centroid(&clip_levels(table, fe, fc))
}

/// Exact centroid of the aggregate `max_j min(h[j], triangle_j(y))` on [−3, 3].
///
/// Two sets overlap only between neighbouring centres, so by inclusion–exclusion
/// `∫max = Σ_j ∫clip_j − Σ_j ∫min(clip_j, clip_j+1)` (and the same for the first
/// moment), and every term has a closed form:
/// - an interior set clipped at h: trapezoid of area h(2 − h), symmetric about its centre;
/// - an edge set (half triangle on [−3, −2] or [2, 3]) clipped at h: area h(2 − h)/2 and
///   moment about its centre ±(1 − (1 − h)³)/6 (toward the inside);
/// - the overlap of neighbours clipped at a and b, with m = min(a, b, 1/2): area m − m²,
///   symmetric about the midpoint of the two centres.
///
/// The sum is over 7 sets and 6 overlaps with no branching on the shape, which is what
/// makes evaluation cheap; the unit tests check it against a breakpoint-by-breakpoint
/// integration of the linear pieces (where the clipped segments cross) and against a
/// fine Simpson rule.
///
/// Returns 0 (the centre of the universe, i.e. "no gain change") when every level is 0:
/// the aggregate is then empty and has no centroid. With the sets above that cannot
/// happen, because the memberships of any input sum to one, so some rule fires with
/// strength ≥ 1/2; the fallback only guards custom or degenerate use. Levels are taken
/// as clamped to [0, 1], NaN as 0.
pub fn centroid(h: &[f64; 7]) -> f64 {
    // Levels outside [0, 1] (or NaN) cannot come from the rules; clamp them for custom use.
    let h = h.map(|v| if v > 0.0 { v.min(1.0) } else { 0.0 });
    centroids(h.map(F64x2::splat)).0[0]
}

/// [`centroid`] of two aggregates at once, one in each lane, from levels in [0, 1] (not
/// NaN, not −0): each lane gets the operations of the formula in its order, so the bits
/// are those of one aggregate computed alone, and the lanes never mix, which keeps the
/// compiler to one vector instruction per operation.
#[inline(always)]
fn centroids(h: [F64x2; 7]) -> F64x2 {
    let (one, two, half) = (F64x2::splat(1.0), F64x2::splat(2.0), F64x2::splat(0.5));
    // Set areas (edge sets are half triangles) and the overlaps of neighbours; kept as
    // independent terms so the sums below do not form one long dependency chain.
    let mut a = [F64x2::splat(0.0); 7];
    for (j, (a, &h)) in a.iter_mut().zip(&h).enumerate() {
        let full = h * (two - h);
        *a = if j == 0 || j == 6 { half * full } else { full };
    }
    let mut o = [F64x2::splat(0.0); 6];
    for (o, pair) in o.iter_mut().zip(h.windows(2)) {
        let m = pair[0].lesser(pair[1]).lesser(half);
        *o = m - m * m;
    }
    // Edge sets: moment about their own centre, toward the inside.
    let q0 = one - h[0];
    let q6 = one - h[6];
    let edge = ((one - q0 * q0 * q0) - (one - q6 * q6 * q6)) / F64x2::splat(6.0);
    let area = (a[0] + a[6]) + (a[1] + a[5]) + (a[2] + a[4]) + a[3]
        - ((o[0] + o[5]) + (o[1] + o[4]) + (o[2] + o[3]));
    // Moments about y = 0: centres −3 … 3, overlap midpoints −2.5 … 2.5.
    let times = F64x2::splat;
    let moment = times(3.0) * (a[6] - a[0]) + times(2.0) * (a[5] - a[1]) + (a[4] - a[2]) + edge
        - (times(2.5) * (o[5] - o[0]) + times(1.5) * (o[4] - o[1]) + half * (o[3] - o[2]));
    (moment / area).where_positive(area)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::{KD_RULES, KI_RULES, KP_RULES};

    /// The same centroid by explicit breakpoints: per unit interval between two centres,
    /// the falling clipped set and the rising clipped set meet at one point; together
    /// with the two clip corners that splits the interval into four linear pieces, each
    /// integrated exactly.
    fn centroid_piecewise(h: &[f64; 7]) -> f64 {
        let mut area = 0.0;
        let mut moment = 0.0;
        for m in 0..6 {
            let (ha, hb) = (h[m], h[m + 1]);
            if ha <= 0.0 && hb <= 0.0 {
                continue;
            }
            let (a, mo) = unit_interval(ha, hb);
            let x0 = m as f64 - 3.0;
            area += a;
            moment += mo + x0 * a;
        }
        moment / area
    }

    /// Area and first moment (about s = 0) on s ∈ [0, 1] of
    /// `f(s) = max(min(ha, 1 − s), min(hb, s))`: the falling set centred at s = 0 clipped at
    /// `ha` and the rising set centred at s = 1 clipped at `hb`.
    ///
    /// The first term is non-increasing and the second non-decreasing, so they cross once,
    /// at `s*`; left of it f follows the first (flat at `ha` up to 1 − ha, then 1 − s), right
    /// of it the second (s up to hb, then flat at `hb`). That gives the breakpoints
    /// 0 ≤ p1 ≤ s* ≤ p3 ≤ 1 with f linear in between.
    fn unit_interval(ha: f64, hb: f64) -> (f64, f64) {
        let s_star = if ha <= hb && ha <= 0.5 {
            ha // a's plateau meets b's slope
        } else if hb < ha && hb <= 0.5 {
            1.0 - hb // a's slope meets b's plateau
        } else {
            0.5 // both slopes
        };
        let p1 = (1.0 - ha).min(s_star);
        let p3 = hb.max(s_star);
        let c = ha.min(1.0 - s_star);
        let (a1, m1) = linear_piece(0.0, p1, ha, ha);
        let (a2, m2) = linear_piece(p1, s_star, ha, c);
        let (a3, m3) = linear_piece(s_star, p3, c, hb);
        let (a4, m4) = linear_piece(p3, 1.0, hb, hb);
        (a1 + a2 + a3 + a4, m1 + m2 + m3 + m4)
    }

    /// Exact area and first moment of the linear function through (x0, y0) and (x1, y1)
    /// over [x0, x1].
    fn linear_piece(x0: f64, x1: f64, y0: f64, y1: f64) -> (f64, f64) {
        let w = x1 - x0;
        (
            0.5 * w * (y0 + y1),
            w * (y0 * (2.0 * x0 + x1) + y1 * (x0 + 2.0 * x1)) / 6.0,
        )
    }

    /// Clip levels by brute force over all 49 rules, straight from the definitions.
    fn brute_levels(table: &RuleTable, e: f64, ec: f64) -> [f64; 7] {
        let e = e.clamp(-3.0, 3.0);
        let ec = ec.clamp(-3.0, 3.0);
        let mut h = [0.0_f64; 7];
        for te in Term::ALL {
            for tc in Term::ALL {
                let s = membership(te, e).min(membership(tc, ec));
                let out = table[te.index()][tc.index()].index();
                h[out] = h[out].max(s);
            }
        }
        h
    }

    fn aggregate(h: &[f64; 7], y: f64) -> f64 {
        Term::ALL
            .iter()
            .map(|&t| h[t.index()].min(membership(t, y)))
            .fold(0.0, f64::max)
    }

    /// Composite Simpson rule with `n` (even) intervals on [−3, 3].
    fn simpson_centroid(h: &[f64; 7], n: usize) -> f64 {
        let dx = 6.0 / n as f64;
        let (mut a, mut m) = (0.0, 0.0);
        for k in 0..=n {
            let y = -3.0 + k as f64 * dx;
            let w = if k == 0 || k == n {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let f = aggregate(h, y);
            a += w * f;
            m += w * f * y;
        }
        m / a
    }

    /// Deterministic pseudo-random numbers in [−3.5, 3.5] (beyond the clamp on purpose).
    fn lcg_points(n: usize) -> Vec<(f64, f64)> {
        let mut s: u64 = 0x2545_f491_4f6c_dd1d;
        let mut next = || {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (s >> 11) as f64 / (1u64 << 53) as f64 * 7.0 - 3.5
        };
        (0..n).map(|_| (next(), next())).collect()
    }

    #[test]
    fn exact_centroid_matches_fine_simpson() {
        let mut points = vec![
            (0.0, 0.0),
            (-3.0, -3.0),
            (3.0, 3.0),
            (3.0, -3.0),
            (0.5, 0.5),
            (-0.5, 2.25),
            (1.3, -2.7),
            (2.999, 0.001),
        ];
        points.extend(lcg_points(14));
        for (e, ec) in points {
            for table in [&KP_RULES, &KI_RULES, &KD_RULES] {
                let h = brute_levels(table, e, ec);
                let exact = evaluate_table(table, e, ec);
                let numeric = simpson_centroid(&h, 1_000_000);
                assert!(
                    (exact - numeric).abs() < 1e-9,
                    "e={e} ec={ec}: exact {exact} vs Simpson {numeric}"
                );
                let pieces = centroid_piecewise(&h);
                assert!((pieces - numeric).abs() < 1e-9, "piecewise {pieces}");
            }
        }
    }

    /// Closed form against the breakpoint integration for arbitrary clip levels (not only
    /// those the rule tables can produce), including zeros, ones and the 1/2 boundary.
    #[test]
    fn closed_form_equals_breakpoint_integration() {
        let specials = [0.0, 0.5, 1.0, 0.25, 0.75];
        let mut s: u64 = 7;
        let mut next = || {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        for k in 0..20_000 {
            let mut h = [0.0; 7];
            for v in h.iter_mut() {
                let r = next();
                *v = if r < 0.3 {
                    0.0
                } else if r < 0.5 {
                    specials[(next() * 5.0) as usize % 5]
                } else {
                    next()
                };
            }
            if h.iter().all(|&v| v == 0.0) {
                continue;
            }
            let (a, b) = (centroid(&h), centroid_piecewise(&h));
            assert!((a - b).abs() < 1e-12, "case {k}: {h:?}: {a} vs {b}");
        }
    }

    /// `n` pseudo-random points and the grid of step 0.25 out to ±`r`/4.
    fn points_and_grid(n: usize, r: i32) -> Vec<(f64, f64)> {
        let mut points = lcg_points(n);
        for i in -r..=r {
            for j in -r..=r {
                points.push((i as f64 * 0.25, j as f64 * 0.25));
            }
        }
        points
    }

    #[test]
    fn fast_clip_levels_equal_brute_force() {
        let engine = FuzzyEngine::default();
        for (e, ec) in points_and_grid(2000, 12) {
            for (k, table) in engine.tables().iter().enumerate() {
                assert_eq!(
                    engine.clip_levels(k, e, ec),
                    brute_levels(table, e, ec),
                    "e={e} ec={ec}"
                );
            }
        }
    }

    /// The centroid as one aggregate at a time computed it before the engine computed the
    /// three side by side (f64::min and max, a clamp on every level).
    fn centroid_one_by_one(h: &[f64; 7]) -> f64 {
        let h = h.map(|v| if v > 0.0 { v.min(1.0) } else { 0.0 });
        let a: [f64; 7] = std::array::from_fn(|j| {
            let full = h[j] * (2.0 - h[j]);
            if j == 0 || j == 6 {
                0.5 * full
            } else {
                full
            }
        });
        let o: [f64; 6] = std::array::from_fn(|j| {
            let m = h[j].min(h[j + 1]).min(0.5);
            m - m * m
        });
        let (q0, q6) = (1.0 - h[0], 1.0 - h[6]);
        let edge = ((1.0 - q0 * q0 * q0) - (1.0 - q6 * q6 * q6)) / 6.0;
        let area = (a[0] + a[6]) + (a[1] + a[5]) + (a[2] + a[4]) + a[3]
            - ((o[0] + o[5]) + (o[1] + o[4]) + (o[2] + o[3]));
        let moment = 3.0 * (a[6] - a[0]) + 2.0 * (a[5] - a[1]) + (a[4] - a[2]) + edge
            - (2.5 * (o[5] - o[0]) + 1.5 * (o[4] - o[1]) + 0.5 * (o[3] - o[2]));
        if area > 0.0 {
            moment / area
        } else {
            0.0
        }
    }

    /// The three outputs computed side by side have the bits of each computed alone, as
    /// before, from the rule tables' levels and from any levels (out of [0, 1], NaN).
    #[test]
    fn side_by_side_centroids_have_the_bits_of_one_by_one() {
        let engine = FuzzyEngine::default();
        let mut points = points_and_grid(20_000, 14);
        points.extend([(f64::NAN, 0.5), (-0.0, 0.0), (3.0, -3.0), (1e300, -1e-300)]);
        for (e, ec) in points {
            let out = engine.evaluate(e, ec);
            let one_by_one: [f64; 3] =
                std::array::from_fn(|k| centroid_one_by_one(&engine.clip_levels(k, e, ec)));
            assert_eq!(
                [out.dkp, out.dki, out.dkd].map(f64::to_bits),
                one_by_one.map(f64::to_bits),
                "e={e} ec={ec}"
            );
        }
        for (x, y) in lcg_points(5_000) {
            let h: [f64; 7] = std::array::from_fn(|j| match j {
                0 => f64::NAN,
                3 => -0.0,
                _ => crate::math::sin(x * (j as f64 + 1.0) + y) * 1.4,
            });
            assert_eq!(centroid(&h).to_bits(), centroid_one_by_one(&h).to_bits());
        }
    }

    /// Closed-form centroids of single clipped sets, worked by hand.
    #[test]
    fn hand_computed_centroids() {
        let mut h = [0.0; 7];
        // ZO fully on: symmetric triangle → 0.
        h[3] = 1.0;
        assert!(centroid(&h).abs() < 1e-15);
        // NB at 1: right half-triangle on [−3, −2] → −3 + 1/3.
        let mut h = [0.0; 7];
        h[0] = 1.0;
        assert!((centroid(&h) - (-3.0 + 1.0 / 3.0)).abs() < 1e-15);
        // PS clipped at 1/2: trapezoid on [0, 2] with top [0.5, 1.5] → centre 1.
        let mut h = [0.0; 7];
        h[4] = 0.5;
        assert!((centroid(&h) - 1.0).abs() < 1e-15);
        // PS and PM both at 1/2: flat 1/2 on [0.5, 2.5] plus ramps; symmetric about 1.5.
        h[5] = 0.5;
        assert!((centroid(&h) - 1.5).abs() < 1e-15);
        // NB at 1 and PB at 1: mirror images → 0.
        let mut h = [0.0; 7];
        h[0] = 1.0;
        h[6] = 1.0;
        assert!(centroid(&h).abs() < 1e-15);
        // NB at 1 and NM at 1/4: NB's slope falls from 1 to 1/4 on [−3, −2.25], NM's
        // plateau holds 1/4 on [−2.25, −1.25], NM's slope falls to 0 at −1.
        let mut h = [0.0; 7];
        h[0] = 1.0;
        h[1] = 0.25;
        let pieces = [
            (-3.0, -2.25, 1.0, 0.25),
            (-2.25, -1.25, 0.25, 0.25),
            (-1.25, -1.0, 0.25, 0.0),
        ];
        let (mut a, mut m) = (0.0, 0.0);
        for (x0, x1, y0, y1) in pieces {
            // Trapezoid = rectangle + triangle, centroids from elementary geometry.
            let lo: f64 = f64::min(y0, y1);
            let rect = (x1 - x0) * lo;
            let tri = 0.5 * (x1 - x0) * (y0 - y1).abs();
            let tri_c = if y0 > y1 {
                x0 + (x1 - x0) / 3.0
            } else {
                x1 - (x1 - x0) / 3.0
            };
            a += rect + tri;
            m += rect * 0.5 * (x0 + x1) + tri * tri_c;
        }
        assert!((centroid(&h) - m / a).abs() < 1e-14);
    }

    #[test]
    fn empty_aggregate_returns_zero() {
        assert_eq!(centroid(&[0.0; 7]), 0.0);
    }

    #[test]
    fn membership_shapes() {
        assert_eq!(membership(Term::NB, -10.0), 1.0);
        assert_eq!(membership(Term::NB, -2.5), 0.5);
        assert_eq!(membership(Term::PB, 10.0), 1.0);
        assert_eq!(membership(Term::ZO, 0.25), 0.75);
        assert_eq!(membership(Term::ZO, 1.0), 0.0);
        assert_eq!(membership(Term::PM, f64::NAN), 0.0);
    }

    #[test]
    fn inputs_beyond_universe_are_clamped_and_nan_is_zo() {
        let engine = FuzzyEngine::default();
        assert_eq!(engine.evaluate(7.0, -9.0), engine.evaluate(3.0, -3.0));
        assert_eq!(engine.evaluate(f64::NAN, 0.0), engine.evaluate(0.0, 0.0));
        // At the centre only ZO/ZO fires: ΔKp′ = ΔKi′ = 0 (ZO), ΔKd′ = NS → −1.
        let out = engine.evaluate(0.0, 0.0);
        assert!(out.dkp.abs() < 1e-15);
        assert!(out.dki.abs() < 1e-15);
        assert!((out.dkd + 1.0).abs() < 1e-15);
    }
}
