//! The online form of the HMM segment mapping (docs/design/five-axis.md §5.2): the reference and
//! the measured samples arrive one at a time. Only the `band` newest segments are
//! candidates, and a sample's mapping can be read back `lag` samples later, so the work
//! per sample is O(band·max_skip + lag) whatever the path's length — less with a beam,
//! which drops the states that have fallen far behind the best — and nothing is
//! allocated after construction (every buffer is a ring of fixed size).
//!
//! The recursion step, the fresh start, the best state and the read-back are the shared
//! core's ([`viterbi`]); the band, the beam and the rings are this file's. With a band
//! covering the whole reference and a lag covering the whole run it decodes what
//! [`viterbi_offline`](super::hmm::viterbi_offline) decodes.

use crate::math;
use serde::{Deserialize, Serialize};

use super::hmm::{segment_cost, HmmParams};
use super::viterbi;
use crate::geometry::{self, Vector};
use crate::kinematics::Pose;

/// The online decoder. It serialises whole (for FMU state save/restore); bytes from
/// elsewhere go through [`OnlineMapper::check`] before use.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OnlineMapper {
    params: HmmParams,
    length: f64,
    band: usize,
    lag: usize,
    /// Ring capacity − 1: the rings hold a power of two ≥ band + 1 entries, so an index
    /// wraps with a mask instead of a division (several per segment and sample).
    mask: usize,
    /// The newest reference tips, unit axes and second points (index & mask).
    tips: Vec<Vector<3>>,
    axes: Vec<Vector<3>>,
    seconds: Vec<Vector<3>>,
    references: usize,
    /// C(k, j) of the latest sample for j in `valid` (index j & mask).
    cost: Vec<f64>,
    next: Vec<f64>,
    valid: (usize, usize),
    /// Predecessors (absolute segments) of the last `lag + 1` samples: row k mod
    /// (lag + 1), column j & mask. Not the core's `BackTable`: that one grows and drops
    /// rows (allocation and copying per sample), and this ring is sized once and saved
    /// as it is in the FMU state.
    back: Vec<usize>,
    samples: usize,
    previous_tip: Option<Vector<3>>,
    /// States whose cost exceeds the best by more than this are dropped (mm of summed
    /// cost; infinite: none, the exact decoder).
    beam: f64,
}

impl OnlineMapper {
    /// A decoder over the `band` (≥ 1) newest segments that can read back `lag` samples;
    /// `length` is the tool length of the second points, mm.
    pub fn new(params: HmmParams, length: f64, band: usize, lag: usize) -> Self {
        let band = band.max(1);
        let capacity = (band + 1).next_power_of_two();
        OnlineMapper {
            params,
            length,
            band,
            lag,
            mask: capacity - 1,
            tips: vec![Vector::zeros(); capacity],
            axes: vec![Vector::zeros(); capacity],
            seconds: vec![Vector::zeros(); capacity],
            references: 0,
            cost: vec![f64::INFINITY; capacity],
            next: vec![f64::INFINITY; capacity],
            valid: (0, 0),
            back: vec![0; (lag + 1) * capacity],
            samples: 0,
            previous_tip: None,
            beam: f64::INFINITY,
        }
    }

    /// The same decoder keeping only the states within `beam` (mm of summed cost) of the
    /// best: a state that far behind has fallen off the measured tool for good (every
    /// sample adds its distance), and dropping it shrinks the work from the whole band to
    /// the few segments around the tool. A non-positive or NaN beam keeps every state.
    pub fn with_beam(mut self, beam: f64) -> Self {
        self.beam = if beam > 0.0 { beam } else { f64::INFINITY };
        self
    }

    /// Appends the next reference point (tip and unit tool axis).
    pub fn push_reference(&mut self, tip: Vector<3>, axis: Vector<3>) {
        let slot = self.references & self.mask;
        self.tips[slot] = tip;
        self.axes[slot] = axis;
        self.seconds[slot] = tip + axis * self.length;
        self.references += 1;
    }

