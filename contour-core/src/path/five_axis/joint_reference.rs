//! Joint references of a five-axis path: the tip moves along its path at the feed, one
//! sample every `Ts` (the planar interpolator's law, §4.6, on the tip curve), the tool
//! axis is the path's at that point, and the joints come from the machine's inverse
//! kinematics with C unwrapped from sample to sample.

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::tool_path::{tips_length, ToolPath};
use crate::geometry::Vector;
use crate::kinematics::{Joints, Pose, TableTiltingAc};
use crate::path::{Curve, Interpolator, Nurbs, PathError, Polyline, Progress};

/// The tip curve the interpolator runs on.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
enum TipInterpolator {
    Curve(Interpolator<3, Nurbs<3>>),
    Polyline(Interpolator<3, Polyline<3>>),
}

/// One joint-reference sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointSample {
    /// The tool pose on the path.
    pub pose: Pose,
    /// The joints that put the tool there (mm, rad).
    pub joints: Joints,
    /// The tip curve's parameter.
    pub u: f64,
    /// Whether this is the path's end.
    pub done: bool,
}

/// Samples a [`ToolPath`] at a constant tip feed and converts each sample to joints. The
/// whole struct is the state the FMU saves (see [`SavedReference`]); bytes from elsewhere
/// go through [`JointReference::check`].
#[derive(Clone, Debug, PartialEq)]
pub struct JointReference {
    path: ToolPath,
    /// The built-in's name when the path is one: a state holds the name instead of its
    /// 80 001 poses (6 MB), and the name rebuilds them bit for bit.
    builtin: Option<String>,
    machine: TableTiltingAc,
    tip: TipInterpolator,
    joints: Joints,
}

/// Refuses a path whose tip length overflows (control points or CL records near ±1e308):
/// the interpolator would crawl along it for ever at outputs of 1e308 mm.
pub(crate) fn check_length(path: &ToolPath) -> Result<(), PathError> {
    let length = match path {
        ToolPath::Curves { tip, .. } => tip.length(),
        ToolPath::Poses { tips, .. } => tips_length(tips),
    };
    if length.is_finite() {
        Ok(())
    } else {
        Err(PathError::invalid(format!(
            "the tip's path is {length} mm long: no feed follows it (a point near ±1e308?)"
        )))
    }
}

/// The tips as the constant-feed interpolator runs along them: a polyline, which has no
/// piece where the tool turns on the spot (at constant tip feed such a turn would take no
/// time); a plan runs those.
fn constant_feed_tips(tips: &std::sync::Arc<[Vector<3>]>) -> Result<Polyline<3>, PathError> {
    if let Some(i) = (1..tips.len()).find(|&i| tips[i] == tips[i - 1]) {
        return Err(PathError::invalid(format!(
            "the tool turns on the spot from pose {} to pose {i}: the reference at constant \
             feed (accel = 0) cannot follow that; a plan (accel > 0) can",
            i - 1
        )));
    }
    Polyline::shared(std::sync::Arc::clone(tips))
}

impl JointReference {
    /// Starts at the path's start with `feed` (mm/s, ≥ 0) every `ts` seconds; the start
    /// C is the one nearest 0.
    pub fn new(
        path: ToolPath,
        machine: TableTiltingAc,
        feed: f64,
        ts: f64,
    ) -> Result<Self, PathError> {
        check_length(&path)?;
        let tip = match &path {
            ToolPath::Curves { tip, .. } => {
                TipInterpolator::Curve(Interpolator::new(tip.clone(), feed, ts)?)
            }
            ToolPath::Poses { tips, .. } => {
                TipInterpolator::Polyline(Interpolator::new(constant_feed_tips(tips)?, feed, ts)?)
            }
        };
        let mut reference = JointReference {
            path,
            builtin: None,
            machine,
            tip,
            joints: Joints::zeros(),
        };
        let u = reference.parameter();
        reference.joints = reference.solve(u, 0.0)?;
        Ok(reference)
    }

