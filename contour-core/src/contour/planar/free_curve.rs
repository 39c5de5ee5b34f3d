//! Free-curve contour-error estimator: the two-circle method of the paper (after Chen et
//! al.), docs/design/two-axis.md §4.1.
//!
//! Recent reference samples are kept in a fixed-capacity ring buffer. From the newest
//! command point the search walks back while the distance to P decreases; the last point
//! is Rε. Circles C1 through (Rε+1, Rε, Rε−1) and C2 through (Rε, Rε−1, Rε−2) approximate
//! the path around it. Combination (docs/design/two-axis.md §4.1): the foot lies between Rε and its
//! neighbour on P's side, and the estimate is the mean of the two circles that span that
//! interval: C1 and C2 when P is behind Rε, C1 and C0 through (Rε+2, Rε+1, Rε) when P is
//! ahead ((P − Rε)·(Rε+1 − Rε) > 0). Their leading interpolation errors have opposite
//! signs. Near the ends of the buffer the one available circle is used.
//!
//! Each circle is evaluated by [`local_circle::circle_error`], which reduces continuously to the
//! signed distance to the chord line for collinear samples, so straight parts need no
//! threshold. The walk is bounded by the capacity and nothing is allocated after
//! construction. Walking back from the command point (not a global nearest search) keeps
//! the estimate on the right branch where a path crosses itself.

use serde::{Deserialize, Serialize};

use super::local_circle::{self, CircleStart, SampleCircle};
use crate::contour::{ContourEstimate, ContourEstimator};
use crate::geometry::{self, Vector2};

/// Default buffer capacity. The actual point lags the command by about 1/(Kpp·Ts)
/// samples (35 for Kpp = 28.5 s⁻¹, Ts = 1 ms) whatever the feed; 256 leaves ample margin.
pub const DEFAULT_CAPACITY: usize = 256;

/// Smallest buffer that can hold C1 and C2 (Rε+1 … Rε−2).
pub const MIN_CAPACITY: usize = 4;

/// Reference points closer than this (mm) to the newest stored one are not stored:
/// a held reference (feed 0, path end) must not create degenerate circles.
const MIN_SPACING: f64 = 1e-9;

/// Serialised form, validated on load so a corrupt state blob cannot cause out-of-range
/// indexing.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct FreeCurveData {
    buf: Vec<Vector2>,
    head: usize,
    len: usize,
}

/// Two-circle free-curve estimator over a ring buffer of reference samples.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(try_from = "FreeCurveData", into = "FreeCurveData")]
pub struct FreeCurveEstimator {
    buf: Vec<Vector2>,
    /// Index of the newest sample.
    head: usize,
    /// Number of valid samples.
    len: usize,
    /// `chords[i]`: the length of the chord from the sample before `buf[i]` to it, as
    /// `push` measured it. Each chord serves up to four circles, so it is measured once;
    /// derived from the samples, so neither saved nor compared.
    chords: Vec<f64>,
    /// `circles[i]`: the circle through the samples around `buf[i]` (the one before it,
    /// it, the one after), kept: the walk back meets the same circles for many samples,
    /// and measuring one takes most of an estimate's time. Started once its newest sample
    /// has arrived and finished on the next sample, each time after the estimate (off the
    /// path from the actual point to it); measured when first needed after a restore.
    /// Derived, so neither saved nor compared.
    circles: Vec<KeptCircle>,
}

/// A circle beside the ring, as far as it has been measured.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
enum KeptCircle {
    #[default]
    Unmeasured,
    Started(CircleStart),
    Measured(SampleCircle),
}

impl PartialEq for FreeCurveEstimator {
    fn eq(&self, other: &Self) -> bool {
        (&self.buf, self.head, self.len) == (&other.buf, other.head, other.len)
    }
}

impl TryFrom<FreeCurveData> for FreeCurveEstimator {
    type Error = String;
    fn try_from(d: FreeCurveData) -> Result<Self, String> {
        if d.buf.len() < MIN_CAPACITY || d.head >= d.buf.len() || d.len > d.buf.len() {
            return Err("corrupt free-curve estimator state".into());
        }
        let mut estimator = FreeCurveEstimator {
            chords: vec![0.0; d.buf.len()],
            circles: vec![KeptCircle::Unmeasured; d.buf.len()],
            buf: d.buf,
            head: d.head,
            len: d.len,
        };
        // The chords again, from the samples, as `push` measured them.
        for k in 0..estimator.len.saturating_sub(1) {
            let i = estimator.index(k);
            estimator.chords[i] = geometry::dist(&estimator.get(k), &estimator.get(k + 1));
        }
        Ok(estimator)
    }
}

impl From<FreeCurveEstimator> for FreeCurveData {
    fn from(e: FreeCurveEstimator) -> Self {
        FreeCurveData {
            buf: e.buf,
            head: e.head,
            len: e.len,
        }
    }
}