    /// Checks what construction and use guarantee, for a decoder restored from bytes:
    /// ring sizes that match the band and lag, a live range inside the band, finite
    /// points and parameters. The error names the first violation.
    pub fn check(&self) -> Result<(), String> {
        let capacity = (self.band.max(1) + 1).next_power_of_two();
        let rows = self
            .lag
            .checked_add(1)
            .and_then(|r| r.checked_mul(capacity));
        if self.band == 0 || self.mask != capacity - 1 {
            return Err(format!(
                "ring mask {} does not fit the band {}",
                self.mask, self.band
            ));
        }
        for (name, len) in [
            ("tips", self.tips.len()),
            ("axes", self.axes.len()),
            ("second points", self.seconds.len()),
            ("costs", self.cost.len()),
            ("next costs", self.next.len()),
        ] {
            if len != capacity {
                return Err(format!("{name} ring holds {len} entries, not {capacity}"));
            }
        }
        if rows != Some(self.back.len()) {
            return Err(format!(
                "back-pointer table holds {} entries, not (lag + 1)·{capacity}",
                self.back.len()
            ));
        }
        let (lo, hi) = self.valid;
        if lo > hi || hi > self.references || hi - lo > self.band {
            return Err(format!(
                "live segments {lo}..{hi} lie outside the band of the {} reference points",
                self.references
            ));
        }
        let weight = self.params.angle_weight;
        if self.params.max_skip == 0 || !(weight.is_finite() && weight >= 0.0) {
            return Err(format!("mapping parameters {:?} are invalid", self.params));
        }
        if !(self.length.is_finite() && self.length > 0.0) || self.beam.is_nan() || self.beam <= 0.0
        {
            return Err(format!(
                "tool length {} mm or beam {} mm is invalid",
                self.length, self.beam
            ));
        }
        let points = self.tips.iter().chain(&self.axes).chain(&self.seconds);
        if !points.chain(&self.previous_tip).all(geometry::is_finite)
            || self.cost.iter().chain(&self.next).any(|c| c.is_nan())
        {
            return Err("a reference point, cost or the previous tip is not finite".into());
        }
        Ok(())
    }

    /// The mapping's settings: parameters, tool length, band, lag, beam.
    pub fn settings(&self) -> (HmmParams, f64, usize, usize, f64) {
        (self.params, self.length, self.band, self.lag, self.beam)
    }

    /// Reference point `i` while it is held (it ends a held segment, or begins one).
    pub fn point(&self, i: usize) -> Option<Pose> {
        let held = self.references.saturating_sub(self.band + 1);
        (i >= held && i < self.references).then(|| Pose {
            tip: self.tips[i & self.mask],
            axis: self.axes[i & self.mask],
        })
    }

    /// Reference point `i` while it is held, or, up to [`AHEAD`] points past the newest,
    /// the reference continued with the newest chord's turn and the newest axis step
    /// (none beyond that, or with fewer than two points).
    ///
    /// The measured tool can be ahead of the newest reference sample the controller has
    /// (a reference that arrives a few samples late, an offset along the path): its foot
    /// then lies past the end, where the held points alone would clamp it to the newest
    /// point and give the newest segment a chord for the tangent at its far end. A path
    /// sampled at a steady feed continues, over a chord or two, much as its last chords
    /// turn: on a circle with equal chords and an axis turning evenly the continuation is
    /// exact.
    pub fn extended_point(&self, i: usize) -> Option<Pose> {
        let newest = self.references.checked_sub(1)?;
        if i <= newest {
            return self.point(i);
        }
        let steps = i - newest;
        if steps > AHEAD || newest == 0 {
            return None;
        }
        let at = |i: usize| (self.tips[i & self.mask], self.axes[i & self.mask]);
        let ((r0, o0), (r1, o1)) = (at(newest - 1), at(newest));
        let chord = r1 - r0;
        // The turn from the chord before to the newest one (none with two points).
        let turn = match newest.checked_sub(2).and_then(|i| self.point(i)) {
            Some(p) => Rotation::between(&(r0 - p.tip), &chord),
            None => Rotation::NONE,
        };
        let mut tip = r1;
        for step in 1..=steps {
            tip += turn.apply(&chord, step as f64);
        }
        let axis = Rotation::between(&o0, &o1).apply(&o1, steps as f64);
        Some(Pose { tip, axis })
    }

    /// Segment `j` with [`OnlineMapper::extended_point`]'s ends: held, or continued past
    /// the newest point.
    pub fn extended_segment(&self, j: usize) -> Option<(Pose, Pose)> {
        Some((
            self.extended_point(j)?,
            self.extended_point(j.checked_add(1)?)?,
        ))
    }

    /// Reference points pushed so far.
    pub fn references(&self) -> usize {
        self.references
    }

