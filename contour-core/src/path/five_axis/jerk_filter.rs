//! The jerk filter of a planned reference (docs/design/five-axis.md §5.3b): two moving
//! averages in series, of `m1` and `m2` samples, over the raw samples of a
//! velocity-and-acceleration plan. An average of samples within limits is within them:
//! every joint keeps its travel, velocity and acceleration limits, while a step of
//! acceleration ΔA becomes a ramp of jerk ΔA/(m1·Ts), and the one-sample spike a small
//! kink of the path gives is spread over (m1 + m2)·Ts.
//!
//! The sums are kept exact, in integers of 2⁻³⁰ (about 1 pm or 1 nrad) from an origin
//! (the path's end, which the filter therefore reaches exactly): the filter costs O(1) per
//! sample, never drifts however long the path, and a restored state continues bit for
//! bit.

use serde::{Deserialize, Serialize};

use crate::geometry::Vector;

/// Quanta per unit (mm or rad).
const SCALE: f64 = (1u64 << 30) as f64;

/// The most quanta a raw sample may count from the origin in a restored filter: 2⁹⁰,
/// 10¹⁸ mm, beyond any path. A fuzzed state with samples near the i128 range, and sums
/// that agree with them, overflowed on its next sample.
const MAX_QUANTA: i128 = 1 << 90;
/// The farthest origin a restored filter may count from, mm or rad (10¹⁸).
const MAX_ORIGIN: f64 = 1e18;

/// Two moving averages in series over `D`-vectors. The rings are flat, `D` numbers per
/// sample, allocated once.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JerkFilter<const D: usize> {
    /// The last `m1` raw samples, quantised.
    raw: Vec<i128>,
    /// The last `m2` sums of the first stage.
    sums: Vec<i128>,
    /// The current sums of the two stages.
    first: Vec<i128>,
    second: Vec<i128>,
    /// The next slot of each ring, in samples.
    at: (usize, usize),
    /// What the quanta count from.
    origin: Vec<f64>,
}

fn quantise(v: f64) -> i128 {
    (v * SCALE).round() as i128
}

impl<const D: usize> JerkFilter<D> {
    /// A filter of `m1` then `m2` samples (each ≥ 1; 1 passes samples through) at rest at
    /// `start`, counting from `origin` (a sample equal to it comes out exactly).
    pub fn new(m1: usize, m2: usize, start: &Vector<D>, origin: &Vector<D>) -> Self {
        let (m1, m2) = (m1.max(1), m2.max(1));
        let q: Vec<i128> = (0..D).map(|d| quantise(start[d] - origin[d])).collect();
        let first: Vec<i128> = q.iter().map(|v| v * m1 as i128).collect();
        JerkFilter {
            raw: q.repeat(m1),
            sums: first.repeat(m2),
            second: first.iter().map(|v| v * m2 as i128).collect(),
            first,
            at: (0, 0),
            origin: origin.iter().copied().collect(),
        }
    }

    /// The lengths of the two averages, samples.
    pub fn lengths(&self) -> (usize, usize) {
        (self.raw.len() / D.max(1), self.sums.len() / D.max(1))
    }

    /// Takes the next raw sample and gives the next filtered one.
    pub fn push(&mut self, sample: &Vector<D>) -> Vector<D> {
        let (m1, m2) = self.lengths();
        let (i, j) = self.at;
        for d in 0..D {
            let q = quantise(sample[d] - self.origin[d]);
            let (first, second) = self.sums_with(d, q);
            self.raw[i * D + d] = q;
            self.sums[j * D + d] = first;
            (self.first[d], self.second[d]) = (first, second);
        }
        self.at = ((i + 1) % m1, (j + 1) % m2);
        self.output()
    }

    /// The filtered sample [`Self::push`] would give for `sample`, the filter unchanged
    /// (the reference's velocity looks one sample ahead).
    pub fn peek(&self, sample: &Vector<D>) -> Vector<D> {
        Vector::<D>::from_fn(|d, _| {
            let (_, second) = self.sums_with(d, quantise(sample[d] - self.origin[d]));
            self.value(d, second)
        })
    }

    /// The two stages' sums of component `d` once its next raw sample is `q` quanta.
    fn sums_with(&self, d: usize, q: i128) -> (i128, i128) {
        let (i, j) = self.at;
        let first = self.first[d] + q - self.raw[i * D + d];
        (first, self.second[d] + first - self.sums[j * D + d])
    }

    /// Component `d` of the filtered sample whose second-stage sum is `second`.
    fn value(&self, d: usize, second: i128) -> f64 {
        let (m1, m2) = self.lengths();
        self.origin[d] + second as f64 / ((m1 * m2) as f64 * SCALE)
    }

    /// The current filtered sample.
    pub fn output(&self) -> Vector<D> {
        Vector::<D>::from_fn(|d, _| self.value(d, self.second[d]))
    }

