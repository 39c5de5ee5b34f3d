//! The evaluation-function estimate (docs/design/five-axis.md §5.3) computed while the run goes on,
//! for the controller's outputs: the offline form (`run_evaluation`) with what a sample
//! stream allows.
//!
//! A measured sample k takes part once the online mapping of it is settled, `lag`
//! samples later (its mapping j is then read back along the best path). Like offline,
//! the sample is a candidate for the reference points i with j − K < i ≤ j + K (K =
//! `max_skip`), and each point keeps its nearest candidate (by tip distance). Point i
//! is closed when a settled mapping reaches i + K: no later sample can be a candidate
//! for it, the mapping only moves forward. Then F is minimised over the parabola
//! through the joints of k − 1, k, k + 1, with λ1, λ2 from the neighbouring reference
//! points and R from the reference received so far (offline: the whole path — online
//! the rest of the path is not known yet; on a part that turns evenly they agree).
//!
//! Fixed-size rings, so nothing is allocated per sample. A point whose nearest sample
//! has already left the joint ring (the tool stood still for longer than the ring) or
//! whose neighbours have left the mapper's band gets no estimate.

use serde::{Deserialize, Serialize};

use super::evaluation::{evaluate, weights, Evaluation};
use super::hmm_online::OnlineMapper;
use crate::geometry::angle_between;
use crate::geometry::{self, Vector};
use crate::kinematics::{Joints, TableTiltingAc};

/// Measured samples kept beyond the decision lag: the nearest sample of a point may be
/// this much older than the settled one, and its successor must still be held.
const EXTRA_SAMPLES: usize = 64;

/// The estimate of one closed reference point.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PointEvaluation {
    /// The reference point's index (among the distinct reference poses received).
    pub point: usize,
    /// The measured sample it was fitted around.
    pub sample: u64,
    /// Estimated tip contour error, mm.
    pub tip: f64,
    /// Estimated orientation contour error, rad.
    pub orientation: f64,
}

/// Online evaluation-function estimates.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OnlineEvaluation {
    /// K: a sample mapped to j is a candidate for points j − K + 1 ..= j + K.
    reach: usize,
    /// Joints and tips of the newest samples, sample k at k & `sample_mask`.
    joints: Vec<Joints>,
    tips: Vec<Vector<3>>,
    sample_mask: usize,
    /// Samples pushed so far.
    samples: u64,
    /// Nearest candidate (squared tip distance, sample) of the open points, point i at
    /// i & `point_mask`; the open points are `first ..`.
    nearest: Vec<Option<(f64, u64)>>,
    point_mask: usize,
    first: usize,
    /// Tip travel (mm) and tool turn (rad) over the reference received so far, up to
    /// point `measured_to`: R = travel / turn.
    travel: f64,
    turn: f64,
    measured_to: usize,
    latest: Option<PointEvaluation>,
}

impl OnlineEvaluation {
    /// For a mapping with largest skip `max_skip` read back `lag` samples late.
    pub fn new(max_skip: usize, lag: usize) -> Self {
        let reach = max_skip.max(1);
        let sample_capacity = (lag + EXTRA_SAMPLES).next_power_of_two();
        let point_capacity = (2 * reach + 2).next_power_of_two();
        OnlineEvaluation {
            reach,
            joints: vec![Joints::zeros(); sample_capacity],
            tips: vec![Vector::zeros(); sample_capacity],
            sample_mask: sample_capacity - 1,
            samples: 0,
            nearest: vec![None; point_capacity],
            point_mask: point_capacity - 1,
            first: 0,
            travel: 0.0,
            turn: 0.0,
            measured_to: 0,
            latest: None,
        }
    }

    /// The newest closed point with an estimate.
    pub fn latest(&self) -> Option<PointEvaluation> {
        self.latest
    }

    /// Samples pushed so far.
    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// The next measured sample (its joints and tip), after `mapper` has mapped it;
    /// `lag` is the delay at which mappings are read back. Returns the newest estimate.
    pub fn push(
        &mut self,
        machine: &TableTiltingAc,
        mapper: &OnlineMapper,
        lag: usize,
        joints: &Joints,
        tip: &Vector<3>,
    ) -> Option<PointEvaluation> {
        let k = self.samples;
        self.joints[k as usize & self.sample_mask] = *joints;
        self.tips[k as usize & self.sample_mask] = *tip;
        self.samples += 1;
        self.measure_reference(mapper);
        let (Some(j), Some(settled)) = (mapper.mapped(lag), k.checked_sub(lag as u64)) else {
            return self.latest;
        };
        // Close the points no later sample can reach, then offer the settled sample to
        // the points it can.
        let close_to = (j + 1).saturating_sub(self.reach);
        if close_to > self.first + self.nearest.len() {
            // The mapping leapt ahead (it re-synchronised): the skipped points have no
            // candidate.
            self.nearest.iter_mut().for_each(|n| *n = None);
            self.first = close_to;
        }
        while self.first < close_to {
            let i = self.first;
            if let Some(e) = self.nearest[i & self.point_mask]
                .take()
                .and_then(|(_, sample)| self.estimate(machine, mapper, i, sample))
            {
                self.latest = Some(e);
            }
            self.first += 1;
        }
        let tip = self.tips[settled as usize & self.sample_mask];
        let last = (j + self.reach).min(self.first + self.nearest.len() - 1);
        for i in self.first..=last {
            let Some(point) = mapper.point(i) else {
                continue;
            };
            let d = geometry::dist2(&tip, &point.tip);
            let slot = &mut self.nearest[i & self.point_mask];
            if slot.is_none_or(|(best, _)| d < best) {
                *slot = Some((d, settled));
            }
        }
        self.latest
    }