impl Default for FreeCurveEstimator {
    fn default() -> Self {
        Self::new(DEFAULT_CAPACITY)
    }
}

impl FreeCurveEstimator {
    /// Estimator remembering the last `capacity` distinct reference samples (at least
    /// [`MIN_CAPACITY`]; smaller values are raised to it). The capacity must exceed the
    /// lag of the actual point behind the command, in samples, plus two.
    pub fn new(capacity: usize) -> Self {
        let cap = capacity.max(MIN_CAPACITY);
        FreeCurveEstimator {
            buf: vec![Vector2::zeros(); cap],
            head: 0,
            len: 0,
            chords: vec![0.0; cap],
            circles: vec![KeptCircle::Unmeasured; cap],
        }
    }

    /// Buffer capacity.
    pub fn capacity(&self) -> usize {
        self.buf.len()
    }

    /// Number of stored samples.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True before the first sample.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Where the `k`-th newest stored sample is in the ring (0 = newest); `k < len`.
    fn index(&self, k: usize) -> usize {
        // No `%` on the hot path: k < len ≤ capacity and head < capacity.
        if k <= self.head {
            self.head - k
        } else {
            (self.head + self.buf.len()).wrapping_sub(k)
        }
    }

    /// The `k`-th newest stored sample (0 = newest); `k < len`.
    fn get(&self, k: usize) -> Vector2 {
        self.buf.get(self.index(k)).copied().unwrap_or_default()
    }

    /// The length of the chord from the `k + 1`-th latest sample to the `k`-th.
    fn chord(&self, k: usize) -> f64 {
        self.chords.get(self.index(k)).copied().unwrap_or_default()
    }

    fn push(&mut self, r: Vector2) {
        let chord = if self.len > 0 {
            geometry::dist(&r, &self.get(0))
        } else {
            0.0
        };
        if self.len > 0 && chord <= MIN_SPACING {
            return;
        }
        let cap = self.buf.len();
        // No `%`: a division costs more than the rest of the push's bookkeeping.
        self.head = if self.head + 1 < cap {
            self.head + 1
        } else {
            0
        };
        self.buf[self.head] = r;
        self.chords[self.head] = chord;
        self.circles[self.head] = KeptCircle::Unmeasured;
        self.len = (self.len + 1).min(cap);
    }

    /// The samples around the `m`-th latest (`1 ≤ m ≤ len − 2`), oldest first, and the
    /// lengths of their two chords.
    fn around(&self, m: usize) -> ([Vector2; 3], [f64; 2]) {
        (
            [self.get(m + 1), self.get(m), self.get(m - 1)],
            [self.chord(m), self.chord(m - 1)],
        )
    }

    /// The circle through the samples around the `m`-th latest, measured now.
    #[cfg(test)]
    fn measure_circle(&self, m: usize) -> SampleCircle {
        let (pts, chords) = self.around(m);
        SampleCircle::through(pts, chords)
    }

    /// The circle through the samples around the `m`-th latest, kept: measured, or
    /// finished, if it was not yet.
    fn circle(&mut self, m: usize) -> &KeptCircle {
        let i = self.index(m).min(self.circles.len() - 1);
        if !matches!(self.circles[i], KeptCircle::Measured(_)) {
            let (pts, chords) = self.around(m);
            let start = match self.circles[i] {
                KeptCircle::Started(start) => start,
                _ => SampleCircle::start(pts, chords),
            };
            self.circles[i] = KeptCircle::Measured(SampleCircle::finish(start, pts, chords));
        }
        &self.circles[i]
    }

    /// After an estimate: starts the circle around the sample before the newest (its
    /// newer neighbour has just arrived) and finishes the one started last time.
    fn measure_ahead(&mut self) {
        if self.len >= 3 {
            let i = self.index(1).min(self.circles.len() - 1);
            if self.circles[i] == KeptCircle::Unmeasured {
                let (pts, chords) = self.around(1);
                self.circles[i] = KeptCircle::Started(SampleCircle::start(pts, chords));
            }
        }
        if self.len >= 4 {
            self.circle(2);
        }
    }

    /// Rε: how many samples back from the newest the distance to `actual` stops
    /// decreasing. Newest to oldest is the ring's part up to `head` backwards, then the
    /// rest backwards: two plain loops over slices.
    fn walk_back(&self, actual: Vector2) -> usize {
        let (front, back) = self.buf.split_at((self.head + 1).min(self.buf.len()));
        let front = &front[front.len().saturating_sub(self.len)..];
        let back = &back[back.len().saturating_sub(self.len - front.len())..];
        let Some((newest, front)) = front.split_last() else {
            return 0;
        };
        let mut d = geometry::dist2(&actual, newest);
        let mut k = 0;
        for part in [front, back] {
            for r in part.iter().rev() {
                let dn = geometry::dist2(&actual, r);
                if dn < d {
                    d = dn;
                    k += 1;
                } else {
                    return k;
                }
            }
        }
        k
    }