    /// [`Self::new`] on the built-in path `name` (see [`ToolPath::builtin`]).
    pub fn builtin(
        name: &str,
        machine: TableTiltingAc,
        feed: f64,
        ts: f64,
    ) -> Result<Self, PathError> {
        let mut reference = Self::new(ToolPath::builtin(name)?, machine, feed, ts)?;
        reference.builtin = Some(name.to_owned());
        Ok(reference)
    }

    fn parameter(&self) -> f64 {
        match &self.tip {
            TipInterpolator::Curve(i) => i.parameter(),
            TipInterpolator::Polyline(i) => i.parameter(),
        }
    }

    fn solve(&self, u: f64, previous_c: f64) -> Result<Joints, PathError> {
        let pose = self.path.pose_at(u);
        self.machine
            .inverse(&pose, previous_c)
            .ok_or_else(|| PathError::invalid(format!("no joints reach the pose at u = {u}")))
    }

    /// The current sample.
    pub fn current(&self) -> JointSample {
        let (u, done) = match &self.tip {
            TipInterpolator::Curve(i) => (i.parameter(), i.is_done()),
            TipInterpolator::Polyline(i) => (i.parameter(), i.is_done()),
        };
        JointSample {
            pose: self.path.pose_at(u),
            joints: self.joints,
            u,
            done,
        }
    }

    /// Checks a reference restored from bytes as construction would have made it, with
    /// sample period `ts`: the interpolator runs on the path's own tip curve at a finite
    /// feed, inside its parameter range, and the joints and machine are finite. (The path
    /// checked itself when decoded.) The error names the first violation.
    pub fn check(&self, ts: f64) -> Result<(), String> {
        let (same_curve, feed, period, u, range, point) = match (&self.tip, &self.path) {
            (TipInterpolator::Curve(i), ToolPath::Curves { tip, .. }) => (
                i.path() == tip,
                i.feed(),
                i.ts(),
                i.parameter(),
                tip.param_range(),
                i.point(),
            ),
            (TipInterpolator::Polyline(i), ToolPath::Poses { tips, .. }) => (
                i.path().points() == &tips[..],
                i.feed(),
                i.ts(),
                i.parameter(),
                (0.0, (tips.len() - 1) as f64),
                i.point(),
            ),
            _ => return Err("the interpolator runs on another kind of path".into()),
        };
        if !same_curve {
            return Err("the interpolator runs on another tip curve than the path's".into());
        }
        if !(feed.is_finite() && feed >= 0.0) {
            return Err(format!("feed {feed} mm/s must be finite and >= 0"));
        }
        if period != ts {
            return Err(format!(
                "interpolation period {period} s differs from the sample clock's {ts} s"
            ));
        }
        if !(range.0..=range.1).contains(&u) {
            return Err(format!(
                "path parameter {u} lies outside the path's [{}, {}]",
                range.0, range.1
            ));
        }
        let machine = [self.machine.a_pivot, self.machine.c_pivot];
        if !(crate::geometry::is_finite(&self.joints)
            && crate::geometry::is_finite(&point)
            && machine.iter().all(crate::geometry::is_finite))
        {
            return Err(
                "the joints, the current tip or the machine's pivots are not finite".into(),
            );
        }
        Ok(())
    }

    /// The current sample's joints.
    pub fn joints(&self) -> Joints {
        self.joints
    }

    /// The joints of the next sample, the reference unchanged (the current ones where the
    /// inverse kinematics refuse the next pose; `step` reports that).
    pub fn peek(&self) -> Joints {
        let u = match &self.tip {
            TipInterpolator::Curve(i) => i.peek(),
            TipInterpolator::Polyline(i) => i.peek(),
        };
        // Not `solve`: its error message would allocate on every refused peek.
        let pose = self.path.pose_at(u);
        self.machine
            .inverse(&pose, self.joints[4])
            .unwrap_or(self.joints)
    }

    /// Whether the reference rests at the path's end.
    pub fn is_done(&self) -> bool {
        match &self.tip {
            TipInterpolator::Curve(i) => i.is_done(),
            TipInterpolator::Polyline(i) => i.is_done(),
        }
    }

    /// The sample period, s.
    pub fn ts(&self) -> f64 {
        match &self.tip {
            TipInterpolator::Curve(i) => i.ts(),
            TipInterpolator::Polyline(i) => i.ts(),
        }
    }

