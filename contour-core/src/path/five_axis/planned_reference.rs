//! A planned five-axis reference: the plan shared by the instances that run it, with one
//! instance's place on it; saved as the plan's inputs and the place, a built-in by name.

use std::sync::Arc;

use super::plan::{FiveAxisCursor, FiveAxisPlan, PlanSummary, PlannedSample};
use super::planner::{fingerprint, FiveAxisInputs, Planner};
use super::ToolPath;
use crate::geometry;
use crate::kinematics::{Joints, TableTiltingAc};
use crate::limits::{JointLimits, PathLimits};
use crate::path::PathError;

/// A planned reference: the plan shared by the instances that run it, with one
/// instance's place on it.
#[derive(Clone, Debug)]
pub struct PlannedFiveAxisReference {
    inputs: Arc<FiveAxisInputs>,
    plan: Arc<FiveAxisPlan>,
    cursor: FiveAxisCursor,
}

impl PlannedFiveAxisReference {
    /// At the start of the plan for `inputs`.
    pub fn new(
        inputs: FiveAxisInputs,
        planner: &Planner,
        name: &dyn Fn(usize) -> String,
    ) -> Result<Self, PathError> {
        let plan = planner.plan(&inputs, name)?;
        let cursor = plan.start();
        Ok(PlannedFiveAxisReference {
            inputs: Arc::new(inputs),
            plan,
            cursor,
        })
    }

    /// On the plan for `inputs` at a saved `cursor`. What needs no plan is checked first
    /// (so a damaged state costs no planning): the inputs against the `saved`
    /// fingerprint, the cursor's own consistency; then the plan the planner keeps or
    /// makes against the saved summary, and the place against the plan.
    fn resume(
        inputs: FiveAxisInputs,
        cursor: FiveAxisCursor,
        saved: (u64, PlanSummary),
        planner: &Planner,
    ) -> Result<Self, String> {
        let (saved_fingerprint, saved_summary) = saved;
        if fingerprint(&inputs) != saved_fingerprint {
            return Err(
                "the plan's saved inputs do not match their fingerprint: the state \
                        is damaged"
                    .into(),
            );
        }
        cursor.filter.check()?;
        let (m1, m2) = cursor.filter.lengths();
        if (m1 as u64, m2 as u64) != saved_summary.filter {
            return Err(format!(
                "the saved jerk filter has {m1} + {m2} samples, the saved plan {} + {}",
                saved_summary.filter.0, saved_summary.filter.1
            ));
        }
        if cursor.sample > saved_summary.samples || !geometry::is_finite(&cursor.joints) {
            return Err("the saved place lies outside the saved plan".into());
        }
        let plan = planner
            .plan(&inputs, &|i| format!("pose {i}"))
            .map_err(|e| e.to_string())?;
        let summary = plan.summary();
        if summary != saved_summary {
            return Err(format!(
                "the state was saved on a plan of {} samples ({} nodes, a jerk filter of \
                 {} + {}), this build plans {} ({} nodes, {} + {}) from the same inputs: it \
                 was saved by another build",
                saved_summary.samples,
                saved_summary.nodes,
                saved_summary.filter.0,
                saved_summary.filter.1,
                summary.samples,
                summary.nodes,
                summary.filter.0,
                summary.filter.1
            ));
        }
        if cursor.interval + 1 >= plan.path.s.len() || cursor.foot + 1 >= plan.path.s.len() {
            return Err("the saved place lies outside the plan".into());
        }
        Ok(PlannedFiveAxisReference {
            inputs: Arc::new(inputs),
            plan,
            cursor,
        })
    }

    /// The plan.
    pub fn plan(&self) -> &Arc<FiveAxisPlan> {
        &self.plan
    }

    /// What the plan was made from.
    pub fn inputs(&self) -> &FiveAxisInputs {
        &self.inputs
    }

    /// The current sample.
    pub fn current(&mut self) -> PlannedSample {
        self.plan.sample(&mut self.cursor)
    }

