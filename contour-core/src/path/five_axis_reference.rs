//! The five-axis reference as the interpolator FMU and the in-process loop run it: at a
//! constant tip feed with the joints from the inverse kinematics (`accel` = 0, the
//! reference before limits, docs/design/five-axis.md §5.3a), or planned within the
//! machine's limits (§5.3b).

use serde::{Deserialize, Serialize};

use super::plan::{PlanInputs, PlannedReference};
use super::{JointReference, PathError, ToolPath};
use crate::kinematics::{Joints, TableTiltingAc};
use crate::limits::{JointLimits, PathLimits};

/// A five-axis reference. The whole value is the state an FMU saves.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FiveAxisReference {
    kind: Kind,
    /// The joints one sample before the current one (the current ones at the start):
    /// the velocity's central difference needs them.
    previous: Joints,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[allow(clippy::large_enum_variant)] // one per instance
enum Kind {
    /// The tip at constant feed, the joints on the A ≥ 0 branch.
    ConstantFeed(JointReference),
    /// Planned within the limits.
    Planned(PlannedReference),
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
    /// The reference on `path` (`builtin` its name when it is one) for `machine`: planned
    /// within `joints` and `limits` when `limits.accel` > 0, else at the constant feed
    /// `limits.feed`. `name` names a programmed pose in a planner's refusal.
    pub fn new(
        path: ToolPath,
        builtin: Option<String>,
        machine: TableTiltingAc,
        joints: JointLimits,
        limits: PathLimits,
        ts: f64,
        name: &dyn Fn(usize) -> String,
    ) -> Result<Self, PathError> {
        super::joint_reference::check_length(&path)?;
        if limits.accel > 0.0 {
            let inputs = PlanInputs {
                path,
                builtin,
                machine,
                joints,
                limits,
                ts,
            };
            return Ok(Self::starting(Kind::Planned(PlannedReference::new(
                inputs, name,
            )?)));
        }
        Ok(Self::starting(Kind::ConstantFeed(match builtin {
            Some(name) => JointReference::builtin(&name, machine, limits.feed, ts)?,
            None => JointReference::new(path, machine, limits.feed, ts)?,
        })))
    }

    fn starting(kind: Kind) -> Self {
        let previous = kind.joints();
        FiveAxisReference { kind, previous }
    }

    /// The current sample.
    pub fn current(&mut self) -> ReferenceSample {
        self.kind.current()
    }

    /// The reference's joint velocities at the current sample (mm/s, rad/s): the central
    /// difference (q(k+1) − q(k−1))/(2·Ts), the derivative of the samples to O(Ts²) and
    /// not a sample late as a backward difference would be; at the start q(−1) = q(0).
    pub fn velocity(&self) -> Joints {
        let (next, ts) = self.next();
        (next - self.previous) / (2.0 * ts)
    }

    /// The reference's joint accelerations at the current sample (mm/s², rad/s²): the
    /// central second difference (q(k+1) − 2·q(k) + q(k−1))/Ts².
    pub fn acceleration(&self) -> Joints {
        let (next, ts) = self.next();
        (next - self.kind.joints() * 2.0 + self.previous) / (ts * ts)
    }

    /// The next sample's joints and the sample period.
    fn next(&self) -> (Joints, f64) {
        match &self.kind {
            Kind::ConstantFeed(r) => (r.peek(), r.ts()),
            Kind::Planned(r) => (r.peek(), r.inputs().ts),
        }
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
