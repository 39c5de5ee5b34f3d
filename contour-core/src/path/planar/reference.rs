//! The planned XY reference sampled every Ts (docs/design/two-axis.md §4.9): the plan of
//! [`XyPlan`] made once, then one sample a step in O(1). It saves its inputs and its
//! sample count; a restored one is planned from them (the plan is a function of them), so
//! a state from elsewhere cannot carry a plan that breaks the limits: through an
//! [`XyPlans`] cache, which finds the plan an instance of this process made.

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::plan::{XyCursor, XyLimits, XyPlan, XyPoint};
use super::plan_cache::XyPlans;
use crate::path::planar::Path;
use crate::path::PathError;

/// A planned XY reference at its latest sample.
#[derive(Clone, Debug, PartialEq)]
pub struct XyReference {
    path: Path,
    limits: XyLimits,
    plan: Arc<XyPlan>,
    /// Samples taken: the current one is at k·Ts.
    k: u64,
    cursor: XyCursor,
    current: XyPoint,
}

/// A saved [`XyReference`] as read back, before [`SavedXyReference::resume`] finds or
/// makes its plan.
#[derive(Debug, Serialize, Deserialize)]
pub struct SavedXyReference {
    path: Path,
    limits: XyLimits,
    k: u64,
}

impl SavedXyReference {
    /// The reference at its saved sample, on the plan `plans` keeps or makes for its path
    /// and limits.
    pub fn resume(self, plans: &XyPlans) -> Result<XyReference, String> {
        check_before_planning(&self)?;
        let plan = plans
            .plan(&self.path, &self.limits)
            .map_err(|e| e.to_string())?;
        Ok(XyReference::on(plan, self.path, self.limits, self.k))
    }
}

/// What a saved reference is refused for before any planning: limits the parameters
/// would not pass, a line or an arc its constructor would not make, a sample time that is
/// not a number.
fn check_before_planning(saved: &SavedXyReference) -> Result<(), String> {
    saved.limits.validate()?;
    saved.path.check().map_err(|e| e.to_string())?;
    if (saved.limits.ts * saved.k as f64).is_finite() {
        Ok(())
    } else {
        Err("planned reference: sample time not finite".into())
    }
}

impl XyReference {
    /// Plans `path` within `limits`; the first sample is the path's start, at rest.
    pub fn new(path: Path, limits: XyLimits) -> Result<Self, PathError> {
        let plan = Arc::new(XyPlan::new(&path, &limits)?);
        Ok(Self::on(plan, path, limits, 0))
    }

    /// [`XyReference::new`] on the plan `plans` keeps or makes: instances on one path
    /// and limits share it.
    pub fn planned_by(path: Path, limits: XyLimits, plans: &XyPlans) -> Result<Self, PathError> {
        let plan = plans.plan(&path, &limits)?;
        Ok(Self::on(plan, path, limits, 0))
    }

    /// On `plan` (of `path` within `limits`) at sample `k`.
    fn on(plan: Arc<XyPlan>, path: Path, limits: XyLimits, k: u64) -> Self {
        let mut cursor = XyCursor::default();
        let current = plan.at(k as f64 * limits.ts, &mut cursor);
        XyReference {
            path,
            limits,
            plan,
            k,
            cursor,
            current,
        }
    }

    /// The next sample.
    pub fn step(&mut self) -> XyPoint {
        self.k = self.k.saturating_add(1);
        self.current = self
            .plan
            .at(self.k as f64 * self.limits.ts, &mut self.cursor);
        self.current
    }

    /// The latest sample.
    pub fn current(&self) -> XyPoint {
        self.current
    }

    /// The sample one period ahead, the reference unchanged (the plan's look-ahead).
    pub fn peek(&self) -> XyPoint {
        let mut cursor = self.cursor;
        self.plan.at(
            self.k.saturating_add(1) as f64 * self.limits.ts,
            &mut cursor,
        )
    }

    /// The plan has reached the path's end.
    pub fn done(&self) -> bool {
        self.k as f64 * self.limits.ts >= self.plan.duration()
    }

    /// The planned duration, s.
    pub fn duration(&self) -> f64 {
        self.plan.duration()
    }

    /// The planned geometry (blended corners included).
    pub fn geometry(&self) -> Path {
        self.plan.geometry()
    }

