//! The `program` estimator: the exact contour error to a whole programmed path (a G-code
//! program, a NURBS or a built-in), the paper's line and arc formulas move by move and the
//! exact closest point on NURBS (docs/design/two-axis.md §4.8).
//!
//! The distance to the whole path would confuse a contour that comes back near itself
//! (a slot's two walls, a pocket's passes): the tool lagging on one pass could be nearer
//! the next. So the estimator measures against the stretch of the path the reference
//! travelled during the last [`WINDOW`] samples, and a little beyond the newest reference
//! (as far as the tool is from it: an overshoot). The tool follows its command with a lag
//! in time (about 1/Kpp: 35 samples at the paper's gains, whatever the feed), so its foot
//! point lies on that stretch; a pass the reference left more than [`WINDOW`] samples ago
//! is not in it. The free-curve estimator keeps the same number of reference samples.
//!
//! One exception: a kink of more than 90° taken without slowing down (a program run at
//! constant feed). Just after it the reference pulls the tool back along the move it
//! has left, and the nearest point, on that move, would make the contour correction hold
//! the tool on it while the axis loops drag it back: the tool slides away from the
//! corner. So where the foot is on a move before the reference's and the reference lies
//! behind it along that move, the tool is measured against the reference's own move. The
//! same holds round an arc tighter than the lag (a slot's end at speed): the reference
//! comes back behind the tool, which the nearest point would hold on the pass it left.
//! A planned reference slows down into a kink, and the exception does not arise.
//!
//! The reference is located at the first place, from its last one on, where the path
//! passes within [`ON_PATH`] of it: the interpolator never goes back, and where the path
//! crosses itself the earlier pass comes first.
//!
//! Both searches run on the [`TrueErrorIndex`] tree restricted to that stretch: their
//! cost depends on how many moves lie near the tool, not on the program's length, and
//! nothing is allocated after construction.

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::free_curve::DEFAULT_CAPACITY;
use super::{TrueError, TrueErrorIndex, TrueErrorIndexes};
use crate::contour::{ContourEstimate, ContourEstimator};
use crate::geometry::{self, Vector2};
use crate::path::planar::Path;

/// How near the path (mm) the reference must be to be on it: 1 µm. A reference farther
/// off comes from another path (another file or tolerance) and is reported.
pub const ON_PATH: f64 = 1e-3;

/// Samples of reference travel the tool is measured against.
pub const WINDOW: usize = DEFAULT_CAPACITY;

/// Where the estimator is along the path: arc lengths from the path's start, and the
/// index chunks (a program's moves) that hold them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Track {
    /// The reference's arc lengths of the last [`WINDOW`] samples, a ring.
    history: Vec<f64>,
    /// Index in `history` of the newest.
    newest: usize,
    reference_chunk: usize,
    /// The chunk of the last foot point (the search finds its guess's chunk from it).
    foot_chunk: usize,
    /// Arc lengths of the last two foot points, the newer last (the next one's guess).
    feet: [f64; 2],
    /// The largest distance of a reference from the path seen, when over [`ON_PATH`].
    off_path: Option<f64>,
    /// `off_path` has been taken for the log.
    off_path_reported: bool,
}

impl Default for Track {
    fn default() -> Self {
        Track {
            history: vec![0.0; WINDOW],
            newest: 0,
            reference_chunk: 0,
            foot_chunk: 0,
            feet: [0.0; 2],
            off_path: None,
            off_path_reported: false,
        }
    }
}

impl Track {
    fn reference_at(&self) -> f64 {
        self.history[self.newest]
    }
}

/// The exact contour error to a programmed path, tracked along it (see the module docs).
#[derive(Clone, Debug)]
pub struct ProgramEstimator {
    /// Shared by the instances on one path ([`TrueErrorIndexes`]).
    index: Arc<TrueErrorIndex>,
    track: Track,
}

/// A [`ProgramEstimator`] as saved: its path and its track. Read as it is, it finds its
/// index in a [`TrueErrorIndexes`] ([`SavedProgramEstimator::resume`]); read as a
/// `ProgramEstimator`, it builds its own.
#[derive(Deserialize)]
pub struct SavedProgramEstimator {
    path: Path,
    track: Track,
}