    /// Circle through the samples centred on `m` (m+1 older, m−1 newer), evaluated at the
    /// sample `k` (which must be one of the three); `None` if unavailable.
    fn triple(&mut self, p: Vector2, m: usize, k: usize) -> Option<ContourEstimate> {
        if m == 0 || m + 1 >= self.len || k + 1 < m || k > m + 1 {
            return None;
        }
        let at = self.get(k);
        match self.circle(m) {
            KeptCircle::Measured(circle) => Some(circle.error(p, at, m + 1 - k)),
            _ => None,
        }
    }
}

impl ContourEstimator for FreeCurveEstimator {
    fn estimate(&mut self, reference: Vector2, actual: Vector2) -> ContourEstimate {
        self.push(reference);
        match self.len {
            0 | 1 => return ContourEstimate::default(),
            2 => {
                let (a, b) = (self.get(1), self.get(0));
                let d = b - a;
                let dir = d * (1.0 / geometry::norm(&d));
                return super::line::line_error(actual, b, dir);
            }
            _ => {}
        }
        let k = self.walk_back(actual);
        let re = self.get(k);
        let ahead = k >= 1 && (actual - re).dot(&(self.get(k - 1) - re)) > 0.0;
        // The foot lies between Rε and its neighbour on P's side. Both circles whose three
        // samples span that interval (centred on Rε and on the neighbour) are used: their
        // leading interpolation errors have opposite signs, so their mean cancels them.
        let centred = self.triple(actual, k, k);
        let beside = if ahead {
            self.triple(actual, k - 1, k)
        } else {
            self.triple(actual, k + 1, k)
        };
        let result = match (centred, beside) {
            (Some(a), Some(b)) => local_circle::mean(a, b),
            (Some(e), None) | (None, Some(e)) => e,
            // Rε is the oldest sample: the circle (Rε, Rε+1, Rε+2); len ≥ 3 guarantees it.
            (None, None) => self
                .triple(actual, k.saturating_sub(1), k)
                .unwrap_or_default(),
        };
        self.measure_ahead();
        result
    }