    /// The end poses of segment `j` while it is still held (one of the `band` newest).
    pub fn segment(&self, j: usize) -> Option<(Pose, Pose)> {
        Some((self.point(j)?, self.point(j.checked_add(1)?)?))
    }

    /// Samples mapped so far.
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// Maps the next measured sample (tip and unit tool axis); returns the best segment
    /// for it now, or `None` while the reference has no segment.
    pub fn push_sample(&mut self, tip: Vector<3>, axis: Vector<3>) -> Option<usize> {
        let hi = self.references.saturating_sub(1);
        let lo = hi.saturating_sub(self.band);
        if hi == lo {
            return None;
        }
        let second = tip + axis * self.length;
        let motion = self.previous_tip.map_or(Vector::zeros(), |p| tip - p);
        let (mask, skip) = (self.mask, self.params.max_skip);
        let row = (self.samples % (self.lag + 1)) * (mask + 1);
        // Live states of the previous sample are [vlo, vhi); they reach [vlo, vhi − 1 + K].
        let (vlo, vhi) = self.valid;
        let live = if self.samples > 0 { vlo..vhi } else { 0..0 };
        let (mut from, mut to) = if live.is_empty() {
            (lo, hi)
        } else {
            (lo.max(vlo), hi.min(vhi + skip))
        };
        let (tips, seconds, params) = (&self.tips, &self.seconds, &self.params);
        let c = |j: usize| {
            let (a, b) = (j & mask, (j + 1) & mask);
            let (r, s) = ([&tips[a], &tips[b]], [&seconds[a], &seconds[b]]);
            segment_cost(params, r, s, &tip, &second, &motion)
        };
        let (cost, next, back) = (&self.cost, &mut self.next, &mut self.back[row..]);
        let mut store = |j: usize, cj, i| {
            next[j & mask] = cj;
            back[j & mask] = i;
        };
        let previous = |i: usize| cost[i & mask];
        let reachable = viterbi::step(
            skip,
            from..to,
            live,
            previous,
            |j, best| best + c(j),
            &mut store,
        );
        if !reachable {
            // The first sample, or the band ran past every path: start afresh (any
            // segment, no history).
            (from, to) = (lo, hi);
            viterbi::start(lo..hi, c, store);
        }
        // The beam: states costlier than the best by more than `beam` are dropped.
        let least = (from..to)
            .map(|j| self.next[j & self.mask])
            .fold(f64::INFINITY, f64::min);
        let (mut first, mut last) = (to, from);
        for j in from..to {
            let slot = &mut self.next[j & self.mask];
            if *slot > least + self.beam || slot.is_nan() {
                *slot = f64::INFINITY;
            } else {
                first = first.min(j);
                last = j + 1;
            }
        }
        if first >= last {
            // Nothing finite (a NaN observation): keep the range so the next sample
            // restarts.
            (first, last) = (from, to);
        }
        std::mem::swap(&mut self.cost, &mut self.next);
        self.valid = (first, last);
        self.samples += 1;
        self.previous_tip = Some(tip);
        Some(self.best())
    }

    /// The oldest segment still held (the band's first): a mapping there, once the band
    /// is full, has the tool at or behind the band's tail, where the segment it is on may
    /// have left the band.
    pub fn oldest_segment(&self) -> usize {
        self.references.saturating_sub(1).saturating_sub(self.band)
    }

    /// Whether every segment the band can hold is held (the reference has more than
    /// `band` segments).
    pub fn band_is_full(&self) -> bool {
        self.references > self.band + 1
    }

    /// Forgets the path of costs: the next sample is mapped afresh, to its own least-cost
    /// segment in the band, as the first one is. For a mapping that has lost the tool, or
    /// may (left behind the band, or outrun by a tool faster than `max_skip` segments per
    /// sample): the recursion alone would need many samples to come back, if it does.
    pub fn restart(&mut self) {
        self.valid = (0, 0);
    }

    /// The segment of least cost for the newest sample (ties to the lower segment).
    fn best(&self) -> usize {
        let (lo, hi) = self.valid;
        viterbi::best_state(lo..hi, |j| self.cost[j & self.mask])
    }

