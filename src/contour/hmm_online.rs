//! The online form of the HMM segment mapping (docs/design.md §5.2): the reference and
//! the measured samples arrive one at a time. Only the `band` newest segments are
//! candidates, and a sample's mapping can be read back `lag` samples later, so the work
//! per sample is O(band·max_skip + lag) whatever the path's length, and nothing is
//! allocated after construction (every buffer is a ring of fixed size).
//!
//! With a band covering the whole reference and a lag covering the whole run it decodes
//! what [`viterbi_offline`](super::hmm::viterbi_offline) decodes.

use super::hmm::{segment_cost, HmmParams};
use crate::geometry::Vector;
use crate::kinematics::Pose;

/// The online decoder.
#[derive(Clone, Debug)]
pub struct OnlineMapper {
    params: HmmParams,
    length: f64,
    band: usize,
    lag: usize,
    /// The newest `band + 1` reference tips, unit axes and second points (index mod
    /// `band + 1`).
    tips: Vec<Vector<3>>,
    axes: Vec<Vector<3>>,
    seconds: Vec<Vector<3>>,
    references: usize,
    /// C(k, j) of the latest sample for j in `valid` (index j mod band).
    cost: Vec<f64>,
    next: Vec<f64>,
    valid: (usize, usize),
    /// Predecessors (absolute segments) of the last `lag + 1` samples: row k mod
    /// (lag + 1), column j mod band.
    back: Vec<usize>,
    samples: usize,
    previous_tip: Option<Vector<3>>,
}

impl OnlineMapper {
    /// A decoder over the `band` (≥ 1) newest segments that can read back `lag` samples;
    /// `length` is the tool length of the second points, mm.
    pub fn new(params: HmmParams, length: f64, band: usize, lag: usize) -> Self {
        let band = band.max(1);
        OnlineMapper {
            params,
            length,
            band,
            lag,
            tips: vec![Vector::zeros(); band + 1],
            axes: vec![Vector::zeros(); band + 1],
            seconds: vec![Vector::zeros(); band + 1],
            references: 0,
            cost: vec![f64::INFINITY; band],
            next: vec![f64::INFINITY; band],
            valid: (0, 0),
            back: vec![0; (lag + 1) * band],
            samples: 0,
            previous_tip: None,
        }
    }

    /// Appends the next reference point (tip and unit tool axis).
    pub fn push_reference(&mut self, tip: Vector<3>, axis: Vector<3>) {
        let slot = self.references % (self.band + 1);
        self.tips[slot] = tip;
        self.axes[slot] = axis;
        self.seconds[slot] = tip + axis * self.length;
        self.references += 1;
    }

    /// Reference points pushed so far.
    pub fn references(&self) -> usize {
        self.references
    }

    /// The end poses of segment `j` while it is still held (one of the `band` newest).
    pub fn segment(&self, j: usize) -> Option<(Pose, Pose)> {
        let held = self.references.saturating_sub(self.band + 1);
        if j < held || j + 1 >= self.references {
            return None;
        }
        let ring = self.band + 1;
        let pose = |i: usize| Pose {
            tip: self.tips[i % ring],
            axis: self.axes[i % ring],
        };
        Some((pose(j), pose(j + 1)))
    }

    /// Samples mapped so far.
    pub fn samples(&self) -> usize {
        self.samples
    }

    fn cost_of(&self, j: usize, tip: &Vector<3>, second: &Vector<3>, motion: &Vector<3>) -> f64 {
        let ring = self.band + 1;
        let (a, b) = (j % ring, (j + 1) % ring);
        segment_cost(
            &self.params,
            [&self.tips[a], &self.tips[b]],
            [&self.seconds[a], &self.seconds[b]],
            tip,
            second,
            motion,
        )
    }

    /// Maps the next measured sample (tip and unit tool axis); returns the best segment
    /// for it now, or `None` while the reference has no segment.
    pub fn push_sample(&mut self, tip: Vector<3>, axis: Vector<3>) -> Option<usize> {
        let hi = self.references.saturating_sub(1);
        let lo = hi.saturating_sub(self.band);
        if hi == lo {
            return None;
        }
        let second = tip + axis * self.length;
        let motion = self.previous_tip.map_or(Vector::zeros(), |p| tip - p);
        let row = (self.samples % (self.lag + 1)) * self.band;
        let (vlo, vhi) = self.valid;
        let mut reachable = false;
        for j in lo..hi {
            let c = self.cost_of(j, &tip, &second, &motion);
            let mut best = (f64::INFINITY, j);
            if self.samples > 0 {
                for i in
                    j.saturating_sub(self.params.max_skip).max(vlo)..=j.min(vhi.wrapping_sub(1))
                {
                    let ci = self.cost[i % self.band];
                    if ci < best.0 {
                        best = (ci, i);
                    }
                }
            }
            reachable |= best.0.is_finite();
            self.next[j % self.band] = best.0 + c;
            self.back[row + j % self.band] = best.1;
        }
        if !reachable {
            // The first sample, or the band ran past every path: start afresh (any
            // segment, no history).
            for j in lo..hi {
                self.next[j % self.band] = self.cost_of(j, &tip, &second, &motion);
                self.back[row + j % self.band] = j;
            }
        }
        std::mem::swap(&mut self.cost, &mut self.next);
        self.valid = (lo, hi);
        self.samples += 1;
        self.previous_tip = Some(tip);
        Some(self.best())
    }