    /// Adds the reference received since the last sample to the travel and turn.
    fn measure_reference(&mut self, mapper: &OnlineMapper) {
        while self.measured_to + 1 < mapper.references() {
            if let Some((a, b)) = mapper.segment(self.measured_to) {
                self.travel += geometry::dist(&a.tip, &b.tip);
                self.turn += angle_between(&a.axis, &b.axis);
            }
            self.measured_to += 1;
        }
    }

    /// The estimate at point `i` from the parabola around `sample`.
    fn estimate(
        &self,
        machine: &TableTiltingAc,
        mapper: &OnlineMapper,
        i: usize,
        sample: u64,
    ) -> Option<PointEvaluation> {
        let oldest = self.samples.saturating_sub(self.joints.len() as u64);
        if sample == 0 || sample - 1 < oldest || sample + 1 >= self.samples {
            return None;
        }
        let q = |k: u64| self.joints[k as usize & self.sample_mask];
        let reference = mapper.point(i)?;
        let before = mapper.point(i.saturating_sub(1))?;
        let after = mapper.point(i + 1).unwrap_or(reference);
        let ratio = if self.turn > 0.0 {
            self.travel / self.turn
        } else {
            0.0
        };
        let lambda = weights(&before, &after, ratio);
        let Evaluation {
            tip, orientation, ..
        } = evaluate(
            machine,
            &reference,
            lambda,
            ratio,
            &[q(sample - 1), q(sample), q(sample + 1)],
        );
        Some(PointEvaluation {
            point: i,
            sample,
            tip,
            orientation,
        })
    }

