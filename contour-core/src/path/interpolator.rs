//! Feed-rate interpolator: one reference sample every `Ts` at feed `F` (docs/design/two-axis.md §4.6).
//!
//! The curve parameter advances by the second-order Taylor inverse of the arc length,
//!   Δu = L/|C'| − L²·(C'·C'')/(2|C'|⁴),  L = F·Ts,
//! so each chord stays within 0.1 % of L on smooth curves. Where that step is unusable
//! (|C'| ≈ 0 at a degenerate control polygon, or the second-order term reverses the step)
//! a bounded bisection on the chord length takes over; each step's chord is checked and,
//! if off by more than 0.01 %, corrected by a few Newton steps. Derivatives at the current
//! parameter are kept from the previous step, so a typical sample costs one curve
//! evaluation, and every sample a bounded number: no heap allocation, O(1) time.

use serde::{Deserialize, Serialize};

use super::planar::Path;
use super::{Curve, CurvePoint, PathError};
use crate::geometry::{self, Vector};

/// One emitted reference sample.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sample<const D: usize = 2> {
    /// Reference point, mm.
    pub point: Vector<D>,
    /// Curve parameter of the point (a hint for exact-distance searches).
    pub u: f64,
    /// True once the path end has been reached (this and every later sample is the end).
    pub done: bool,
}

/// Samples a curve (a planar [`Path`] unless said otherwise) at a constant feed. The
/// whole struct is the state the FMU saves.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Interpolator<const D: usize = 2, C = Path> {
    path: C,
    feed: f64,
    ts: f64,
    u: f64,
    cur: CurvePoint<D>,
    done: bool,
    samples: u64,
}

/// Bisection iterations of the fallback step (bounds its cost).
const BISECT_ITERS: u32 = 60;
/// Newton corrections allowed after the Taylor predictor.
const NEWTON_ITERS: u32 = 4;
/// Relative chord error accepted without correction (well inside the 0.1 % budget).
const CHORD_TOL: f64 = 1e-4;

fn check(feed: f64, ts: f64) -> Result<(), PathError> {
    if !(feed.is_finite() && feed >= 0.0) {
        return Err(PathError::invalid(format!(
            "feed must be finite and >= 0, got {feed}"
        )));
    }
    if !(ts.is_finite() && ts > 0.0) {
        return Err(PathError::invalid(format!(
            "sample period must be finite and > 0, got {ts}"
        )));
    }
    Ok(())
}

/// Where an [`Interpolator`] stands on its path, without the path: what an owner that
/// already saves the path (or can rebuild it) saves of the interpolator.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Progress<const D: usize> {
    feed: f64,
    ts: f64,
    u: f64,
    cur: CurvePoint<D>,
    done: bool,
    samples: u64,
}

impl<const D: usize, C: Curve<D>> Interpolator<D, C> {
    /// Starts at the beginning of `path` with feed `feed` (mm/s, ≥ 0) and period `ts` (s, > 0).
    pub fn new(path: C, feed: f64, ts: f64) -> Result<Self, PathError> {
        check(feed, ts)?;
        let u = path.param_range().0;
        let cur = path.eval(u);
        Ok(Interpolator {
            path,
            feed,
            ts,
            u,
            cur,
            done: false,
            samples: 0,
        })
    }

    /// Where this interpolator stands (see [`Progress`]).
    pub fn progress(&self) -> Progress<D> {
        Progress {
            feed: self.feed,
            ts: self.ts,
            u: self.u,
            cur: self.cur,
            done: self.done,
            samples: self.samples,
        }
    }

    /// Continues on `path` from `progress`, as saved by [`Self::progress`] on the same
    /// path. Refuses an unusable feed or period and a parameter outside the path; the
    /// owner checks that the path is the one the progress was made on.
    pub fn resume(path: C, progress: Progress<D>) -> Result<Self, PathError> {
        let Progress {
            feed,
            ts,
            u,
            cur,
            done,
            samples,
        } = progress;
        check(feed, ts)?;
        let (start, end) = path.param_range();
        if !(start..=end).contains(&u) {
            return Err(PathError::invalid(format!(
                "path parameter {u} lies outside the path's [{start}, {end}]"
            )));
        }
        Ok(Interpolator {
            path,
            feed,
            ts,
            u,
            cur,
            done,
            samples,
        })
    }

