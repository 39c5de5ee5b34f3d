//! The XY table's evaluation (docs/usage.md, `contour-eval` on the XY table): every
//! measured point's signed distance to the programmed contour and to the planned one
//! (the corners blended as `PathInterpolator2D` with `accel` > 0 plans them,
//! docs/design/two-axis.md §4.9), exactly, by the library's [`TrueErrorIndex`] (closed
//! forms for lines and arcs, the exact closest point on blends and NURBS).
//!
//! The sign is the controller's `contourError`'s (docs/design/overview.md, conventions):
//! positive right of the direction of travel.
//!
//! **Which pass.** The distance to the whole path would confuse a contour that comes
//! back near itself (a slot's two walls, a pocket's passes): a point that lags on one
//! pass can be nearer the next. So the point is tracked along the path, as the
//! controller's `program` estimator tracks its reference (§4.8), without a reference:
//! each sample is measured against the stretch of path within a reach of the last
//! sample's foot, both ways, where the reach is twice the tool's move since the last
//! sample, four times the last distance from the path (at a corner the foot jumps by
//! up to 2d/tan(α/2) between the two sides of an inside angle α: 2d at a right angle,
//! 4d down to about 53°) and [`MARGIN`]. Where the nearest point of that stretch is at
//! its end, the distance still falls beyond it: the stretch is extended by the reach
//! (or the distance from the path, if larger) while the nearest point keeps getting
//! nearer. So the foot follows the tool along its own pass, and another pass is
//! searched only when it lies within a few contour errors of path length.
//!
//! The first sample is placed at the first place along the path (from its start) that
//! is as near to it as any: a run that starts where its path starts, as every run does,
//! starts on the first pass.

use contour_core::contour::planar::{TrueError, TrueErrorIndex};
use contour_core::geometry::{self, Vector2};
use contour_core::path::planar::{blended, Path, Shape};

/// Path length (mm) every stretch reaches beyond what the tool's move and its distance
/// from the path call for: 1 µm.
pub const MARGIN: f64 = 1e-3;

/// Slack on the nearest distance when the first sample is placed, mm (rounding).
const TIE: f64 = 1e-9;

/// One measured point, evaluated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanarSample {
    /// The programmed move of the foot (a program's move index, from 0); 0 on a line, an
    /// arc or a NURBS.
    pub segment: usize,
    /// Signed distance to the programmed contour, mm, > 0 right of travel.
    pub contour: f64,
    /// Signed distance to the planned contour, mm, > 0 right of travel.
    pub planned: f64,
    /// Arc length of the programmed foot from the path's start, mm.
    pub along: f64,
}

/// The programmed path and what it is planned into.
pub struct Geometry {
    pub programmed: Path,
    /// The planned geometry where it differs from the programmed one.
    pub planned: Option<Path>,
}

impl Geometry {
    /// The planned geometry of `path` at the blend `tolerance` (mm, ≥ 0): a program's
    /// corners rounded as the interpolator rounds them (bare G64 and the start within
    /// `tolerance`, G64 P within P); a line, an arc or a NURBS is planned on itself.
    pub fn new(path: Path, tolerance: f64) -> Result<Geometry, String> {
        let planned = match &path {
            Path::Program(program) => {
                let planned = blended(program, tolerance);
                (planned.moves() != program.moves()).then_some(Path::Program(planned))
            }
            Path::Line(_) | Path::Arc(_) | Path::Nurbs(_) => None,
        };
        Ok(Geometry {
            programmed: path,
            planned,
        })
    }

    /// Corners the plan rounds.
    pub fn blends(&self) -> usize {
        match &self.planned {
            Some(Path::Program(p)) => p
                .moves()
                .iter()
                .filter(|m| matches!(m.shape, Shape::Blend(_)))
                .count(),
            _ => 0,
        }
    }
}