    /// The limits it was planned with.
    pub fn limits(&self) -> &XyLimits {
        &self.limits
    }
}

impl Serialize for XyReference {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        #[derive(Serialize)]
        struct Data<'a> {
            path: &'a Path,
            limits: &'a XyLimits,
            k: u64,
        }
        Data {
            path: &self.path,
            limits: &self.limits,
            k: self.k,
        }
        .serialize(s)
    }
}

/// Planned anew: a reference read without a cache (see [`SavedXyReference`]).
impl<'de> Deserialize<'de> for XyReference {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let saved = SavedXyReference::deserialize(d)?;
        check_before_planning(&saved).map_err(serde::de::Error::custom)?;
        let plan = XyPlan::new(&saved.path, &saved.limits).map_err(serde::de::Error::custom)?;
        Ok(XyReference::on(
            Arc::new(plan),
            saved.path,
            saved.limits,
            saved.k,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::path::planar::Program;

    /// A saved arc its constructor would refuse (a negative radius) and limits the
    /// parameters would refuse are refused before planning: the fuzzer's state with such
    /// an arc planned an arc of negative length and panicked sampling it.
    #[test]
    fn a_saved_reference_is_checked_before_it_is_planned() {
        use crate::geometry::Vector2;
        #[derive(Serialize)]
        struct Arc {
            center: Vector2,
            radius: f64,
            start_angle: f64,
            sweep: f64,
        }
        #[derive(Serialize)]
        #[allow(dead_code)]
        enum Path {
            Line(()),
            Arc(Arc),
        }
        #[derive(Serialize)]
        struct Saved {
            path: Path,
            limits: XyLimits,
            k: u64,
        }
        let limits = XyLimits::example();
        let arc = |radius| {
            Path::Arc(Arc {
                center: Vector2::new(0.0, 0.0),
                radius,
                start_angle: 0.0,
                sweep: 1.0,
            })
        };
        let cases = [
            (arc(-5.0), limits, "radius"),
            (
                arc(5.0),
                XyLimits {
                    jerk: -1.0,
                    ..limits
                },
                "jerk",
            ),
            (
                arc(5.0),
                XyLimits {
                    accel: f64::NAN,
                    ..limits
                },
                "accel",
            ),
        ];
        for (path, limits, expected) in cases {
            let bytes = postcard::to_stdvec(&Saved { path, limits, k: 0 }).unwrap();
            let saved: SavedXyReference = postcard::from_bytes(&bytes).unwrap();
            let e = saved.resume(&XyPlans::new()).err().unwrap();
            assert!(e.contains(expected), "{e}");
            assert!(postcard::from_bytes::<XyReference>(&bytes).is_err());
        }
        // The same arc with a positive radius plans.
        let bytes = postcard::to_stdvec(&Saved {
            path: arc(5.0),
            limits,
            k: 0,
        })
        .unwrap();
        let saved: SavedXyReference = postcard::from_bytes(&bytes).unwrap();
        assert!(saved.resume(&XyPlans::new()).is_ok());
    }

    /// The look-ahead is the next step, bit for bit, on a program with an exact stop, a
    /// tight arc and its end, and peeking moves nothing.
    #[test]
    fn peek_is_the_next_sample_and_leaves_the_reference_where_it_was() {
        let program = Program::parse_gcode(
            "G21 G90 G61\nG1 X5 Y0 F600\nG3 X5.4 Y0.4 R0.4\nG1 X5.4 Y3\nM30\n",
            "peek",
        )
        .unwrap();
        let limits = XyLimits {
            feed: 10.0,
            rapid: 100.0,
            accel: 2000.0,
            jerk: 5e4,
            tolerance: 0.0,
            ts: 1e-3,
        };
        let mut reference = XyReference::new(Path::Program(program), limits).unwrap();
        let mut steps = 0;
        while !reference.done() || steps < 3 {
            let before = reference.clone();
            let peeked = reference.peek();
            assert_eq!(reference, before);
            assert_eq!(reference.step(), peeked, "sample {steps}");
            steps += 1;
        }
        assert!(steps > 500, "{steps}");
        // At the end the look-ahead is the end at rest.
        assert_eq!(reference.peek().speed, 0.0);
    }
}