impl SavedProgramEstimator {
    /// The estimator, on the index `indexes` keeps or makes for its path; refused (naming
    /// the value) when the track does not fit the path.
    pub fn resume(self, indexes: &TrueErrorIndexes) -> Result<ProgramEstimator, String> {
        ProgramEstimator::checked(indexes.index(&self.path), self.track)
    }
}

/// [`SavedProgramEstimator`] as written, borrowing its parts.
#[derive(Serialize)]
struct SavedProgramEstimatorRef<'a> {
    path: &'a Path,
    track: &'a Track,
}

impl ProgramEstimator {
    /// The estimator for `path`, at its start (allocates the index once).
    pub fn new(path: &Path) -> Self {
        ProgramEstimator::on(Arc::new(TrueErrorIndex::new(path)))
    }

    /// The estimator for the path of `index`, at its start.
    pub fn on(index: Arc<TrueErrorIndex>) -> Self {
        ProgramEstimator {
            index,
            track: Track::default(),
        }
    }

    /// The path it measures against.
    pub fn path(&self) -> &Path {
        self.index.path()
    }

    /// Arc length along the path of the reference's last position, mm.
    pub fn reference_at(&self) -> f64 {
        self.track.reference_at()
    }

    /// The largest distance (mm) of a reference from the path, the first time one was
    /// off by more than [`ON_PATH`]; `None` afterwards and while every reference was on it.
    pub fn take_off_path(&mut self) -> Option<f64> {
        if self.track.off_path_reported {
            return None;
        }
        let off = self.track.off_path;
        self.track.off_path_reported = off.is_some();
        off
    }

    /// Moves the reference's track on to `reference`; returns the arc length the
    /// reference had [`WINDOW`] samples before.
    fn locate_reference(&mut self, reference: Vector2) -> f64 {
        let t = &mut self.track;
        let index = &self.index;
        let last = t.reference_at();
        // Where it would be at the speed of its last step.
        let previous = t.history[(t.newest + WINDOW - 1) % WINDOW];
        let guess = last + (last - previous);
        let (chunk, e) = index
            .first_within_near(reference, last, t.reference_chunk, guess, ON_PATH)
            .unwrap_or_else(|| {
                let (chunk, e) =
                    index.error_between(reference, t.reference_chunk, guess, last, f64::INFINITY);
                let off = e.error.abs();
                t.off_path = Some(t.off_path.map_or(off, |o| o.max(off)));
                (chunk, e)
            });
        t.reference_chunk = chunk;
        t.newest = (t.newest + 1) % WINDOW;
        let oldest = t.history[t.newest];
        t.history[t.newest] = along(index, chunk, &e, last).max(last);
        oldest
    }
}

/// Arc length of the foot of `e`, found in `chunk`. A full circle's start is also its
/// end: a foot there is at whichever of the two is nearer `near`.
fn along(index: &TrueErrorIndex, chunk: usize, e: &TrueError, near: f64) -> f64 {
    if !index.is_closed(chunk) {
        return index.length_at(chunk, e.u);
    }
    let [(start, start_point), (end, end_point)] = index.chunk_ends(chunk);
    let at_both = |p: Vector2| geometry::dist(&p, &e.foot) <= 1e-9 * (1.0 + p.amax());
    if at_both(start_point) && at_both(end_point) {
        if (near - start).abs() <= (end - near).abs() {
            start
        } else {
            end
        }
    } else {
        index.length_at(chunk, e.u)
    }
}