/// Where the tracked foot is.
#[derive(Clone, Copy, Debug)]
struct Foot {
    chunk: usize,
    error: TrueError,
    /// Arc length from the path's start, mm.
    along: f64,
}

/// The foot of a run's points followed along one path (see the module docs).
struct Tracker {
    index: TrueErrorIndex,
    /// The path's length, mm.
    length: f64,
    /// The last point and its foot.
    last: Option<(Vector2, Foot)>,
}

impl Tracker {
    fn new(path: &Path) -> Tracker {
        let index = TrueErrorIndex::new(path);
        let length = index.chunk_ends(index.chunk_count() - 1)[1].0;
        Tracker {
            index,
            length,
            last: None,
        }
    }

    /// The foot of `e` found in `chunk`, its arc length the one nearer `near` where the
    /// foot is both ends of a full circle.
    fn foot(&self, chunk: usize, error: TrueError, near: f64) -> Foot {
        let index = &self.index;
        let mut along = index.length_at(chunk, error.u);
        if index.is_closed(chunk) {
            let [(start, start_point), (end, end_point)] = index.chunk_ends(chunk);
            let at = |p: Vector2| geometry::dist(&p, &error.foot) <= 1e-9 * (1.0 + p.amax());
            if at(start_point) && at(end_point) {
                along = if (near - start).abs() <= (end - near).abs() {
                    start
                } else {
                    end
                };
            }
        }
        Foot {
            chunk,
            error,
            along,
        }
    }

    /// The nearest point of the stretch `from` … `to`.
    fn nearest(&self, p: Vector2, hint: usize, from: f64, to: f64, near: f64) -> Foot {
        let (chunk, e) = self.index.error_between(p, hint, f64::NAN, from, to);
        self.foot(chunk, e, near)
    }

    /// The foot of the run's next point `p`.
    fn next(&mut self, p: Vector2) -> Foot {
        let (last_point, last) = match self.last {
            Some(last) => last,
            None => {
                let nearest = self.index.error(p, 0.0).error.abs();
                let (chunk, e) = self
                    .index
                    .first_within(p, 0.0, nearest + TIE)
                    .unwrap_or_else(|| {
                        self.index.error_between(p, 0, f64::NAN, 0.0, f64::INFINITY)
                    });
                (p, self.foot(chunk, e, 0.0))
            }
        };
        let reach = 2.0 * geometry::dist(&p, &last_point) + 4.0 * last.error.error.abs() + MARGIN;
        let (mut from, mut to) = (last.along - reach, last.along + reach);
        let mut best = self.nearest(p, last.chunk, from, to, last.along);
        let end = 1e-9 * (1.0 + self.length);
        // The distance still falls beyond an end of the stretch: extend it that way
        // while the nearest point gets nearer.
        while to < self.length && best.along >= to - end {
            let stretch = reach.max(best.error.error.abs());
            let further = self.nearest(p, best.chunk, to, to + stretch, best.along);
            if further.error.error.abs() >= best.error.error.abs() {
                break;
            }
            (best, to) = (further, to + stretch);
        }
        while from > 0.0 && best.along <= from + end {
            let stretch = reach.max(best.error.error.abs());
            let further = self.nearest(p, best.chunk, from - stretch, from, best.along);
            if further.error.error.abs() >= best.error.error.abs() {
                break;
            }
            (best, from) = (further, from - stretch);
        }
        self.last = Some((p, best));
        best
    }
}

/// Every point of a run evaluated against `geometry`, in order.
pub fn evaluate(geometry: &Geometry, points: &[Vector2]) -> Vec<PlanarSample> {
    let mut programmed = Tracker::new(&geometry.programmed);
    let mut planned = geometry.planned.as_ref().map(Tracker::new);
    let is_program = matches!(geometry.programmed, Path::Program(_));
    points
        .iter()
        .map(|&p| {
            let foot = programmed.next(p);
            let contour = foot.error.error;
            PlanarSample {
                segment: if is_program { foot.chunk } else { 0 },
                contour,
                planned: planned.as_mut().map_or(contour, |t| t.next(p).error.error),
                along: foot.along,
            }
        })
        .collect()
}

