//! The five-axis reference as the interpolator FMU and the in-process loop run it: at a
//! constant tip feed with the joints from the inverse kinematics (`accel` = 0, the
//! reference before limits, docs/design/five-axis.md §5.3a), or planned within the
//! machine's limits (§5.3b).

use serde::{Deserialize, Serialize};

use super::planned_reference::{PlannedFiveAxisReference, SavedPlannedReference};
use super::planner::{FiveAxisInputs, Planner};
use super::JointReference;
use crate::kinematics::Joints;
use crate::path::PathError;

/// A five-axis reference. The whole value is the state an FMU saves; it is restored as a
/// [`SavedFiveAxisReference`], which plans again through a [`Planner`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FiveAxisReference {
    kind: Kind,
    /// The joints one sample before the current one (the current ones at the start):
    /// the velocity's central difference needs them.
    previous: Joints,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[allow(clippy::large_enum_variant)] // one per instance
enum Kind {
    /// The tip at constant feed, the joints on the A ≥ 0 branch.
    ConstantFeed(JointReference),
    /// Planned within the limits.
    Planned(PlannedFiveAxisReference),
}

/// A saved [`FiveAxisReference`] as read back (the same layout), before it is planned
/// again by [`SavedFiveAxisReference::resume`].
#[derive(Deserialize)]
pub struct SavedFiveAxisReference {
    kind: SavedKind,
    previous: Joints,
}

#[derive(Deserialize)]
#[allow(clippy::large_enum_variant)] // one per restore
enum SavedKind {
    ConstantFeed(JointReference),
    Planned(SavedPlannedReference),
}

impl SavedFiveAxisReference {
    /// The reference, its plan found or made again by `planner` and the saved place
    /// checked against it.
    pub fn resume(self, planner: &Planner) -> Result<FiveAxisReference, String> {
        let kind = match self.kind {
            SavedKind::ConstantFeed(r) => Kind::ConstantFeed(r),
            SavedKind::Planned(r) => Kind::Planned(r.resume(planner)?),
        };
        Ok(FiveAxisReference {
            kind,
            previous: self.previous,
        })
    }
}

/// One sample of a [`FiveAxisReference`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceSample {
    /// The joints (mm, rad).
    pub joints: Joints,
    /// The programmed path's parameter where the reference stands (a hint for the
    /// truth's nearest-point search).
    pub u: f64,
    /// Whether the reference rests at the path's end.
    pub done: bool,
    /// The planned tip's distance from the programmed path, mm (0 without a plan).
    pub tip_deviation: f64,
    /// The planned tool axis's angle from the programmed one, rad (0 without a plan).
    pub orientation_deviation: f64,
}

impl FiveAxisReference {
    /// The reference of `inputs`: planned by `planner` within the joints' and the path's
    /// limits when `limits.accel` > 0, else at the constant feed `limits.feed`. `name`
    /// names a programmed pose in a planner's refusal.
    pub fn new(
        inputs: FiveAxisInputs,
        planner: &Planner,
        name: &dyn Fn(usize) -> String,
    ) -> Result<Self, PathError> {
        super::joint_reference::check_length(&inputs.path)?;
        if inputs.limits.accel > 0.0 {
            return Ok(Self::starting(Kind::Planned(
                PlannedFiveAxisReference::new(inputs, planner, name)?,
            )));
        }
        let FiveAxisInputs {
            path,
            builtin,
            machine,
            limits,
            ts,
            ..
        } = inputs;
        Ok(Self::starting(Kind::ConstantFeed(match builtin {
            Some(name) => JointReference::builtin(&name, machine, limits.feed, ts)?,
            None => JointReference::new(path, machine, limits.feed, ts)?,
        })))
    }

    fn starting(kind: Kind) -> Self {
        let first = kind.joints();
        // A plan starts at rest: the sample before is the first one. At constant feed the
        // tip starts at the feed: the sample before is the quadratic through the first
        // three extended back, so the central differences at the first sample are the
        // second-order forward ones (q(−1) = q(0) would give half the feed and a spike
        // of v/Ts in the acceleration).
        let previous = match &kind {
            Kind::Planned(_) => first,
            Kind::ConstantFeed(r) => {
                // A copy of the reference, once at initialization.
                let mut ahead = r.clone();
                let second = ahead.step().map_or(first, |s| s.joints);
                let third = ahead.step().map_or(second, |s| s.joints);
                first * 3.0 - second * 3.0 + third
            }
        };
        FiveAxisReference { kind, previous }
    }