    /// Checks a filter restored from bytes: rings of whole samples, at least one each,
    /// the slots inside them, and the sums those of the rings (a state that says
    /// otherwise would drift from the raw samples for good).
    pub fn check(&self) -> Result<(), String> {
        let (m1, m2) = self.lengths();
        let whole = self.raw.len() == m1 * D
            && self.sums.len() == m2 * D
            && self.first.len() == D
            && self.second.len() == D
            && self.origin.len() == D
            && self.origin.iter().all(|v| v.is_finite());
        if !whole || m1 == 0 || m2 == 0 || self.at.0 >= m1 || self.at.1 >= m2 {
            return Err("the jerk filter's rings are empty or its slots outside them".into());
        }
        // A new sample counts from the origin: beyond 10¹⁸ its quanta would overflow too.
        if self.raw.iter().any(|q| q.abs() > MAX_QUANTA)
            || self.origin.iter().any(|v| v.abs() > MAX_ORIGIN)
        {
            return Err("the jerk filter's samples or origin lie beyond 10^18".into());
        }
        // Checked: the stage-one sums are not bounded yet.
        fn total(mut values: impl Iterator<Item = i128>) -> Option<i128> {
            values.try_fold(0i128, |sum, v| sum.checked_add(v))
        }
        for d in 0..D {
            let first = total((0..m1).map(|k| self.raw[k * D + d]));
            let second = total((0..m2).map(|k| self.sums[k * D + d]));
            // The newest stage-one sum is `first`.
            let newest = self.sums[((self.at.1 + m2 - 1) % m2) * D + d];
            if first != Some(self.first[d])
                || second != Some(self.second[d])
                || Some(newest) != first
            {
                return Err("the jerk filter's sums disagree with its rings".into());
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_restored_filter_with_samples_near_the_integer_range_is_refused() {
        // The fuzz finding: rings and sums that agree, samples at 2^100 quanta.
        let mut f = JerkFilter::<1>::new(2, 1, &V1::new(0.0), &V1::new(0.0));
        let q = 1i128 << 100;
        f.raw = vec![q, q];
        f.first = vec![2 * q];
        f.sums = vec![2 * q];
        f.second = vec![2 * q];
        assert!(f.check().unwrap_err().contains("beyond"));
        // An origin far away makes the next sample's quanta overflow just the same.
        let mut far = JerkFilter::<1>::new(2, 1, &V1::new(0.0), &V1::new(0.0));
        far.origin = vec![1e300];
        assert!(far.check().unwrap_err().contains("beyond"));
        // Within the bound the same shape is accepted and steps.
        let q = 1i128 << 80;
        f.raw = vec![q, q];
        f.first = vec![2 * q];
        f.sums = vec![2 * q];
        f.second = vec![2 * q];
        assert!(f.check().is_ok());
        let out = f.push(&V1::new(0.0));
        assert_eq!(out[0], (q as f64) / 2.0 / SCALE);
    }

    type V1 = Vector<1>;

    /// The same filter written as the convolution it is: each output the mean over m2
    /// windows of the mean over m1 raw samples (the start repeated before the first).
    fn convolved(raw: &[f64], start: f64, m1: usize, m2: usize) -> Vec<f64> {
        let at = |k: isize| if k < 0 { start } else { raw[k as usize] };
        (0..raw.len() as isize)
            .map(|k| {
                let mut total = 0.0;
                for j in 0..m2 as isize {
                    for i in 0..m1 as isize {
                        total += at(k - j - i);
                    }
                }
                total / (m1 * m2) as f64
            })
            .collect()
    }

    #[test]
    fn it_is_the_two_box_convolution_and_turns_an_acceleration_step_into_a_ramp() {
        // A trapezoidal velocity profile, sampled positions: accelerate at 1000 mm/s² for
        // 50 samples, cruise, brake.
        let ts = 1e-3;
        let mut raw = Vec::new();
        let (mut p, mut v) = (3.0, 0.0);
        for k in 0..400 {
            let a = if k < 50 {
                1000.0
            } else if (200..250).contains(&k) {
                -1000.0
            } else {
                0.0
            };
            v += a * ts;
            p += v * ts;
            raw.push(p);
        }
        raw.extend(std::iter::repeat_n(p, 100));
        let (m1, m2) = (20, 10);
        let mut filter = JerkFilter::new(m1, m2, &V1::new(3.0), &V1::new(p));
        // Peeking gives what the push gives.
        let out: Vec<f64> = raw
            .iter()
            .map(|&r| {
                let ahead = filter.peek(&V1::new(r));
                let next = filter.push(&V1::new(r))[0];
                assert_eq!(ahead[0], next);
                next
            })
            .collect();
        let reference = convolved(&raw, 3.0, m1, m2);
        for (o, r) in out.iter().zip(&reference) {
            assert!((o - r).abs() < 1e-9, "{o} vs {r}");
        }
        // Jerk of the raw samples: 1000/Ts at each step; filtered: at most 1000/(m1·Ts).
        let jerk = |x: &[f64]| {
            x.windows(4)
                .map(|w| ((w[3] - 3.0 * w[2] + 3.0 * w[1] - w[0]) / ts.powi(3)).abs())
                .fold(0.0, f64::max)
        };
        assert!(jerk(&raw) > 0.9e6);
        assert!(
            jerk(&out) <= 1000.0 / (m1 as f64 * ts) * 1.001,
            "{}",
            jerk(&out)
        );
        // Speed and acceleration stay within the raw ones.
        let accel = |x: &[f64]| {
            x.windows(3)
                .map(|w| ((w[2] - 2.0 * w[1] + w[0]) / ts / ts).abs())
                .fold(0.0, f64::max)
        };
        assert!(accel(&out) <= accel(&raw) * 1.0001);
        // It ends at rest exactly on the end (its origin), and the state continues bit
        // for bit.
        assert_eq!(out[out.len() - 1], p);
        let mut copy = filter.clone();
        copy.check().unwrap();
        for k in 0..50 {
            let r = V1::new(p + k as f64);
            assert_eq!(copy.push(&r), filter.push(&r));
        }
    }

    #[test]
    fn a_state_whose_sums_disagree_is_refused() {
        let mut filter = JerkFilter::new(3, 2, &Vector::<2>::new(1.0, 2.0), &Vector::<2>::zeros());
        filter.push(&Vector::<2>::new(1.5, 2.5));
        filter.check().unwrap();
        let mut bad = filter.clone();
        bad.first[1] += 1;
        assert!(bad.check().is_err());
        let mut bad = filter.clone();
        bad.at.0 = 3;
        assert!(bad.check().is_err());
    }
}