/// The size of a run's errors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Statistics {
    /// The sample of the largest |error| (the first of equal ones).
    pub at: usize,
    /// The error there, signed, mm.
    pub max: f64,
    /// Mean |error|, mm.
    pub mean: f64,
    /// Root mean square, mm.
    pub rms: f64,
}

impl Statistics {
    /// Of `values` (at least one).
    pub fn of(values: impl Iterator<Item = f64>) -> Statistics {
        let (mut at, mut max, mut sum, mut squares, mut n) = (0, 0.0f64, 0.0, 0.0, 0usize);
        for (k, v) in values.enumerate() {
            if v.abs() > max.abs() {
                (at, max) = (k, v);
            }
            sum += v.abs();
            squares += v * v;
            n += 1;
        }
        let n = n.max(1) as f64;
        Statistics {
            at,
            max,
            mean: sum / n,
            rms: (squares / n).sqrt(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use contour_core::math;
    use contour_core::path::planar::Program;

    fn program(text: &str) -> Path {
        Path::Program(Program::parse_gcode(text, "t.ngc").unwrap())
    }

    #[test]
    fn statistics_keep_the_sign_and_the_first_largest() {
        let s = Statistics::of([0.1, -0.3, 0.3, 0.0].into_iter());
        assert_eq!((s.at, s.max), (1, -0.3));
        assert!((s.mean - 0.175).abs() < 1e-15);
        assert!((s.rms - (0.19f64 / 4.0).sqrt()).abs() < 1e-15);
    }

    #[test]
    fn a_run_that_starts_mid_path_is_found_and_followed() {
        // The first point is 12 mm along a 20 mm line, 0.1 mm right of it.
        let path = program("G1 X20 F600\n");
        let geometry = Geometry::new(path, 0.0).unwrap();
        let points: Vec<Vector2> = (0..50)
            .map(|k| Vector2::new(12.0 + 0.1 * k as f64, -0.1))
            .collect();
        for s in evaluate(&geometry, &points) {
            assert!((s.contour - 0.1).abs() < 1e-12 && s.planned == s.contour);
        }
    }

    #[test]
    fn a_full_circle_is_followed_round_and_on() {
        // A full circle as one move, then a line out of it at its start: at the end of
        // the circle the foot is its start point again and must go on, not back.
        let path = program("G1 X10 F600\nG3 X10 Y0 I0 J5\nG1 X20\n");
        let geometry = Geometry::new(path, 0.0).unwrap();
        let centre = Vector2::new(10.0, 5.0);
        let mut points: Vec<Vector2> = (0..100)
            .map(|k| Vector2::new(0.1 * k as f64, -0.01))
            .collect();
        for k in 0..=400 {
            let phi = -std::f64::consts::FRAC_PI_2 + std::f64::consts::TAU * k as f64 / 400.0;
            points.push(centre + Vector2::new(math::cos(phi), math::sin(phi)) * 5.01);
        }
        points.extend((1..100).map(|k| Vector2::new(10.0 + 0.1 * k as f64, -0.01)));
        let samples = evaluate(&geometry, &points);
        let segments: Vec<usize> = samples.iter().map(|s| s.segment).collect();
        assert_eq!(segments[..100], [0; 100]);
        assert!(segments[101..500].iter().all(|&s| s == 1));
        assert!(
            segments[501..].iter().all(|&s| s == 2),
            "{:?}",
            &segments[495..]
        );
        for (k, s) in samples.iter().enumerate() {
            assert!((s.contour - 0.01).abs() < 1e-12, "{k}: {s:?}");
        }
        assert!(samples.windows(2).all(|w| w[1].along >= w[0].along - 1e-12));
    }
}