    /// The mapping of the sample `steps` before the newest (0 = the newest), along the
    /// best path to the newest: `None` beyond the lag or before the first sample.
    pub fn mapped(&self, steps: usize) -> Option<usize> {
        if self.samples == 0 || steps > self.lag || steps >= self.samples {
            return None;
        }
        let newest = self.samples - 1;
        let (rows, columns) = (self.lag + 1, self.mask + 1);
        let predecessor = |k: usize, j: usize| self.back[(k % rows) * columns + (j & self.mask)];
        Some(viterbi::backtrack(
            newest,
            self.best(),
            newest - steps,
            predecessor,
            |_, _| {},
        ))
    }
}

/// How many reference points [`OnlineMapper::extended_point`] continues past the newest.
pub const AHEAD: usize = 3;

/// A rotation about a unit axis, applied as a multiple of its angle (Rodrigues).
#[derive(Clone, Copy, Debug)]
struct Rotation {
    axis: Vector<3>,
    angle: f64,
}

impl Rotation {
    const NONE: Rotation = Rotation {
        axis: Vector::<3>::new(0.0, 0.0, 1.0),
        angle: 0.0,
    };

    /// The least rotation turning the direction of `a` into that of `b` (none when
    /// either is zero or they are parallel: nothing to continue, or no unique plane).
    fn between(a: &Vector<3>, b: &Vector<3>) -> Rotation {
        match geometry::unit(&a.cross(b)) {
            Some(axis) => Rotation {
                axis,
                angle: geometry::angle_between(a, b),
            },
            None => Rotation::NONE,
        }
    }

