//! The true five-axis contour errors of a run: how far each measured tool tip is from the
//! reference tool path, and the angle between its tool axis and the reference axis at the
//! nearest point (docs/campaigns.md, "Metrics").
//!
//! The reference is the interpolator's own output, one pose per sample, as the fmpy
//! engine's metrics (`contour_fmu.checks.five_axis_truth`) take it, so the two engines
//! measure the same thing: between samples the tip path is the Catmull-Rom cubic through
//! the neighbouring samples, cut into [`UPSAMPLE`] chords per interval, and the axis the
//! normalised interpolation of its end axes. A measured tip is projected onto the chords
//! of the [`WINDOW`] intervals up to its own time (at a figure-eight's crossing the branch
//! not yet reached, or long passed, is never taken).
//!
//! Written independently of the Python: the poses come from contour-core's kinematics, and
//! the nearest chord is found by bounding balls around each interval's chords, which skip
//! an interval only when it cannot hold the nearest chord; equal distances go to the
//! earlier chord, as a scan would find them (a test checks against the plain scan).

use contour_core::geometry::Vector;
use contour_core::kinematics::{Joints, TableTiltingAc};
use contour_core::math;

/// Chords per reference interval.
pub const UPSAMPLE: usize = 16;
/// Reference intervals searched back from a measured sample's own time.
pub const WINDOW: usize = 150;

type Point = [f64; 3];

fn sub(a: Point, b: Point) -> Point {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: Point, b: Point) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: Point) -> f64 {
    dot(a, a).sqrt()
}

fn point(v: &Vector<3>) -> Point {
    [v[0], v[1], v[2]]
}

/// The reference tool path of a run, cut into chords.
pub struct ReferenceToolPath {
    /// The chords' ends: `UPSAMPLE` per interval between distinct reference tips, then the
    /// last tip.
    dense: Vec<Point>,
    /// The unit tool axis at each of `dense`.
    axes: Vec<Point>,
    /// Reference sample k → its distinct tip (repeated samples, before the start and after
    /// the end, would make chords of no length).
    distinct: Vec<usize>,
    /// Per interval: the centre and radius of a ball holding its chords.
    balls: Vec<(Point, f64)>,
}

/// A measured pose's errors: tip distance (mm) and orientation angle (rad).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoseError {
    pub tip: f64,
    pub orientation: f64,
}

impl ReferenceToolPath {
    /// The path of the reference joints (one pose per sample) on `machine`.
    pub fn new(machine: &TableTiltingAc, reference: &[Joints]) -> ReferenceToolPath {
        let mut tips: Vec<Point> = Vec::with_capacity(reference.len());
        let mut axes: Vec<Point> = Vec::with_capacity(reference.len());
        let mut distinct = Vec::with_capacity(reference.len());
        for q in reference {
            let pose = machine.forward(q);
            let tip = point(&pose.tip);
            if tips.last() != Some(&tip) {
                tips.push(tip);
                axes.push(point(&pose.axis));
            }
            distinct.push(tips.len() - 1);
        }
        let (dense, axes) = densified(&tips, &axes);
        let balls = dense
            .windows(UPSAMPLE + 1)
            .step_by(UPSAMPLE)
            .map(bounding_ball)
            .collect();
        ReferenceToolPath {
            dense,
            axes,
            distinct,
            balls,
        }
    }

    /// The errors of the measured joints `q` at sample `k` (reference samples up to
    /// k + `ahead` are searched). `None` when the reference is a single point.
    pub fn error(
        &self,
        machine: &TableTiltingAc,
        q: &Joints,
        k: usize,
        ahead: usize,
    ) -> Option<PoseError> {
        let newest = self.distinct[(k + ahead).min(self.distinct.len() - 1)];
        let last = self.dense.len() - 1;
        let lo = newest.saturating_sub(WINDOW) * UPSAMPLE;
        let mut hi = (newest * UPSAMPLE).min(last);
        if hi == lo {
            hi = (lo + UPSAMPLE).min(last);
        }
        if hi == lo {
            return None;
        }
        let pose = machine.forward(q);
        let (p, o) = (point(&pose.tip), point(&pose.axis));
        let (j, t, tip) = self.nearest_chord(p, lo, hi);
        let a = self.axes[j];
        let b = self.axes[j + 1];
        let mut axis = [0.0; 3];
        for i in 0..3 {
            axis[i] = a[i] * (1.0 - t) + b[i] * t;
        }
        let length = norm(axis);
        let axis = axis.map(|v| v / length);
        let cross = [
            o[1] * axis[2] - o[2] * axis[1],
            o[2] * axis[0] - o[0] * axis[2],
            o[0] * axis[1] - o[1] * axis[0],
        ];
        Some(PoseError {
            tip,
            orientation: math::atan2(norm(cross), dot(o, axis)),
        })
    }