    /// Back to the start of the path.
    pub fn reset(&mut self) {
        self.u = self.path.param_range().0;
        self.cur = self.path.eval(self.u);
        self.done = false;
        self.samples = 0;
    }

    /// Changes the feed for the following samples (mm/s, ≥ 0; 0 holds position).
    pub fn set_feed(&mut self, feed: f64) -> Result<(), PathError> {
        check(feed, self.ts)?;
        self.feed = feed;
        Ok(())
    }

    /// The path being followed.
    pub fn path(&self) -> &C {
        &self.path
    }
    /// Feed, mm/s.
    pub fn feed(&self) -> f64 {
        self.feed
    }
    /// Sample period, s.
    pub fn ts(&self) -> f64 {
        self.ts
    }
    /// Current reference point (sample number [`Self::samples`]).
    pub fn point(&self) -> Vector<D> {
        self.cur.p
    }
    /// Current curve parameter.
    pub fn parameter(&self) -> f64 {
        self.u
    }
    /// Whether the end point has been reached.
    pub fn is_done(&self) -> bool {
        self.done
    }
    /// The reference's velocity at the current sample, mm/s: the feed along the curve's
    /// tangent there; zero at the end (and where the curve has no tangent).
    pub fn velocity(&self) -> Vector<D> {
        self.feed_along(&self.cur, self.done)
    }
    /// The reference's velocity at the next sample, mm/s, the interpolator unchanged (its
    /// look-ahead); zero once the next sample is the end.
    pub fn next_velocity(&self) -> Vector<D> {
        if self.done {
            return Vector::zeros();
        }
        let (_, next, done) = self.next_point();
        self.feed_along(&next, done)
    }
    /// The feed along the tangent at `point`; zero at the end or without a tangent.
    fn feed_along(&self, point: &CurvePoint<D>, done: bool) -> Vector<D> {
        match geometry::unit(&point.d1) {
            Some(t) if !done => t * self.feed,
            _ => Vector::zeros(),
        }
    }
    /// The reference's acceleration at the current sample, mm/s²: feed² times the
    /// curve's curvature vector there (the feed is constant); zero at the end.
    pub fn acceleration(&self) -> Vector<D> {
        if self.done {
            return Vector::zeros();
        }
        self.cur.frame().1 * (self.feed * self.feed)
    }
    /// Number of steps taken since the start (the current point is at time samples·Ts).
    pub fn samples(&self) -> u64 {
        self.samples
    }
    /// The current sample.
    pub fn current(&self) -> Sample<D> {
        Sample {
            point: self.cur.p,
            u: self.u,
            done: self.done,
        }
    }

    /// Advances by one period and returns the new reference sample. The sample that would
    /// pass the path end is clamped to the end point and reports `done`.
    pub fn step(&mut self) -> Sample<D> {
        if self.done {
            return self.current();
        }
        self.samples += 1;
        (self.u, self.cur, self.done) = self.next_point();
        self.current()
    }

    /// The parameter of the next sample, the interpolator unchanged.
    pub fn peek(&self) -> f64 {
        if self.done {
            return self.u;
        }
        self.next_point().0
    }