    /// The programmed path's parameter at `source` (a place among the programmed poses,
    /// as [`PlannedSample::source`]): the polyline's own for poses, the curve's for a
    /// curve pair (sampled uniformly in it for planning).
    pub fn path_parameter(&self, source: f64) -> f64 {
        match &self.inputs.path {
            ToolPath::Poses { .. } => source,
            ToolPath::Curves { tip, .. } => {
                let (u0, u1) = crate::path::Curve::param_range(tip);
                let last = (self.plan.programmed.max(2) - 1) as f64;
                u0 + (u1 - u0) * (source / last).clamp(0.0, 1.0)
            }
        }
    }

    /// The current sample's joints.
    pub fn joints(&self) -> Joints {
        self.cursor.joints
    }

    /// Whether the reference rests at the path's end.
    pub fn is_done(&self) -> bool {
        self.cursor.sample >= self.plan.samples
    }

    /// The joints of the next sample, the reference unchanged.
    pub fn peek(&self) -> Joints {
        self.plan.peek(&self.cursor)
    }

    /// Advances one period.
    pub fn step(&mut self) -> PlannedSample {
        self.plan.advance(&mut self.cursor);
        self.current()
    }
}

impl PartialEq for PlannedFiveAxisReference {
    fn eq(&self, other: &Self) -> bool {
        self.inputs == other.inputs && self.cursor == other.cursor
    }
}

#[derive(serde::Serialize)]
struct SavedReference<'a> {
    inputs: SavedInputs<'a>,
    /// The inputs' [`fingerprint`], checked before they are planned again.
    fingerprint: u64,
    /// The plan the place is on, checked against the one restored.
    plan: PlanSummary,
    cursor: &'a FiveAxisCursor,
}

#[derive(serde::Serialize)]
enum SavedInputs<'a> {
    Builtin(
        &'a str,
        &'a TableTiltingAc,
        &'a JointLimits,
        &'a PathLimits,
        f64,
    ),
    Data(&'a FiveAxisInputs),
}

/// A saved [`PlannedFiveAxisReference`] as read back, before
/// [`SavedPlannedReference::resume`] plans it again.
#[derive(serde::Deserialize)]
pub struct SavedPlannedReference {
    inputs: RestoredInputs,
    fingerprint: u64,
    plan: PlanSummary,
    cursor: FiveAxisCursor,
}

#[derive(serde::Deserialize)]
enum RestoredInputs {
    Builtin(String, TableTiltingAc, JointLimits, PathLimits, f64),
    Data(FiveAxisInputs),
}

impl SavedPlannedReference {
    /// The reference on the plan `planner` keeps or makes for the saved inputs, at the
    /// saved place once checked against it.
    pub fn resume(self, planner: &Planner) -> Result<PlannedFiveAxisReference, String> {
        let inputs = match self.inputs {
            RestoredInputs::Builtin(name, machine, joints, limits, ts) => FiveAxisInputs {
                path: ToolPath::builtin(&name).map_err(|e| e.to_string())?,
                builtin: Some(name),
                feeds: Vec::new(),
                machine,
                joints,
                limits,
                ts,
            },
            RestoredInputs::Data(inputs) => inputs,
        };
        let saved = (self.fingerprint, self.plan);
        PlannedFiveAxisReference::resume(inputs, self.cursor, saved, planner)
    }
}

impl serde::Serialize for PlannedFiveAxisReference {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let i = &*self.inputs;
        let inputs = match &i.builtin {
            Some(name) => SavedInputs::Builtin(name, &i.machine, &i.joints, &i.limits, i.ts),
            None => SavedInputs::Data(i),
        };
        SavedReference {
            inputs,
            fingerprint: fingerprint(i),
            plan: self.plan.summary(),
            cursor: &self.cursor,
        }
        .serialize(serializer)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vector;
    use crate::kinematics::Pose;
    use crate::math;