    /// The current sample.
    pub fn current(&mut self) -> ReferenceSample {
        self.kind.current()
    }

    /// The reference's joint velocities (mm/s, rad/s) and accelerations (mm/s², rad/s²)
    /// at the current sample: the central differences (q(k+1) − q(k−1))/(2·Ts) and
    /// (q(k+1) − 2·q(k) + q(k−1))/Ts², the derivatives of the samples to O(Ts²) and not a
    /// sample late as a backward difference would be (see [`Self::starting`] for the
    /// first sample); both 0 once the reference rests at its end.
    pub fn derivatives(&self) -> (Joints, Joints) {
        if self.kind.done() {
            return (Joints::zeros(), Joints::zeros());
        }
        let (next, ts) = match &self.kind {
            Kind::ConstantFeed(r) => (r.peek(), r.ts()),
            Kind::Planned(r) => (r.peek(), r.inputs().ts),
        };
        let now = self.kind.joints();
        (
            (next - self.previous) / (2.0 * ts),
            (next - now * 2.0 + self.previous) / (ts * ts),
        )
    }

    /// Advances one period.
    pub fn step(&mut self) -> Result<ReferenceSample, PathError> {
        self.previous = self.kind.joints();
        match &mut self.kind {
            Kind::ConstantFeed(r) => {
                r.step()?;
            }
            Kind::Planned(r) => {
                r.step();
            }
        }
        Ok(self.current())
    }

    /// The planned duration, s (`None` without a plan).
    pub fn planned_duration(&self) -> Option<f64> {
        match &self.kind {
            Kind::ConstantFeed(_) => None,
            Kind::Planned(r) => Some(r.plan().report().duration),
        }
    }

    /// Checks a reference restored from bytes against the sample period `ts` (a plan
    /// checked its place when it was restored).
    pub fn check(&self, ts: f64) -> Result<(), String> {
        if !crate::geometry::is_finite(&self.previous) {
            return Err("the previous sample's joints are not finite".into());
        }
        match &self.kind {
            Kind::ConstantFeed(r) => r.check(ts),
            Kind::Planned(r) => {
                let period = r.inputs().ts;
                if period != ts {
                    return Err(format!(
                        "the plan's period {period} s differs from the sample clock's {ts} s"
                    ));
                }
                Ok(())
            }
        }
    }
}

impl Kind {
    fn joints(&self) -> Joints {
        match self {
            Kind::ConstantFeed(r) => r.joints(),
            Kind::Planned(r) => r.joints(),
        }
    }

    fn done(&self) -> bool {
        match self {
            Kind::ConstantFeed(r) => r.is_done(),
            Kind::Planned(r) => r.is_done(),
        }
    }