    /// The segment of least cost for the newest sample (ties to the lower segment).
    fn best(&self) -> usize {
        let (lo, hi) = self.valid;
        (lo..hi).fold(lo, |best, j| {
            if self.cost[j % self.band] < self.cost[best % self.band] {
                j
            } else {
                best
            }
        })
    }

    /// The mapping of the sample `steps` before the newest (0 = the newest), along the
    /// best path to the newest: `None` beyond the lag or before the first sample.
    pub fn mapped(&self, steps: usize) -> Option<usize> {
        if self.samples == 0 || steps > self.lag || steps >= self.samples {
            return None;
        }
        let mut j = self.best();
        for s in 0..steps {
            let k = self.samples - 1 - s;
            j = self.back[(k % (self.lag + 1)) * self.band + j % self.band];
        }
        Some(j)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contour::hmm::{viterbi_offline, ReferencePolyline};

    type V3 = Vector<3>;

    fn spiral(n: usize) -> (Vec<V3>, Vec<V3>) {
        let tips = (0..n)
            .map(|j| {
                let t = j as f64 * 0.15;
                V3::new(30.0 * t.cos(), 30.0 * t.sin(), 0.5 * t)
            })
            .collect();
        let axes = (0..n)
            .map(|j| {
                let lean = 0.4 * (j as f64 * 0.05).sin();
                V3::new(lean.sin(), 0.0, lean.cos())
            })
            .collect();
        (tips, axes)
    }

    #[test]
    fn with_everything_in_view_it_decodes_as_offline() {
        let params = HmmParams {
            max_skip: 2,
            angle_weight: 0.7,
        };
        let (tips, axes) = spiral(30);
        let run: Vec<V3> = tips.iter().map(|p| p + V3::new(0.3, -0.2, 0.1)).collect();
        let n = 25;
        let reference = ReferencePolyline::new(&tips, &axes, 80.0);
        let seconds: Vec<V3> = run.iter().zip(&axes).map(|(p, o)| p + o * 80.0).collect();
        let offline = viterbi_offline(&reference, &params, &run[..n], &seconds[..n]);
        let mut online = OnlineMapper::new(params, 80.0, 40, 40);
        for (p, o) in tips.iter().zip(&axes) {
            online.push_reference(*p, *o);
        }
        for k in 0..n {
            online.push_sample(run[k], axes[k]);
        }
        for (k, &j) in offline.iter().enumerate() {
            assert_eq!(online.mapped(n - 1 - k), Some(j), "sample {k}");
        }
    }

    #[test]
    fn streaming_with_a_band_and_a_lag_commits_what_offline_decodes() {
        // The reference runs 12 samples ahead of the measured tool (a following error),
        // a band of 24 segments and a lag of 8 samples: every committed decision equals
        // the offline decoding of the same data.
        let params = HmmParams {
            max_skip: 1,
            angle_weight: 1.0,
        };
        let (tips, axes) = spiral(400);
        let lead = 12;
        let run: Vec<V3> = tips.iter().map(|p| p + V3::new(0.0, 0.1, -0.05)).collect();
        let n = tips.len() - lead;
        let reference = ReferencePolyline::new(&tips, &axes, 80.0);
        let seconds: Vec<V3> = run.iter().zip(&axes).map(|(p, o)| p + o * 80.0).collect();
        let offline = viterbi_offline(&reference, &params, &run[..n], &seconds[..n]);
        let (band, lag) = (24, 8);
        let mut online = OnlineMapper::new(params, 80.0, band, lag);
        for j in 0..lead {
            online.push_reference(tips[j], axes[j]);
        }
        let mut committed = 0;
        for k in 0..n {
            online.push_reference(tips[k + lead], axes[k + lead]);
            online.push_sample(run[k], axes[k]);
            if k >= lag {
                assert_eq!(
                    online.mapped(lag),
                    Some(offline[k - lag]),
                    "sample {}",
                    k - lag
                );
                committed += 1;
            }
        }
        assert_eq!(committed, n - lag);
        assert!(online.mapped(lag + 1).is_none());
        // The band's segments are held with their poses, older ones are gone.
        let newest = tips.len() - 2;
        let (a, b) = online.segment(newest).unwrap();
        assert_eq!(
            (a.tip, b.tip, b.axis),
            (tips[newest], tips[newest + 1], axes[newest + 1])
        );
        assert!(online.segment(newest + 1 - band).is_some());
        assert!(online.segment(newest - band).is_none() && online.segment(newest + 1).is_none());
    }
}