    /// `v` turned by `times` the angle.
    fn apply(&self, v: &Vector<3>, times: f64) -> Vector<3> {
        let (s, c) = math::sincos(self.angle * times);
        let k = &self.axis;
        v * c + k.cross(v) * s + k * (k.dot(v) * (1.0 - c))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contour::five_axis::hmm::{viterbi_offline, ReferencePolyline};

    type V3 = Vector<3>;

    fn spiral(n: usize) -> (Vec<V3>, Vec<V3>) {
        let tips = (0..n)
            .map(|j| {
                let t = j as f64 * 0.15;
                V3::new(30.0 * math::cos(t), 30.0 * math::sin(t), 0.5 * t)
            })
            .collect();
        let axes = (0..n)
            .map(|j| {
                let lean = 0.4 * math::sin(j as f64 * 0.05);
                V3::new(math::sin(lean), 0.0, math::cos(lean))
            })
            .collect();
        (tips, axes)
    }

    #[test]
    fn past_the_newest_point_a_circle_and_an_evenly_turning_axis_continue_exactly() {
        // Chords of 0.03 rad on a circle of radius 1 mm tilted out of the x–y plane, the
        // axis turning 0.002 rad a point along a great circle: the three points past the
        // newest are the circle's and the axis's next ones.
        let (radius, step, turn) = (1.0, 0.03, 0.002);
        let (u, w) = (
            V3::new(1.0, 0.0, 0.0),
            geometry::unit(&V3::new(0.0, 0.8, 0.6)).unwrap(),
        );
        let start = geometry::unit(&V3::new(0.1, 0.2, 1.0)).unwrap();
        let about = geometry::unit(&start.cross(&V3::new(0.3, -1.0, 0.2))).unwrap();
        let pose = |i: usize| {
            let phi = step * i as f64;
            let tip = (u * math::cos(phi) + w * math::sin(phi)) * radius + V3::new(5.0, -2.0, 1.0);
            let axis = Rotation {
                axis: about,
                angle: turn,
            }
            .apply(&start, i as f64);
            Pose { tip, axis }
        };
        let mut mapper = OnlineMapper::new(
            HmmParams {
                max_skip: 3,
                angle_weight: 0.5,
            },
            100.0,
            8,
            2,
        );
        assert!(mapper.extended_point(0).is_none());
        mapper.push_reference(pose(0).tip, pose(0).axis);
        assert!(
            mapper.extended_point(1).is_none(),
            "one point: nothing to continue"
        );
        for i in 1..20 {
            mapper.push_reference(pose(i).tip, pose(i).axis);
        }
        for i in 11..=22 {
            let (got, want) = (mapper.extended_point(i).unwrap(), pose(i));
            let off = geometry::dist(&got.tip, &want.tip);
            assert!(off < 1e-13, "point {i}: tip off by {off}");
            let off = geometry::angle_between(&got.axis, &want.axis);
            assert!(off < 1e-13, "point {i}: axis off by {off}");
        }
        // Held points are as pushed; beyond AHEAD, or before the band, nothing.
        assert_eq!(mapper.extended_point(19), mapper.point(19));
        assert!(mapper.extended_point(19 + AHEAD + 1).is_none());
        assert!(mapper.extended_point(10).is_none());
        assert_eq!(
            mapper.extended_segment(20).map(|(a, _)| a),
            mapper.extended_point(20)
        );
        assert!(mapper.extended_segment(19 + AHEAD).is_none());

        // With two points, the continuation is straight.
        let mut two = OnlineMapper::new(
            HmmParams {
                max_skip: 3,
                angle_weight: 0.5,
            },
            100.0,
            8,
            2,
        );
        two.push_reference(V3::zeros(), V3::z());
        two.push_reference(V3::new(0.03, 0.0, 0.0), V3::z());
        let next = two.extended_point(3).unwrap();
        assert!((next.tip - V3::new(0.09, 0.0, 0.0)).amax() < 1e-15);
        assert_eq!(next.axis, V3::z());
    }

    #[test]
    fn with_everything_in_view_it_decodes_as_offline() {
        let params = HmmParams {
            max_skip: 2,
            angle_weight: 0.7,
        };
        let (tips, axes) = spiral(30);
        let run: Vec<V3> = tips.iter().map(|p| p + V3::new(0.3, -0.2, 0.1)).collect();
        let n = 25;
        let reference = ReferencePolyline::new(&tips, &axes, 80.0);
        let seconds: Vec<V3> = run.iter().zip(&axes).map(|(p, o)| p + o * 80.0).collect();
        let offline = viterbi_offline(&reference, &params, &run[..n], &seconds[..n]);
        let mut online = OnlineMapper::new(params, 80.0, 40, 40);
        for (p, o) in tips.iter().zip(&axes) {
            online.push_reference(*p, *o);
        }
        for k in 0..n {
            online.push_sample(run[k], axes[k]);
        }
        for (k, &j) in offline.iter().enumerate() {
            assert_eq!(online.mapped(n - 1 - k), Some(j), "sample {k}");
        }
    }

    #[test]
    fn streaming_with_a_band_and_a_lag_commits_what_offline_decodes() {
        // The reference runs 12 samples ahead of the measured tool (a following error),
        // a band of 24 segments and a lag of 8 samples: every committed decision equals
        // the offline decoding of the same data.
        let params = HmmParams {
            max_skip: 1,
            angle_weight: 1.0,
        };
        let (tips, axes) = spiral(400);
        let lead = 12;
        let run: Vec<V3> = tips.iter().map(|p| p + V3::new(0.0, 0.1, -0.05)).collect();
        let n = tips.len() - lead;
        let reference = ReferencePolyline::new(&tips, &axes, 80.0);
        let seconds: Vec<V3> = run.iter().zip(&axes).map(|(p, o)| p + o * 80.0).collect();
        let offline = viterbi_offline(&reference, &params, &run[..n], &seconds[..n]);
        let (band, lag) = (24, 8);
        let mut online = OnlineMapper::new(params, 80.0, band, lag);
        // With a beam of 2 mm it commits the same decisions.
        let mut beamed = OnlineMapper::new(params, 80.0, band, lag).with_beam(2.0);
        for j in 0..lead {
            online.push_reference(tips[j], axes[j]);
            beamed.push_reference(tips[j], axes[j]);
        }
        let mut committed = 0;
        for k in 0..n {
            online.push_reference(tips[k + lead], axes[k + lead]);
            online.push_sample(run[k], axes[k]);
            beamed.push_reference(tips[k + lead], axes[k + lead]);
            beamed.push_sample(run[k], axes[k]);
            if k >= lag {
                assert_eq!(beamed.mapped(lag), online.mapped(lag), "beam, sample {k}");
                assert_eq!(
                    online.mapped(lag),
                    Some(offline[k - lag]),
                    "sample {}",
                    k - lag
                );
                committed += 1;
            }
        }
        assert_eq!(committed, n - lag);
        assert!(online.mapped(lag + 1).is_none());
        // The band's segments are held with their poses, older ones are gone.
        let newest = tips.len() - 2;
        let (a, b) = online.segment(newest).unwrap();
        assert_eq!(
            (a.tip, b.tip, b.axis),
            (tips[newest], tips[newest + 1], axes[newest + 1])
        );
        assert!(online.segment(newest + 1 - band).is_some());
        assert!(online.segment(newest - band).is_none() && online.segment(newest + 1).is_none());
    }
}