impl ContourEstimator for ProgramEstimator {
    fn estimate(&mut self, reference: Vector2, actual: Vector2) -> ContourEstimate {
        let oldest = self.locate_reference(reference);
        let t = &mut self.track;
        let to = t.reference_at() + geometry::dist(&actual, &reference) + ON_PATH;
        // Where the foot would be at the speed of its last step.
        let guess = 2.0 * t.feet[1] - t.feet[0];
        let (mut chunk, mut e) =
            self.index
                .error_between(actual, t.foot_chunk, guess, oldest - ON_PATH, to);
        // Held to a move the reference has left while the reference pulls back along
        // it (the path turned by more than 90° between them, at a kink or round a tight
        // arc): measure against the reference's own move (design §4.8).
        if chunk < t.reference_chunk {
            let tangent = Vector2::new(e.normal[1], -e.normal[0]);
            if (reference - e.foot).dot(&tangent) < 0.0 {
                let from = self.index.chunk_ends(t.reference_chunk)[0].0;
                (chunk, e) = self
                    .index
                    .error_between(actual, t.reference_chunk, guess, from, to);
            }
        }
        t.foot_chunk = chunk;
        t.feet = [t.feet[1], along(&self.index, chunk, &e, t.feet[1])];
        e.estimate()
    }

    fn reset(&mut self) {
        self.track = Track::default();
    }
}

impl PartialEq for ProgramEstimator {
    fn eq(&self, other: &Self) -> bool {
        self.track == other.track && self.path() == other.path()
    }
}

impl ProgramEstimator {
    /// The estimator on `index` with the saved track `t`, checked against the path.
    fn checked(index: Arc<TrueErrorIndex>, t: Track) -> Result<Self, String> {
        let chunks = index.chunk_count();
        let length = index.chunk_ends(chunks - 1)[1].0;
        if t.history.len() != WINDOW || t.newest >= WINDOW {
            return Err(format!(
                "program estimator: a history of {} samples with the newest at {} (expected {WINDOW})",
                t.history.len(),
                t.newest
            ));
        }
        if t.reference_chunk >= chunks || t.foot_chunk >= chunks {
            return Err(format!(
                "program estimator: chunk {} or {} beyond the path's {chunks}",
                t.reference_chunk, t.foot_chunk
            ));
        }
        let on_path = |s: &&f64| s.is_finite() && (0.0..=length).contains(*s);
        if let Some(s) = t.history.iter().find(|s| !on_path(s)) {
            return Err(format!(
                "program estimator: a reference position {s} mm off the path (0 … {length} mm)"
            ));
        }
        if let Some(s) = t.feet.iter().find(|s| !on_path(s)) {
            return Err(format!(
                "program estimator: a foot point's position {s} mm off the path (0 … {length} mm)"
            ));
        }
        Ok(ProgramEstimator { index, track: t })
    }
}

impl TryFrom<SavedProgramEstimator> for ProgramEstimator {
    type Error = String;
    fn try_from(d: SavedProgramEstimator) -> Result<Self, String> {
        ProgramEstimator::checked(Arc::new(TrueErrorIndex::new(&d.path)), d.track)
    }
}

impl Serialize for ProgramEstimator {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        SavedProgramEstimatorRef {
            path: self.path(),
            track: &self.track,
        }
        .serialize(s)
    }
}

impl<'de> Deserialize<'de> for ProgramEstimator {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let data = SavedProgramEstimator::deserialize(d)?;
        ProgramEstimator::try_from(data).map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contour::planar::true_error;
    use crate::path::planar::{builtin, Program};
    use crate::path::{Curve, Interpolator};

    /// Two passes 0.6 mm apart, both to +x: 30 mm along y = 0, round a loop on the
    /// left, then 30 mm along y = 0.6 (a pocket's passes, 37 mm of path apart).
    fn passes() -> Path {
        let text = "G1 X30 F600\nY3\nX-2\nY0.6\nX30\n";
        Path::Program(Program::parse_gcode(text, "passes.ngc").unwrap())
    }