    /// A planned quarter turn of 200 poses at 30 mm/s, 2 m/s², and 300 samples on it.
    fn stepped(planner: &Planner) -> PlannedFiveAxisReference {
        let poses: Vec<Pose> = (0..200)
            .map(|i| {
                let t = i as f64 * 0.008;
                Pose {
                    tip: Vector::<3>::new(20.0 * math::cos(t), 20.0 * math::sin(t), 1.0),
                    axis: Vector::<3>::new(0.2 * math::cos(t), 0.2 * math::sin(t), 1.0),
                }
            })
            .collect();
        let inputs = FiveAxisInputs {
            path: ToolPath::from_poses(&poses).unwrap(),
            builtin: None,
            feeds: Vec::new(),
            machine: TableTiltingAc::ORIGIN,
            joints: JointLimits::DEFAULT,
            limits: PathLimits {
                accel: 2000.0,
                ..PathLimits::at_feed(30.0)
            },
            ts: 1e-3,
        };
        let mut r =
            PlannedFiveAxisReference::new(inputs, planner, &|i| format!("pose {i}")).unwrap();
        for _ in 0..300 {
            r.step();
        }
        r
    }

    fn saved(r: &PlannedFiveAxisReference) -> SavedPlannedReference {
        postcard::from_bytes(&postcard::to_stdvec(r).unwrap()).unwrap()
    }

    #[test]
    fn a_damaged_state_is_refused_before_planning_and_a_foreign_plan_after() {
        let made_here = Planner::new();
        let r = stepped(&made_here);
        // Restored in a fresh process: planned once, then continues alike.
        let fresh = Planner::new();
        let mut restored = saved(&r).resume(&fresh).unwrap();
        assert_eq!(
            (restored.cursor.clone(), fresh.plans_made()),
            (r.cursor.clone(), 1)
        );
        assert_eq!(restored.step(), r.clone().step());

        // Inputs changed after saving (a flipped bit in a limit): refused, nothing planned.
        let fresh = Planner::new();
        let mut damaged = saved(&r);
        let RestoredInputs::Data(inputs) = &mut damaged.inputs else {
            panic!("saved with its data")
        };
        inputs.limits.feed = f64::from_bits(inputs.limits.feed.to_bits() ^ 1);
        let e = damaged.resume(&fresh).err().unwrap();
        assert!(e.contains("do not match their fingerprint"), "{e}");
        // A place beyond the saved plan's end: refused, nothing planned.
        let mut beyond = saved(&r);
        beyond.cursor.sample = beyond.plan.samples + 1;
        let e = beyond.resume(&fresh).err().unwrap();
        assert!(e.contains("outside the saved plan"), "{e}");
        assert_eq!(fresh.plans_made(), 0);

        // Saved on a plan this build does not make from the same inputs (another
        // build's planner): refused after planning, once.
        let mut foreign = saved(&r);
        foreign.plan.samples -= 1;
        let e = foreign.resume(&fresh).err().unwrap();
        assert!(e.contains("saved by another build"), "{e}");
        let mut foreign = saved(&r);
        foreign.plan.nodes += 1;
        assert!(foreign.resume(&fresh).is_err());
        assert_eq!(
            fresh.plans_made(),
            1,
            "the plan is kept for the next restore"
        );
    }

    /// Saved states carry the fingerprint, so it must not depend on the build or the
    /// platform (FNV-1a of postcard's bytes): pinned for a small path and a built-in.
    #[test]
    fn the_fingerprint_is_the_same_everywhere() {
        let r = stepped(&Planner::new());
        assert_eq!(fingerprint(r.inputs()), 0x2069_992e_1f37_d16b);
        let builtin = FiveAxisInputs {
            path: ToolPath::builtin("tilted_helix").unwrap(),
            builtin: Some("tilted_helix".into()),
            ..r.inputs().clone()
        };
        assert_eq!(fingerprint(&builtin), 0xe0a2_754e_40f1_9bee);
    }
}