    fn reset(&mut self) {
        self.head = 0;
        self.len = 0;
        self.circles.fill(KeptCircle::Unmeasured);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math;

    #[test]
    fn circle_samples_give_exact_radial_error() {
        // On a circle the fitted circles are the circle itself: exact for any lag.
        let c = |t: f64| Vector2::new(3.0 + 20.0 * math::cos(t), 1.0 + 20.0 * math::sin(t));
        let mut e = FreeCurveEstimator::new(16);
        for i in 0..40 {
            let t = i as f64 * 0.005;
            let lag = t - 0.0123;
            let p = Vector2::new(3.0 + 20.03 * math::cos(lag), 1.0 + 20.03 * math::sin(lag));
            let r = e.estimate(c(t), p);
            if i >= 3 {
                assert!((r.error - 0.03).abs() < 1e-12, "i={i}: {}", r.error);
                let n = Vector2::new(-math::cos(lag), -math::sin(lag));
                assert!((r.normal[0] - n[0]).abs() < 1e-9 && (r.normal[1] - n[1]).abs() < 1e-9);
            }
        }
        assert_eq!(e.len(), 16);
    }

    /// The chords are not saved: a restored estimator measures them again, as `push`
    /// did, and goes on bit for bit (also after the ring wrapped).
    #[test]
    fn a_restored_estimator_goes_on_bit_for_bit() {
        let c = |t: f64| Vector2::new(20.0 * math::cos(t), 7.0 * math::sin(2.0 * t));
        let mut original = FreeCurveEstimator::new(8);
        let run = |e: &mut FreeCurveEstimator, from: usize, to: usize| -> Vec<(u64, u64, u64)> {
            (from..to)
                .map(|i| {
                    let t = i as f64 * 0.01;
                    let r = e.estimate(c(t), c(t - 0.035) * 1.001);
                    (
                        r.error.to_bits(),
                        r.normal[0].to_bits(),
                        r.normal[1].to_bits(),
                    )
                })
                .collect()
        };
        run(&mut original, 0, 21);
        // postcard, as the FMUs' saved states.
        let bytes = postcard::to_stdvec(&original).unwrap();
        let mut restored: FreeCurveEstimator = postcard::from_bytes(&bytes).unwrap();
        assert_eq!(restored, original);
        assert_eq!(run(&mut restored, 21, 60), run(&mut original, 21, 60));
    }

    /// Every circle the estimator kept is the one its samples give now: made when its
    /// newest sample came, never left from samples the ring has since overwritten, held
    /// back or reset; and one made after a restore is the same.
    #[test]
    fn kept_circles_are_those_of_the_samples_now() {
        fn check(e: &FreeCurveEstimator) {
            for m in 1..e.len().saturating_sub(1) {
                let (pts, chords) = e.around(m);
                match e.circles[e.index(m)] {
                    KeptCircle::Measured(kept) => assert_eq!(kept, e.measure_circle(m), "m = {m}"),
                    KeptCircle::Started(kept) => {
                        assert_eq!(kept, SampleCircle::start(pts, chords), "m = {m}")
                    }
                    KeptCircle::Unmeasured => {}
                }
            }
        }
        let c = |t: f64| Vector2::new(20.0 * math::cos(t), 7.0 * math::sin(2.0 * t));
        let mut e = FreeCurveEstimator::new(6);
        for i in 0..80 {
            // Held references now and then (the ring keeps one), a reset halfway.
            let t = if i % 7 == 3 { (i - 1) as f64 } else { i as f64 } * 0.01;
            if i == 40 {
                e.reset();
            }
            let r = e.estimate(c(t), c(t - 0.03) * 1.002);
            check(&e);
            if i % 9 == 0 {
                let bytes = postcard::to_stdvec(&e).unwrap();
                let mut restored: FreeCurveEstimator = postcard::from_bytes(&bytes).unwrap();
                let again = restored.estimate(c(t), c(t - 0.03) * 1.002);
                let mut original = e.clone();
                let next = original.estimate(c(t), c(t - 0.03) * 1.002);
                assert_eq!(again, next);
                check(&restored);
                assert!(r.error.is_finite());
            }
        }
        // After the last sample: the circle around the sample before the newest started,
        // every older one measured.
        assert!(matches!(e.circles[e.index(1)], KeptCircle::Started(_)));
        assert!((2..e.len() - 1).all(|m| matches!(e.circles[e.index(m)], KeptCircle::Measured(_))));
    }

    /// With a lag longer than the buffer the walk stops at the oldest sample, where only
    /// the circle on the newer side exists; on a circle that circle is still the path, so
    /// the estimate stays exact (the fallback branch of `estimate`).
    #[test]
    fn a_lag_beyond_the_buffer_uses_the_oldest_circle() {
        let c = |t: f64| Vector2::new(20.0 * math::cos(t), 20.0 * math::sin(t));
        let mut e = FreeCurveEstimator::new(MIN_CAPACITY);
        for i in 0..30 {
            let t = i as f64 * 0.01;
            let lag = t - 0.2; // 20 samples behind, the buffer holds 4
            let p = Vector2::new(19.95 * math::cos(lag), 19.95 * math::sin(lag));
            let r = e.estimate(c(t), p);
            if i >= 3 {
                assert!((r.error + 0.05).abs() < 1e-12, "i={i}: {}", r.error);
                let n = Vector2::new(-math::cos(lag), -math::sin(lag)); // inward: the left normal of a CCW circle
                assert!((r.normal[0] - n[0]).abs() < 1e-9 && (r.normal[1] - n[1]).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn collinear_and_held_reference() {
        let mut e = FreeCurveEstimator::new(8);
        assert_eq!(
            e.estimate(Vector2::new(0.0, 0.0), Vector2::new(0.0, 0.0))
                .error,
            0.0
        );
        for i in 1..20 {
            let x = i as f64 * 0.1;
            let r = e.estimate(
                Vector2::new(x, 2.0 * x),
                Vector2::new(x - 0.2 + 0.002, 2.0 * x - 0.4 - 0.001),
            );
            // Offset (0.002, −0.001) is √5·0.001 right of the direction (1, 2)/√5.
            assert!((r.error - 5f64.sqrt() * 1e-3).abs() < 1e-14, "{}", r.error);
        }
        // Held reference (path end): no duplicate samples, estimate stays finite.
        for _ in 0..20 {
            let r = e.estimate(Vector2::new(1.9, 3.8), Vector2::new(1.9, 3.7));
            assert!(r.error.is_finite() && r.normal[0].is_finite());
        }
        e.reset();
        assert!(e.is_empty());
    }

    #[test]
    fn state_round_trip_rejects_corruption() {
        let mut e = FreeCurveEstimator::new(5);
        for i in 0..7 {
            e.estimate(Vector2::new(i as f64, 0.0), Vector2::new(0.0, 0.0));
        }
        let blob = postcard::to_stdvec(&e).unwrap();
        let back: FreeCurveEstimator = postcard::from_bytes(&blob).unwrap();
        assert_eq!(back, e);
        let bad = FreeCurveData {
            buf: vec![Vector2::zeros(); 5],
            head: 9,
            len: 2,
        };
        let blob = postcard::to_stdvec(&bad).unwrap();
        assert!(postcard::from_bytes::<FreeCurveEstimator>(&blob).is_err());
    }
}