    #[test]
    fn a_tool_off_its_pass_is_measured_against_that_pass_not_the_other_one() {
        // The actual point trails the reference by 40 samples and sits 0.4 mm right of
        // travel (outside the loop's left turns): on the second pass that is 0.2 mm from
        // the first. The tracked estimate is the 0.4 mm to its own pass; the global
        // nearest would be the first pass.
        let path = passes();
        let mut it = Interpolator::new(path.clone(), 20.0, 1e-3).unwrap();
        let mut samples = vec![it.current()];
        while !it.step().done {
            samples.push(it.current());
        }
        let mut e = ProgramEstimator::new(&path);
        let mut compared = 0;
        for k in 0..samples.len() {
            let behind = samples[k.saturating_sub(40)];
            let tangent = path.eval(behind.u).d1;
            let right = Vector2::new(tangent[1], -tangent[0]) / geometry::norm(&tangent);
            let actual = behind.point + right * 0.4;
            let got = e.estimate(samples[k].point, actual);
            // Along the passes, clear of the corners: 0.4 mm right of the pass travelled.
            assert!((got.error - 0.4).abs() < 1e-9, "k = {k}: {}", got.error);
            if actual[1] > 0.0 && actual[1] < 0.3 && (1.0..29.0).contains(&actual[0]) {
                let global = true_error(&path, actual).error;
                assert!((global.abs() - 0.2).abs() < 1e-9, "{global}");
                compared += 1;
            }
        }
        assert!(compared > 1000, "{compared}");
        assert!(e.take_off_path().is_none());
    }

    #[test]
    fn the_reference_goes_round_a_full_circle_and_on() {
        // A full circle programmed as one move, then a line out of it: at the circle's
        // end the reference is at its start point again, and the track must go on, not
        // back. The actual sits 0.1 mm outside the circle all round, then on the line.
        let text = "G1 X10 F600\nG3 X10 Y0 I0 J5\nG1 X20\n";
        let path = Path::Program(Program::parse_gcode(text, "c.ngc").unwrap());
        let mut it = Interpolator::new(path.clone(), 10.0, 1e-3).unwrap();
        let mut e = ProgramEstimator::new(&path);
        let mut s_before = 0.0;
        while !it.step().done {
            let r = it.current();
            let centre = Vector2::new(10.0, 5.0);
            let actual = match r.u {
                s if (10.0 + 1e-6..10.0 + 10.0 * std::f64::consts::PI - 1e-6).contains(&s) => {
                    centre + (r.point - centre) * (5.1 / 5.0)
                }
                _ => r.point + Vector2::new(0.0, -0.05),
            };
            let got = e.estimate(r.point, actual);
            assert!(
                e.reference_at() >= s_before - 1e-9,
                "went back at s = {}",
                r.u
            );
            assert!(
                (e.reference_at() - r.u).abs() < 1e-9,
                "{} vs {}",
                e.reference_at(),
                r.u
            );
            s_before = e.reference_at();
            assert!(
                got.error > 0.0499 && got.error < 0.1001,
                "s = {}: {}",
                r.u,
                got.error
            );
        }
    }

    #[test]
    fn on_the_papers_circle_and_a_line_it_is_the_exact_arc_and_line_estimate() {
        use crate::contour::planar::{ArcEstimator, LineEstimator};
        for name in ["circle", "line"] {
            let path = builtin::by_name(name).unwrap();
            let mut exact = match &path {
                Path::Arc(a) => Box::new(ArcEstimator::new(a)) as Box<dyn ContourEstimator>,
                Path::Line(l) => Box::new(LineEstimator::new(l)),
                _ => unreachable!(),
            };
            let mut e = ProgramEstimator::new(&path);
            let mut it = Interpolator::new(path.clone(), 30.0, 1e-3).unwrap();
            let mut samples = vec![it.current()];
            while !it.step().done {
                samples.push(it.current());
            }
            for k in 0..samples.len() {
                let r = samples[k];
                // 35 samples behind, 0.1 mm to the left of the path there.
                let behind = samples[k.saturating_sub(35)];
                let d1 = path.eval(behind.u).d1;
                let left = Vector2::new(-d1[1], d1[0]) / geometry::norm(&d1);
                let actual = behind.point + left * 0.1;
                let got = e.estimate(r.point, actual);
                let want = exact.estimate(r.point, actual);
                assert!((got.error - want.error).abs() < 1e-12, "{name} {k}");
                assert!((got.error + 0.1).abs() < 1e-12, "{name} {k}: {}", got.error);
                assert!((e.reference_at() - path.length_between(0.0, r.u)).abs() < 1e-9);
            }
            assert_eq!(e.take_off_path(), None, "{name}");
        }
    }