    /// Checks a restored estimator against what `new(max_skip, lag)` builds: ring
    /// sizes, and finite values (the error names the first violation).
    pub fn check(&self, max_skip: usize, lag: usize) -> Result<(), String> {
        let built = OnlineEvaluation::new(max_skip, lag);
        let sizes = |e: &Self| {
            (
                e.reach,
                e.joints.len(),
                e.tips.len(),
                e.sample_mask,
                e.nearest.len(),
                e.point_mask,
            )
        };
        if sizes(self) != sizes(&built) {
            return Err(format!(
                "rings (reach, joints, tips, mask, points, mask) {:?} differ from {:?}",
                sizes(self),
                sizes(&built)
            ));
        }
        let finite = self.joints.iter().all(geometry::is_finite)
            && self.tips.iter().all(geometry::is_finite)
            && self.travel.is_finite()
            && self.turn.is_finite()
            && self.nearest.iter().flatten().all(|(d, _)| d.is_finite());
        if !finite {
            return Err("an evaluation memory value is not finite".into());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contour::five_axis::evaluation::parabola;
    use crate::contour::five_axis::hmm::{viterbi_offline, HmmParams, ReferencePolyline};
    use crate::kinematics::Pose;
    use crate::math;

    type V3 = Vector<3>;

    /// A helix with the tool tilted 20° and turning evenly (so R is the same over every
    /// prefix of the reference), one point per sample; the tool trails by 30 samples,
    /// 0.05 mm out and 1 mrad more tilted, with a slow wobble.
    fn case() -> (TableTiltingAc, Vec<Pose>, Vec<Joints>) {
        let machine = TableTiltingAc {
            a_pivot: V3::new(0.0, 0.0, -40.0),
            c_pivot: V3::new(3.0, -2.0, 0.0),
        };
        let pose = |t: f64, out: f64, tilt: f64| {
            let lean = 20f64.to_radians() + tilt;
            Pose {
                tip: V3::new(
                    (25.0 + out) * math::cos(t),
                    (25.0 + out) * math::sin(t),
                    2.0 * t,
                ),
                axis: V3::new(
                    math::sin(lean) * math::cos(t),
                    math::sin(lean) * math::sin(t),
                    math::cos(lean),
                ),
            }
        };
        let step = 0.002;
        let reference: Vec<Pose> = (0..1500).map(|i| pose(i as f64 * step, 0.0, 0.0)).collect();
        let mut c = 0.0;
        let measured = (0..1500)
            .map(|k| {
                let t = (k as f64 - 30.0).max(0.0) * step;
                let wobble = math::sin(k as f64 * 0.01);
                let q = machine
                    .inverse(&pose(t, 0.05 * wobble, 1e-3 * wobble), c)
                    .unwrap();
                c = q[4];
                q
            })
            .collect();
        (machine, reference, measured)
    }

    #[test]
    fn estimates_use_the_offline_mapping_and_minimise_f_like_a_dense_search() {
        let (machine, reference, measured) = case();
        let (params, length, band, lag) = (
            HmmParams {
                max_skip: 3,
                angle_weight: 0.5,
            },
            100.0,
            128,
            16,
        );
        let mut mapper = OnlineMapper::new(params, length, band, lag).with_beam(5.0);
        let mut online = OnlineEvaluation::new(params.max_skip, lag);
        let mut estimates = Vec::new();
        for (pose, q) in reference.iter().zip(&measured) {
            mapper.push_reference(pose.tip, pose.axis);
            let actual = machine.forward(q);
            mapper.push_sample(actual.tip, actual.axis);
            if let Some(e) = online.push(&machine, &mapper, lag, q, &actual.tip) {
                if estimates.last() != Some(&e) {
                    estimates.push(e);
                }
            }
        }
        // Closed in order; the newest of the points a sample closes is reported (two
        // close together where the mapping moves two segments at once).
        assert!(estimates.len() > 1400, "{}", estimates.len());
        assert!(estimates
            .windows(2)
            .all(|w| (1..=2).contains(&(w[1].point - w[0].point))));

        // The independent reference: the offline mapping of the whole run, each point's
        // nearest candidate, and F minimised over 200 001 points of the parabola.
        let tips: Vec<V3> = reference.iter().map(|p| p.tip).collect();
        let axes: Vec<V3> = reference.iter().map(|p| p.axis).collect();
        let polyline = ReferencePolyline::new(&tips, &axes, length);
        let poses: Vec<Pose> = measured.iter().map(|q| machine.forward(q)).collect();
        let seconds: Vec<V3> = poses.iter().map(|p| p.tip + p.axis * length).collect();
        let ptips: Vec<V3> = poses.iter().map(|p| p.tip).collect();
        let mapping = viterbi_offline(&polyline, &params, &ptips, &seconds);
        let ratio = crate::contour::five_axis::evaluation::mm_per_rad(&reference);
        let mut worst: (f64, f64) = (0.0, 0.0);
        for e in &estimates {
            let i = e.point;
            // Sample 0 arrives with one reference point, no segment: never mapped online.
            let nearest = (1..measured.len())
                .filter(|&k| i + 3 > mapping[k] && i <= mapping[k] + 3)
                .min_by(|&a, &b| {
                    let d = |k: usize| geometry::dist2(&ptips[k], &reference[i].tip);
                    d(a).total_cmp(&d(b))
                })
                .unwrap();
            assert_eq!(e.sample, nearest as u64, "point {i}");
            let q = [
                measured[nearest - 1],
                measured[nearest],
                measured[nearest + 1],
            ];
            let (before, after) = (i.saturating_sub(1), (i + 1).min(reference.len() - 1));
            let lambda = weights(&reference[before], &reference[after], ratio);
            let f = |t: f64| {
                let p = machine.forward(&parabola(&q, t));
                let (tip, angle) = (
                    geometry::dist(&p.tip, &reference[i].tip),
                    angle_between(&p.axis, &reference[i].axis),
                );
                (lambda.0 * tip + lambda.1 * ratio * angle, tip, angle)
            };
            // A grid of 2 001 points, then 2 001 around the best: steps of 1e-6.
            let argmin = |lo: f64, step: f64| {
                (0..=2000)
                    .map(|s| (lo + s as f64 * step).clamp(-1.0, 1.0))
                    .min_by(|a, b| f(*a).0.total_cmp(&f(*b).0))
                    .unwrap()
            };
            let best = f(argmin(argmin(-1.0, 1e-3) - 1e-3, 1e-6));
            worst.0 = worst.0.max((e.tip - best.1).abs());
            worst.1 = worst.1.max((e.orientation - best.2).abs());
        }
        // The grid's own resolution: a step of 1e-6 of a 0.05 mm sample spacing.
        assert!(worst.0 < 1e-7 && worst.1 < 1e-9, "{worst:?}");
        eprintln!("online evaluation vs dense search: {worst:?}");
    }

    #[test]
    fn restored_rings_of_another_size_are_refused() {
        let e = OnlineEvaluation::new(3, 16);
        assert_eq!(e.check(3, 16), Ok(()));
        assert!(e.check(3, 200).unwrap_err().contains("differ"));
        let mut bad = e.clone();
        bad.travel = f64::NAN;
        assert!(bad.check(3, 16).unwrap_err().contains("not finite"));
    }
}