    /// Where the next sample lies: its parameter, curve point and whether it is the end.
    fn next_point(&self) -> (f64, CurvePoint<D>, bool) {
        let l = self.feed * self.ts;
        if l == 0.0 {
            return (self.u, self.cur, false);
        }
        let (_, u_end) = self.path.param_range();
        let (u0, p0) = (self.u, self.cur.p);
        let d1 = self.cur.d1;
        let sp = geometry::norm(&d1);
        let mut du = if sp > 1e-12 {
            l / sp - l * l * d1.dot(&self.cur.d2) / (2.0 * sp.powi(4))
        } else {
            f64::NAN
        };
        if !(du.is_finite() && du > 0.0) {
            du = self.bisect_step(l);
        }
        let mut u1 = u0 + du;
        // A step landing within rounding of the end is the end (keeps `done` on time).
        if u_end - u1 <= 1e-9 * du {
            u1 = u_end;
        }
        if u1 < u_end {
            let mut e = self.path.eval(u1);
            // The Taylor step is checked by the chord it produced; where it misses
            // (degenerate parametrisation, derivative jumps at knots) a few Newton steps on
            // the chord length fix it, and bisection backs those up.
            let mut c = geometry::dist(&e.p, &p0);
            let mut iters = 0;
            while (c - l).abs() > CHORD_TOL * l && iters < NEWTON_ITERS {
                iters += 1;
                let g1 = (e.p - p0).dot(&e.d1) / c;
                let next = u1 - (c - l) / g1;
                if !(g1 > 0.0 && next.is_finite() && next > u0) {
                    break;
                }
                u1 = next.min(u_end);
                e = self.path.eval(u1);
                c = geometry::dist(&e.p, &p0);
            }
            if (c - l).abs() > CHORD_TOL * l {
                u1 = u0 + self.bisect_step(l);
                e = self.path.eval(u1);
            }
            if u1 < u_end {
                return (u1, e, false);
            }
        } else if geometry::dist(&self.path.point(u_end), &p0) > (1.0 + CHORD_TOL) * l {
            // Predictor overshot the end although the end is still more than L away.
            u1 = u0 + self.bisect_step(l);
            if u1 < u_end {
                return (u1, self.path.eval(u1), false);
            }
        }
        (u_end, self.path.eval(u_end), true)
    }