    #[test]
    fn a_reference_off_the_path_is_reported_once_with_its_distance() {
        let path = builtin::by_name("infinity").unwrap();
        let mut e = ProgramEstimator::new(&path);
        let start = path.start_point();
        e.estimate(start, start);
        assert_eq!(e.take_off_path(), None);
        // 5 µm, then 20 µm off the path near its start (the infinity is a NURBS).
        let n = Vector2::new(0.0, 1.0);
        let near = true_error(&path, start + n * 0.005).error.abs();
        e.estimate(start + n * 0.005, start);
        e.estimate(start + n * 0.02, start);
        let far = true_error(&path, start + n * 0.02).error.abs();
        assert!(near > ON_PATH && far > near);
        assert!((e.take_off_path().unwrap() - far).abs() < 1e-9);
        e.estimate(start + n * 0.05, start);
        assert_eq!(e.take_off_path(), None);
    }

    #[test]
    fn a_blended_program_continues_bit_for_bit_after_a_restore() {
        // Every corner a blend: the tool's search starts from its guessed foot, which
        // must come back with the state.
        let program = crate::path::planar::Program::parse_gcode(
            "G64 P0.01\nG1 X2 F600\nX4 Y0.2\nX6 Y0.6\nX8 Y1.2\nX10 Y2\nX11 Y3.5\n",
            "fan.ngc",
        )
        .unwrap();
        let path = Path::Program(crate::path::planar::blended(&program, 0.0));
        let mut e = ProgramEstimator::new(&path);
        let mut it = Interpolator::new(path.clone(), 20.0, 1e-3).unwrap();
        let sample = |it: &Interpolator| {
            let r = it.current().point;
            (r, r + Vector2::new(-0.003, 0.004))
        };
        for _ in 0..300 {
            it.step();
            let (r, p) = sample(&it);
            e.estimate(r, p);
        }
        let blob = postcard::to_stdvec(&e).unwrap();
        let mut restored: ProgramEstimator = postcard::from_bytes(&blob).unwrap();
        for _ in 0..400 {
            it.step();
            let (r, p) = sample(&it);
            let (a, b) = (restored.estimate(r, p), e.estimate(r, p));
            assert_eq!(a.error.to_bits(), b.error.to_bits());
            assert_eq!(a.normal, b.normal);
        }
        // Against the brute force, the same to 1e-12.
        let (r, p) = sample(&it);
        let exact = true_error(&path, p).error;
        assert!((e.estimate(r, p).error - exact).abs() < 1e-12);
    }

    #[test]
    fn the_saved_track_restores_into_a_new_estimator_and_a_corrupt_one_is_refused() {
        let path = passes();
        let mut e = ProgramEstimator::new(&path);
        let mut it = Interpolator::new(path.clone(), 20.0, 1e-3).unwrap();
        for _ in 0..1600 {
            it.step();
            e.estimate(
                it.current().point,
                it.current().point + Vector2::new(0.0, 0.01),
            );
        }
        let blob = postcard::to_stdvec(&e).unwrap();
        let mut restored: ProgramEstimator = postcard::from_bytes(&blob).unwrap();
        assert_eq!(restored, e);
        for _ in 0..200 {
            it.step();
            let (r, p) = (
                it.current().point,
                it.current().point + Vector2::new(0.0, 0.01),
            );
            assert_eq!(restored.estimate(r, p), e.estimate(r, p));
        }
        let mut data = postcard::from_bytes::<SavedProgramEstimator>(&blob).unwrap();
        data.track.history[3] = -1.0;
        let bad = postcard::to_stdvec(&SavedProgramEstimatorRef {
            path: &data.path,
            track: &data.track,
        })
        .unwrap();
        let message = postcard::from_bytes::<ProgramEstimator>(&bad).unwrap_err();
        assert!(
            matches!(message, postcard::Error::SerdeDeCustom),
            "{message}"
        );
    }
}