    /// Advances one period.
    pub fn step(&mut self) -> Result<JointSample, PathError> {
        let u = match &mut self.tip {
            TipInterpolator::Curve(i) => i.step().u,
            TipInterpolator::Polyline(i) => i.step().u,
        };
        self.joints = self.solve(u, self.joints[4])?;
        Ok(self.current())
    }
}

/// A saved [`JointReference`]: the path once, by name for a built-in (the tip
/// interpolator runs on a copy of the path's tip curve, which the state does not repeat),
/// and where the interpolator stands on it.
#[derive(Serialize)]
struct SavedReference<'a> {
    path: SavedPath<'a>,
    machine: &'a TableTiltingAc,
    tip: TipProgress,
    joints: &'a Joints,
}

#[derive(Serialize)]
enum SavedPath<'a> {
    Builtin(&'a str),
    Data(&'a ToolPath),
}

/// [`SavedReference`] as read back (the same bytes, owned).
#[derive(Deserialize)]
struct RestoredReference {
    path: RestoredPath,
    machine: TableTiltingAc,
    tip: TipProgress,
    joints: Joints,
}

#[derive(Deserialize)]
enum RestoredPath {
    Builtin(String),
    Data(ToolPath),
}

#[derive(Clone, Copy, Serialize, Deserialize)]
enum TipProgress {
    Curve(Progress<3>),
    Polyline(Progress<3>),
}

impl Serialize for JointReference {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let path = match &self.builtin {
            Some(name) => SavedPath::Builtin(name),
            None => SavedPath::Data(&self.path),
        };
        let tip = match &self.tip {
            TipInterpolator::Curve(i) => TipProgress::Curve(i.progress()),
            TipInterpolator::Polyline(i) => TipProgress::Polyline(i.progress()),
        };
        SavedReference {
            path,
            machine: &self.machine,
            tip,
            joints: &self.joints,
        }
        .serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for JointReference {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let saved = RestoredReference::deserialize(deserializer)?;
        JointReference::restore(saved).map_err(serde::de::Error::custom)
    }
}

impl JointReference {
    /// Puts a saved reference back on its path: the built-in rebuilt from its name (an
    /// unknown name is refused), the interpolator resumed on the path's own tip curve.
    fn restore(saved: RestoredReference) -> Result<Self, PathError> {
        let (path, builtin) = match saved.path {
            RestoredPath::Builtin(name) => (ToolPath::builtin(&name)?, Some(name)),
            RestoredPath::Data(path) => (path, None),
        };
        check_length(&path)?;
        let tip = match (saved.tip, &path) {
            (TipProgress::Curve(p), ToolPath::Curves { tip, .. }) => {
                TipInterpolator::Curve(Interpolator::resume(tip.clone(), p)?)
            }
            (TipProgress::Polyline(p), ToolPath::Poses { tips, .. }) => {
                TipInterpolator::Polyline(Interpolator::resume(constant_feed_tips(tips)?, p)?)
            }
            _ => {
                return Err(PathError::invalid(
                    "the saved interpolator ran on another kind of path",
                ))
            }
        };
        Ok(JointReference {
            path,
            builtin,
            machine: saved.machine,
            tip,
            joints: saved.joints,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{self, Vector};

    /// Steps `reference` `n` times, returning the joints.
    fn run(reference: &mut JointReference, n: usize) -> Vec<Joints> {
        (0..n).map(|_| reference.step().unwrap().joints).collect()
    }

    #[test]
    fn a_saved_reference_continues_bit_identically_and_holds_its_path_once() {
        let machine = TableTiltingAc {
            a_pivot: Vector::<3>::new(0.0, 1.0, -50.0),
            c_pivot: Vector::<3>::new(2.0, 0.0, 0.0),
        };
        let json = r#"{
            "tip": {"degree": 2, "knots": [0, 0, 0, 1, 1, 1],
                    "control_points": [[0, 0, 0], [10, 5, 0], [20, 0, 1]]},
            "second": {"degree": 2, "knots": [0, 0, 0, 1, 1, 1],
                       "control_points": [[0, 5, 100], [10, 5, 100], [20, -5, 100]]},
            "length": 100
        }"#;
        let cl = "GOTO/0,0,0,0,0,1\nGOTO/5,0,0,0,0.1,1\nGOTO/5,5,1,0.1,0.1,1\nGOTO/0,5,1,0,0,1\n";
        let poses = crate::part_program::cl_data::parse_cl(cl, "part.cl")
            .unwrap()
            .poses();
        let cases = [
            (
                "helix",
                JointReference::builtin("tilted_helix", machine, 50.0, 1e-3),
            ),
            (
                "eight",
                JointReference::builtin("figure_eight", machine, 80.0, 1e-3),
            ),
            (
                "json",
                JointReference::new(
                    ToolPath::parse_json(json, "t.json").unwrap(),
                    machine,
                    20.0,
                    1e-3,
                ),
            ),
            (
                "cl",
                JointReference::new(ToolPath::from_poses(&poses).unwrap(), machine, 20.0, 1e-3),
            ),
        ];
        for (name, reference) in cases {
            let mut reference = reference.unwrap();
            run(&mut reference, 300);
            let bytes = postcard::to_stdvec(&reference).unwrap();
            let mut restored: JointReference = postcard::from_bytes(&bytes).unwrap();
            assert!(restored == reference, "{name}: restored differs");
            assert_eq!(run(&mut restored, 300), run(&mut reference, 300), "{name}");
            // A built-in by name; a file's path once: a CL part of 4 poses (2 × 4 vectors)
            // or a curve pair of 2 × 3 control points, plus the progress.
            let limit = if name == "json" { 600 } else { 400 };
            assert!(bytes.len() < limit, "{name}: {} bytes", bytes.len());
        }
        // A state naming no built-in is refused (postcard keeps no message of its own).
        let helix = JointReference::builtin("tilted_helix", machine, 50.0, 1e-3).unwrap();
        let bytes = postcard::to_stdvec(&helix).unwrap();
        let at = bytes.windows(5).position(|w| w == b"tilte").unwrap();
        let mut renamed = bytes.clone();
        renamed[at] = b'T';
        assert!(postcard::from_bytes::<JointReference>(&renamed).is_err());
        assert!(postcard::from_bytes::<JointReference>(&bytes).is_ok());
    }

    #[test]
    fn the_helix_at_feed_gives_joints_that_reproduce_it() {
        let machine = TableTiltingAc {
            a_pivot: Vector::<3>::new(0.0, 0.0, -50.0),
            c_pivot: Vector::zeros(),
        };
        let mut reference =
            JointReference::new(ToolPath::tilted_helix(), machine, 50.0, 1e-3).unwrap();
        let mut previous = reference.current();
        let c_start = previous.joints[4];
        let mut samples = 0;
        while !previous.done {
            let s = reference.step().unwrap();
            // The tip advances F·Ts along the path (chord 0.05 mm, to 0.01 %)…
            let chord = geometry::dist(&s.pose.tip, &previous.pose.tip);
            assert!(s.done || (chord / 0.05 - 1.0).abs() < 1e-4, "{chord}");
            // …and the forward kinematics of the joints give the pose back.
            let back = machine.forward(&s.joints);
            assert!((back.tip - s.pose.tip).amax() < 1e-9);
            assert!((back.axis - s.pose.axis).amax() < 1e-12);
            // C turns continuously (no 2π jumps) and A stays at the 20° tilt.
            assert!((s.joints[4] - previous.joints[4]).abs() < 0.01);
            assert!((s.joints[3] - 20f64.to_radians()).abs() < 1e-6);
            previous = s;
            samples += 1;
        }
        // Two turns of a helix of radius 20 and pitch 5: length 2·√((40π)² + 5²).
        let length = 2.0 * ((40.0 * std::f64::consts::PI).powi(2) + 25.0).sqrt();
        assert!((samples as f64 - length / 0.05).abs() < 2.0, "{samples}");
        // Two turns of C, unwrapped.
        let turned = (previous.joints[4] - c_start).abs();
        assert!(
            (turned - 2.0 * std::f64::consts::TAU).abs() < 1e-6,
            "{turned}"
        );
    }
}