    fn current(&mut self) -> ReferenceSample {
        match self {
            Kind::ConstantFeed(r) => {
                let s = r.current();
                ReferenceSample {
                    joints: s.joints,
                    u: s.u,
                    done: s.done,
                    tip_deviation: 0.0,
                    orientation_deviation: 0.0,
                }
            }
            Kind::Planned(r) => {
                let s = r.current();
                ReferenceSample {
                    joints: s.joints,
                    u: r.path_parameter(s.source),
                    done: s.done,
                    tip_deviation: s.tip_deviation,
                    orientation_deviation: s.orientation_deviation,
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{self, Vector};
    use crate::kinematics::TableTiltingAc;
    use crate::limits::{JointLimits, PathLimits};
    use crate::path::five_axis::ToolPath;

    fn helix(limits: PathLimits) -> FiveAxisInputs {
        FiveAxisInputs {
            path: ToolPath::builtin("tilted_helix").unwrap(),
            builtin: Some("tilted_helix".into()),
            feeds: Vec::new(),
            machine: TableTiltingAc::ORIGIN,
            joints: JointLimits::DEFAULT,
            limits,
            ts: 1e-3,
        }
    }

    fn reference(accel: f64) -> FiveAxisReference {
        let limits = PathLimits {
            accel,
            ..PathLimits::at_feed(50.0)
        };
        FiveAxisReference::new(helix(limits), &Planner::new(), &|i| format!("pose {i}")).unwrap()
    }

    #[test]
    fn a_saved_reference_resumes_on_the_kept_plan_and_continues_alike() {
        let planner = Planner::new();
        for accel in [0.0, 2000.0] {
            let limits = PathLimits {
                accel,
                ..PathLimits::at_feed(50.0)
            };
            let mut r =
                FiveAxisReference::new(helix(limits), &planner, &|i| format!("pose {i}")).unwrap();
            for _ in 0..500 {
                r.step().unwrap();
            }
            let bytes = postcard::to_stdvec(&r).unwrap();
            let saved: SavedFiveAxisReference = postcard::from_bytes(&bytes).unwrap();
            let mut restored = saved.resume(&planner).unwrap();
            assert_eq!(restored, r);
            if let (Kind::Planned(a), Kind::Planned(b)) = (&r.kind, &restored.kind) {
                assert!(std::sync::Arc::ptr_eq(a.plan(), b.plan()), "planned again");
            }
            for _ in 0..300 {
                assert_eq!(r.step().unwrap(), restored.step().unwrap());
            }
        }
    }

    /// The tip's speed in the workpiece frame when the joints move at `qdot`.
    fn tip_speed(q: &Joints, qdot: &Joints) -> f64 {
        let moved = TableTiltingAc::ORIGIN.jacobian(q) * qdot;
        geometry::norm(&Vector::<3>::new(moved[0], moved[1], moved[2]))
    }

    #[test]
    fn the_derivatives_are_the_samples_central_differences_from_start_to_end() {
        for accel in [0.0, 2000.0] {
            let mut r = reference(accel);
            let ts = 1e-3;
            let mut samples = vec![r.current().joints];
            let mut derivatives = vec![r.derivatives()];
            while !r.current().done {
                let next = match &r.kind {
                    Kind::ConstantFeed(j) => j.peek(),
                    Kind::Planned(p) => p.peek(),
                };
                let sample = r.step().unwrap();
                // Peeking says what the step gives.
                assert_eq!(next, sample.joints);
                samples.push(sample.joints);
                derivatives.push(r.derivatives());
            }
            let n = samples.len();
            for k in 1..n - 1 {
                let (v, a) = derivatives[k];
                let central = (samples[k + 1] - samples[k - 1]) / (2.0 * ts);
                let second = (samples[k + 1] - samples[k] * 2.0 + samples[k - 1]) / (ts * ts);
                assert!(
                    (v - central).amax() < 1e-9 * (1.0 + central.amax()),
                    "{accel} {k}"
                );
                assert!(
                    (a - second).amax() < 1e-6 * (1.0 + second.amax()),
                    "{accel} {k}"
                );
            }
            // At rest at the end.
            assert_eq!(derivatives[n - 1], (Joints::zeros(), Joints::zeros()));
            let (v0, a0) = derivatives[0];
            let (_, a1) = derivatives[1];
            if accel == 0.0 {
                // At constant feed the tip moves at the feed from the first sample on, and
                // the first acceleration is the second's (the helix's), not a start-up
                // spike: second-order forward differences.
                assert!((tip_speed(&samples[0], &v0) - 50.0).abs() < 1e-3);
                assert!((a0 - a1).amax() < 1e-2 * a1.amax(), "{a0} {a1}");
            } else {
                // A plan starts at rest: the raw samples' first move, a·Ts²/2, averaged
                // over the filter's m1 = a/(j·Ts) samples, is j·Ts³/2 at most, so the
                // central difference over 2·Ts is below j·Ts²/4 (0.025 mm/s).
                let jerk = PathLimits::at_feed(50.0).jerk;
                assert!(tip_speed(&samples[0], &v0) < jerk * 1e-6 / 4.0);
            }
        }
    }
}
