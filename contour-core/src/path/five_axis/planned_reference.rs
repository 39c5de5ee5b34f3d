//! A planned five-axis reference: the plan shared by the instances that run it, with one
//! instance's place on it; saved as the plan's inputs and the place, a built-in by name.

use std::sync::Arc;

use super::plan::{FiveAxisCursor, FiveAxisPlan, PlannedSample};
use super::planner::{FiveAxisInputs, Planner};
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

    /// On `plan` at a saved `cursor`, checked against the plan.
    fn resume(
        inputs: FiveAxisInputs,
        cursor: FiveAxisCursor,
        planner: &Planner,
    ) -> Result<Self, String> {
        let plan = planner
            .plan(&inputs, &|i| format!("pose {i}"))
            .map_err(|e| e.to_string())?;
        cursor.filter.check()?;
        let (m1, m2) = cursor.filter.lengths();
        if (m1, m2) != plan.filter {
            return Err(format!(
                "the saved jerk filter has {m1} + {m2} samples, the plan {} + {}",
                plan.filter.0, plan.filter.1
            ));
        }
        if cursor.sample > plan.samples
            || cursor.interval + 1 >= plan.path.s.len()
            || cursor.foot + 1 >= plan.path.s.len()
            || !geometry::is_finite(&cursor.joints)
        {
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
        PlannedFiveAxisReference::resume(inputs, self.cursor, planner)
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
            cursor: &self.cursor,
        }
        .serialize(serializer)
    }
}