    /// (chord, its foot parameter, distance) of the chord in `lo..hi` nearest `p`; equal
    /// distances go to the first. Intervals whose ball is farther than the best chord so
    /// far are skipped; the search starts with the newest interval, where a tool that
    /// follows its reference is.
    fn nearest_chord(&self, p: Point, lo: usize, hi: usize) -> (usize, f64, f64) {
        let intervals = lo / UPSAMPLE..hi.div_ceil(UPSAMPLE);
        let newest = intervals.end - 1;
        let mut best = (usize::MAX, 0.0, f64::INFINITY);
        self.scan(p, newest, hi, &mut best);
        for interval in intervals.clone().rev().skip(1) {
            let (centre, radius) = self.balls[interval];
            let gap = norm(sub(p, centre)) - radius;
            // A margin for the rounding of both distances: an interval is skipped only when
            // it surely holds nothing nearer than, or as near as, the best.
            if gap > best.2 + 1e-9 * (1.0 + radius + best.2) {
                continue;
            }
            self.scan(p, interval, hi, &mut best);
        }
        best
    }

    /// The chords of `interval` (below `hi`) into `best`.
    fn scan(&self, p: Point, interval: usize, hi: usize, best: &mut (usize, f64, f64)) {
        let first = interval * UPSAMPLE;
        for j in first..(first + UPSAMPLE).min(hi) {
            let (a, b) = (self.dense[j], self.dense[j + 1]);
            let ab = sub(b, a);
            let length2 = dot(ab, ab);
            let t = if length2 > 0.0 {
                (dot(sub(p, a), ab) / length2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let foot = [a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]];
            let d = norm(sub(p, foot));
            if d < best.2 || (d == best.2 && j < best.0) {
                *best = (j, t, d);
            }
        }
    }
}

/// The Catmull-Rom chords' ends through `tips` and the unit axes at them.
fn densified(tips: &[Point], axes: &[Point]) -> (Vec<Point>, Vec<Point>) {
    let n = tips.len();
    if n < 2 {
        return (tips.to_vec(), axes.to_vec());
    }
    let mirrored = |a: Point, b: Point| [2.0 * a[0] - b[0], 2.0 * a[1] - b[1], 2.0 * a[2] - b[2]];
    let before = mirrored(tips[0], tips[1]);
    let after = mirrored(tips[n - 1], tips[n - 2]);
    let tip = |i: isize| -> Point {
        if i < 0 {
            before
        } else if i as usize >= n {
            after
        } else {
            tips[i as usize]
        }
    };
    let mut dense = Vec::with_capacity((n - 1) * UPSAMPLE + 1);
    let mut turned = Vec::with_capacity((n - 1) * UPSAMPLE + 1);
    for i in 0..n - 1 {
        let k = i as isize;
        let (p0, p1, p2, p3) = (tip(k - 1), tip(k), tip(k + 1), tip(k + 2));
        for step in 0..UPSAMPLE {
            let s = step as f64 / UPSAMPLE as f64;
            let mut at = [0.0; 3];
            let mut axis = [0.0; 3];
            for c in 0..3 {
                let linear = p2[c] - p0[c];
                let square = 2.0 * p0[c] - 5.0 * p1[c] + 4.0 * p2[c] - p3[c];
                let cube = 3.0 * p1[c] - p0[c] - 3.0 * p2[c] + p3[c];
                at[c] = 0.5 * (2.0 * p1[c] + linear * s + square * (s * s) + cube * (s * s * s));
                axis[c] = axes[i][c] * (1.0 - s) + axes[i + 1][c] * s;
            }
            dense.push(at);
            let length = norm(axis);
            turned.push(axis.map(|v| v / length));
        }
    }
    dense.push(tips[n - 1]);
    let length = norm(axes[n - 1]);
    turned.push(axes[n - 1].map(|v| v / length));
    (dense, turned)
}

/// A ball holding the points (and so the chords between them).
fn bounding_ball(points: &[Point]) -> (Point, f64) {
    let (a, b) = (points[0], points[points.len() - 1]);
    let centre = [
        0.5 * (a[0] + b[0]),
        0.5 * (a[1] + b[1]),
        0.5 * (a[2] + b[2]),
    ];
    let radius = points
        .iter()
        .map(|&q| norm(sub(q, centre)))
        .fold(0.0, f64::max);
    (centre, radius)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn helix(n: usize, pitch: f64) -> Vec<Joints> {
        (0..n)
            .map(|k| {
                let u = k as f64 * 0.01;
                Joints::from([
                    20.0 * math::cos(u),
                    20.0 * math::sin(u),
                    pitch * u,
                    0.3 + 0.1 * math::sin(u),
                    0.5 * u,
                ])
            })
            .collect()
    }

    /// The plain scan of every chord in the window, as the definition reads.
    fn scanned(path: &ReferenceToolPath, p: Point, lo: usize, hi: usize) -> (usize, f64, f64) {
        let mut best = (usize::MAX, 0.0, f64::INFINITY);
        for interval in lo / UPSAMPLE..hi.div_ceil(UPSAMPLE) {
            path.scan(p, interval, hi, &mut best);
        }
        best
    }

    /// The bounded search finds the chord the plain scan finds, bit for bit: on a helix
    /// with a lagging and wandering tool, and on a path that crosses itself (a
    /// figure-eight), where chords far apart in time are near in space.
    #[test]
    fn the_bounded_search_finds_what_the_plain_scan_finds() {
        let machine = TableTiltingAc {
            a_pivot: Vector::<3>::new(0.0, 5.0, -30.0),
            c_pivot: Vector::<3>::new(1.0, -2.0, 0.0),
        };
        let eight: Vec<Joints> = (0..2000)
            .map(|k| {
                let u = k as f64 * std::f64::consts::TAU / 400.0;
                Joints::from([
                    30.0 * math::sin(u),
                    15.0 * math::sin(2.0 * u),
                    0.0,
                    0.2,
                    0.0,
                ])
            })
            .collect();
        for reference in [helix(3000, 2.0), eight] {
            let path = ReferenceToolPath::new(&machine, &reference);
            let mut compared = 0;
            for k in 0..reference.len() {
                let lag = (k % 37) as f64 * 0.3;
                let mut q = reference[k.saturating_sub(lag as usize)];
                q[0] += 0.01 * math::sin(k as f64 * 0.7);
                q[2] -= 0.02 * math::cos(k as f64 * 0.3);
                let pose = machine.forward(&q);
                let newest = path.distinct[k];
                let lo = newest.saturating_sub(WINDOW) * UPSAMPLE;
                let mut hi = (newest * UPSAMPLE).min(path.dense.len() - 1);
                if hi == lo {
                    hi = (lo + UPSAMPLE).min(path.dense.len() - 1);
                }
                let p = point(&pose.tip);
                assert_eq!(
                    path.nearest_chord(p, lo, hi),
                    scanned(&path, p, lo, hi),
                    "{k}"
                );
                compared += 1;
            }
            assert_eq!(compared, reference.len());
        }
    }

    /// A tool on the reference's samples is on the path; one moved off it by a known
    /// distance along the normal of a straight line, and turned by a known angle, has
    /// those errors.
    #[test]
    fn known_offsets_are_measured() {
        let machine = TableTiltingAc::ORIGIN;
        let line: Vec<Joints> = (0..500)
            .map(|k| Joints::from([k as f64 * 0.05, 0.0, 0.0, 0.0, 0.0]))
            .collect();
        let path = ReferenceToolPath::new(&machine, &line);
        for k in [0, 1, 10, 200, 499] {
            let on = path.error(&machine, &line[k], k, 0).unwrap();
            assert!(on.tip < 1e-12 && on.orientation < 1e-12, "{k}: {on:?}");
            let mut off = line[k.saturating_sub(3)];
            off[1] = 0.125;
            off[3] = 0.01;
            let e = path.error(&machine, &off, k, 0).unwrap();
            // Rx(−A) turns the tip's y = 0.125 by A about the x axis: its distance from
            // the x axis stays 0.125.
            assert!((e.tip - 0.125).abs() < 1e-12, "{k}: {e:?}");
            assert!((e.orientation - 0.01).abs() < 1e-12, "{k}: {e:?}");
        }
    }

    /// Samples that repeat a pose (before the start, after the end) make no chord; a
    /// reference that never moves is a single point, with no chord to measure against.
    #[test]
    fn repeated_poses_make_no_chords() {
        let machine = TableTiltingAc::ORIGIN;
        let mut reference = vec![Joints::zeros(); 5];
        reference.extend(helix(50, 1.0));
        reference.extend(vec![*reference.last().unwrap(); 5]);
        let path = ReferenceToolPath::new(&machine, &reference);
        // The standstill's one tip and the helix's 50.
        assert_eq!(path.dense.len(), 50 * UPSAMPLE + 1);
        assert_eq!(path.distinct[..7], [0, 0, 0, 0, 0, 1, 2]);
        assert_eq!(path.distinct[path.distinct.len() - 6..], [50; 6]);
        let still = ReferenceToolPath::new(&machine, &[Joints::zeros(); 4]);
        assert_eq!(still.error(&machine, &Joints::zeros(), 2, 0), None);
    }
}