    /// Parameter increment whose chord is `l`, by bracketing and bisection (bounded).
    fn bisect_step(&self, l: f64) -> f64 {
        let (u0, u_end) = (self.u, self.path.param_range().1);
        let p0 = self.cur.p;
        let chord = |du: f64| geometry::dist(&self.path.point(u0 + du), &p0);
        let span = u_end - u0;
        if chord(span) <= l {
            return span;
        }
        let (mut lo, mut hi) = (0.0, span);
        // Shrink the bracket geometrically first so the bisection starts near the answer.
        for _ in 0..BISECT_ITERS {
            let h = 0.5 * hi;
            if chord(h) > l {
                hi = h;
            } else {
                lo = h;
                break;
            }
        }
        for _ in 0..BISECT_ITERS {
            let m = 0.5 * (lo + hi);
            if chord(m) > l {
                hi = m;
            } else {
                lo = m;
            }
        }
        0.5 * (lo + hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vector2;
    use crate::math;
    use crate::path::planar::builtin;
    use crate::path::Nurbs;

    /// The look-ahead velocity is the next sample's, bit for bit, up to the end (zero
    /// from the sample before it).
    #[test]
    fn next_velocity_is_the_velocity_after_the_step() {
        let mut it = Interpolator::new(builtin::by_name("infinity").unwrap(), 50.0, 1e-3).unwrap();
        let mut steps = 0;
        while !it.is_done() {
            let ahead = it.next_velocity();
            it.step();
            assert_eq!(ahead, it.velocity(), "sample {steps}");
            steps += 1;
        }
        assert!(steps > 100);
        assert_eq!(it.next_velocity(), Vector2::zeros());
    }

    /// Worst relative chord deviation over the whole run (last clamped sample excluded)
    /// and the sample count.
    fn chord_deviation(path: Path, feed: f64, ts: f64) -> (f64, usize) {
        let mut it = Interpolator::new(path, feed, ts).unwrap();
        let l = feed * ts;
        let mut prev = it.point();
        let mut worst: f64 = 0.0;
        let mut n = 0;
        loop {
            let s = it.step();
            if s.done {
                let c = geometry::dist(&s.point, &prev);
                assert!(c <= l * 1.001, "final chord {c} longer than F·Ts");
                break;
            }
            worst = worst.max((geometry::dist(&s.point, &prev) / l - 1.0).abs());
            prev = s.point;
            n += 1;
            assert!(n < 10_000_000);
        }
        (worst, n)
    }

    #[test]
    fn chord_within_0_1_percent() {
        // Chords of 0.01 mm and 0.1 mm per 1 ms sample.
        for &(name, feed) in &[
            ("trident", 10.0),
            ("trident", 100.0),
            ("infinity", 10.0),
            ("infinity", 100.0),
            ("circle", 10.0 * std::f64::consts::PI),
            ("circle", 100.0),
            ("line", 100.0),
            ("arc", 100.0),
        ] {
            let path = builtin::by_name(name).unwrap();
            let len = path.length();
            let (worst, n) = chord_deviation(path, feed, 1e-3);
            assert!(
                worst < 1e-3,
                "{name} F={feed}: worst chord deviation {worst}"
            );
            // Sample count consistent with length / (F·Ts).
            let expect = len / (feed * 1e-3);
            assert!(
                (n as f64 - expect).abs() < 2.0 + 1e-4 * expect,
                "{name}: {n} vs {expect}"
            );
        }
    }

    #[test]
    fn reproduces_paper_circle_time_law() {
        // At F = 10π mm/s the sample k is the paper's (10 cos πt − 10, 10 sin πt), t = k·Ts.
        let ts = 1e-3;
        let mut it = Interpolator::new(
            Path::Arc(builtin::circle()),
            10.0 * std::f64::consts::PI,
            ts,
        )
        .unwrap();
        assert_eq!(it.point(), Vector2::new(0.0, 0.0));
        for k in 1..2000 {
            let s = it.step();
            let t = k as f64 * ts;
            let x = 10.0 * math::cos(std::f64::consts::PI * t) - 10.0;
            let y = 10.0 * math::sin(std::f64::consts::PI * t);
            assert!(
                (s.point[0] - x).abs() < 1e-9 && (s.point[1] - y).abs() < 1e-9,
                "k={k}"
            );
            assert!(!s.done);
        }
        let s = it.step();
        assert!(s.done && s.point[0].abs() < 1e-9 && s.point[1].abs() < 1e-9);
        // Done is sticky.
        assert_eq!(it.step(), s);
    }

    #[test]
    fn degenerate_start_uses_fallback() {
        // Repeated first control points give |C'(0)| = 0 (and C''(0) = 0 for a triple).
        let n = Nurbs::new(
            3,
            crate::path::clamped_uniform_knots(6, 3),
            vec![
                Vector2::new(0., 0.),
                Vector2::new(0., 0.),
                Vector2::new(0., 0.),
                Vector2::new(5., 5.),
                Vector2::new(10., 0.),
                Vector2::new(15., 5.),
            ],
            None,
        )
        .unwrap();
        let (worst, _) = chord_deviation(Path::Nurbs(n), 50.0, 1e-3);
        assert!(worst < 1e-3, "worst {worst}");
    }

    #[test]
    fn state_round_trips_and_validates() {
        let mut it = Interpolator::new(builtin::by_name("trident").unwrap(), 50.0, 1e-3).unwrap();
        for _ in 0..500 {
            it.step();
        }
        let blob = postcard::to_stdvec(&it).unwrap();
        let mut back: Interpolator = postcard::from_bytes(&blob).unwrap();
        assert_eq!(back, it);
        assert_eq!(back.step(), it.step());
        assert!(Interpolator::new(Path::Arc(builtin::circle()), -1.0, 1e-3).is_err());
        assert!(Interpolator::new(Path::Arc(builtin::circle()), 1.0, 0.0).is_err());
        assert!(it.set_feed(f64::NAN).is_err());
        assert_eq!(it.feed(), 50.0);
    }
}
