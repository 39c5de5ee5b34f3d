//! Whole-run evaluation of a measured five-axis run against its reference (docs/design/five-axis.md
//! §5.2–5.3a): the Viterbi segment mapping of every measured sample, the foot-point tip
//! and orientation errors of each sample, and the evaluation-function estimate at each
//! reference point.
//!
//! The mapping scales to long runs: each sample considers only a window of `window`
//! segments around the previous sample's best segment, back-pointers are stored as one
//! byte (the skip j − i ≤ 255), and decisions are committed as soon as every surviving
//! path passes through one segment, after which their rows are dropped. Memory is
//! O(window · undecided samples) — a few hundred rows in practice — plus O(samples) for
//! the result; time is O(samples · window · max_skip). The recursion step, the
//! back-pointer table and the backtrack are the shared core's ([`viterbi`]); the
//! window's placement and the commits are this file's. Where the window holds every
//! segment that matters the result is exactly
//! [`viterbi_offline`](super::hmm::viterbi_offline)'s.

use std::fmt;
use std::sync::Arc;

use super::evaluation::{self, Evaluation};
use super::hmm::{HmmParams, ReferencePolyline};
use super::reference_shape::{foot_error, ReferenceShape};
use super::run_mapping::{map_run, Observer};
use super::viterbi::{self, BackTable};
use super::window_costs::{CostScratch, SegmentTable};
use crate::geometry::slerp;
use crate::geometry::{self, Vector};
use crate::kinematics::{Joints, Pose, TableTiltingAc};

/// Samples between attempts to commit decisions (doubled while survivors stay apart).
const CHECK_EVERY: usize = 1024;

/// The windowed offline Viterbi decoder, fed one observation at a time.
#[derive(Clone, Debug)]
pub struct WindowedViterbi {
    /// The reference's segments, as the window's costs read them (shared with a thread
    /// that computes costs ahead, [`super::run_mapping`]).
    segments: Arc<SegmentTable>,
    params: HmmParams,
    width: usize,
    /// First segment of the newest row's window.
    lo: usize,
    /// C(k, lo + s) of the newest sample.
    cost: Vec<f64>,
    next: Vec<f64>,
    /// c(k, lo + s) of the newest sample, and the work space computing them.
    state_costs: Vec<f64>,
    scratch: CostScratch,
    /// Back-pointers of the undecided samples (from the first undecided one), as bytes.
    back: BackTable<u8>,
    decided: Vec<usize>,
    samples: usize,
    previous_tip: Option<Vector<3>>,
    check_every: usize,
    next_check: usize,
}

impl WindowedViterbi {
    /// A decoder over `reference` with `window` candidate segments per sample (at least
    /// `max_skip + 1`, at most the segment count). `None` when the reference has no
    /// segment or `max_skip` exceeds 255 (the back-pointers are bytes).
    pub fn new(reference: &ReferencePolyline, params: HmmParams, window: usize) -> Option<Self> {
        let m = reference.segments();
        if m == 0 || params.max_skip > u8::MAX as usize {
            return None;
        }
        let width = window.max(params.max_skip + 1).min(m);
        Some(WindowedViterbi {
            segments: Arc::new(SegmentTable::new(reference)),
            params,
            width,
            lo: 0,
            cost: vec![f64::INFINITY; width],
            next: vec![f64::INFINITY; width],
            state_costs: vec![0.0; width],
            scratch: CostScratch::default(),
            back: BackTable::new(width),
            decided: Vec::new(),
            samples: 0,
            previous_tip: None,
            check_every: CHECK_EVERY,
            next_check: CHECK_EVERY,
        })
    }

    /// How many samples pass between attempts to commit (≥ 1). Affects memory and time
    /// only, never the decoded mapping.
    pub fn check_every(mut self, samples: usize) -> Self {
        self.check_every = samples.max(1);
        self.next_check = self.samples + self.check_every;
        self
    }

    /// Candidate segments per sample.
    pub fn width(&self) -> usize {
        self.width
    }

    /// The reference's segments as the decoder costs them.
    pub fn segments(&self) -> Arc<SegmentTable> {
        Arc::clone(&self.segments)
    }

    /// Samples whose mapping is still open (their back-pointer rows are held).
    pub fn pending(&self) -> usize {
        self.samples - self.back.first()
    }

    /// The mapping of the samples decided so far, in order.
    pub fn decided(&self) -> &[usize] {
        &self.decided
    }

    /// The segment of least cost for the newest sample (ties to the lower segment).
    fn best(&self) -> usize {
        viterbi::best_state(self.lo..self.lo + self.width, |j| self.cost[j - self.lo])
    }

    /// Adds the next observation: tool tip and second point (L mm up the tool axis).
    pub fn push(&mut self, tip: &Vector<3>, second: &Vector<3>) {
        self.push_costed(tip, second, None);
    }

    /// The segments of the next sample's window: centred on the newest sample's best
    /// segment, never below the newest window (nothing below it is reachable), within the
    /// reference; `None` before the first sample (which scans every segment).
    fn next_window(&self) -> Option<std::ops::Range<usize>> {
        let (m, w) = (self.segments.segments(), self.width);
        (self.samples > 0).then(|| {
            let lo = self.best().saturating_sub(w / 2).max(self.lo).min(m - w);
            lo..lo + w
        })
    }

    /// [`push`](Self::push), with the costs c(k, j) of the segments `band.0 ..` given as
    /// `band.1` where they were computed already (by [`SegmentTable::costs`] for this
    /// observation): used where they cover the window (the result says whether they
    /// did), computed here otherwise.
    pub fn push_costed(
        &mut self,
        tip: &Vector<3>,
        second: &Vector<3>,
        band: Option<(usize, &[f64])>,
    ) -> bool {
        let motion = self.previous_tip.map_or(Vector::zeros(), |p| tip - p);
        let observation = [tip, second, &motion];
        let covered = if self.samples == 0 {
            self.start(observation);
            false
        } else {
            self.step(observation, band)
        };
        self.samples += 1;
        self.previous_tip = Some(*tip);
        self.commit_now_and_then();
        covered
    }

    /// The first sample, which may be anywhere: one full scan places the window.
    fn start(&mut self, observation: [&Vector<3>; 3]) {
        let (m, w) = (self.segments.segments(), self.width);
        let mut all = vec![0.0; m];
        let scratch = &mut self.scratch;
        self.segments
            .costs(&self.params, 0, observation, &mut all, scratch);
        let best = all
            .iter()
            .enumerate()
            .fold(
                (0, f64::INFINITY),
                |b, (j, &c)| if c < b.1 { (j, c) } else { b },
            )
            .0;
        self.lo = best.saturating_sub(w / 2).min(m - w);
        let (lo, cost) = (self.lo, &mut self.cost);
        let mut row = self.back.push_row(lo);
        viterbi::start(
            lo..lo + w,
            |j| all[j],
            |j, cj, i| {
                cost[j - lo] = cj;
                row.set(j, i);
            },
        );
    }

    /// A later sample: the window moved, its costs taken from `band` where it covers the
    /// window (whether it did), the recursion's step.
    fn step(&mut self, observation: [&Vector<3>; 3], band: Option<(usize, &[f64])>) -> bool {
        let (w, skip) = (self.width, self.params.max_skip);
        let previous_lo = self.lo;
        self.lo = self.next_window().expect("a sample was pushed").start;
        let lo = self.lo;
        let given = band.and_then(|(first, costs)| {
            let from = lo.checked_sub(first)?;
            costs.get(from..from + w)
        });
        let covered = given.is_some();
        let state_costs = match given {
            Some(costs) => costs,
            None => {
                let (costs, scratch) = (&mut self.state_costs, &mut self.scratch);
                self.segments
                    .costs(&self.params, lo, observation, costs, scratch);
                &self.state_costs
            }
        };
        let (cost, next) = (&self.cost, &mut self.next);
        let mut row = self.back.push_row(lo);
        if skip == 1 {
            step_adjacent(cost, lo - previous_lo, state_costs, next, |s, skip| {
                row.set(lo + s, lo + s - skip)
            });
        } else {
            let previous = |i: usize| cost[i - previous_lo];
            // A state without a finite predecessor (the window moved past them all) stays
            // out of reach, whatever its own cost.
            let score = |j: usize, best: f64| {
                if best.is_finite() {
                    best + state_costs[j - lo]
                } else {
                    f64::INFINITY
                }
            };
            let live = previous_lo..previous_lo + w;
            viterbi::step(skip, lo..lo + w, live, previous, score, |j, cj, i| {
                next[j - lo] = cj;
                row.set(j, i);
            });
        }
        std::mem::swap(&mut self.cost, &mut self.next);
        covered
    }

    /// Commits what the survivors agree on, every so often.
    fn commit_now_and_then(&mut self) {
        if self.samples >= self.next_check {
            let before = self.pending();
            self.commit_merged();
            // Survivors still apart: wait longer before the next look (bounded work).
            let wait = if self.pending() >= before {
                self.check_every.max(self.pending())
            } else {
                self.check_every
            };
            self.next_check = self.samples + wait;
        }
    }

    /// Writes the path ending in segment `j` at sample `k` back to the first undecided
    /// sample, and drops those rows.
    fn commit_through(&mut self, k: usize, j: usize) {
        let first = self.back.first();
        let start = self.decided.len();
        self.decided.resize(start + k + 1 - first, 0);
        let (back, decided) = (&self.back, &mut self.decided[start..]);
        let predecessor = |kk, j| back.predecessor(kk, j);
        viterbi::backtrack(k, j, first, predecessor, |kk, j| decided[kk - first] = j);
        self.back.drop_before(k + 1);
    }

    /// Commits every sample through which all finite survivors of the newest row pass.
    fn commit_merged(&mut self) {
        let newest = self.samples - 1;
        let mut alive: Vec<usize> = (0..self.width)
            .filter(|&s| self.cost[s].is_finite())
            .map(|s| self.lo + s)
            .collect();
        let mut k = newest;
        while alive.len() > 1 && k > self.back.first() {
            for j in alive.iter_mut() {
                *j = self.back.predecessor(k, *j);
            }
            alive.sort_unstable();
            alive.dedup();
            k -= 1;
        }
        // Merged at k (but never commit the newest row: it still decides the window).
        if alive.len() == 1 && k < newest {
            self.commit_through(k, alive[0]);
        }
    }

    /// The whole mapping: the rest traced back from the last sample's best segment.
    pub fn finish(mut self) -> Vec<usize> {
        if self.samples > self.back.first() {
            let j = self.best();
            self.commit_through(self.samples - 1, j);
        }
        self.decided
    }
}

/// [`viterbi::step`] for `max_skip` = 1 over the window (the windowed decoder's usual
/// case: a reference coarser than the measurement), the same costs and predecessors
/// without the general step's range arithmetic per state: `previous` the last sample's
/// costs from its window's first state, `shift` how far the window moved since, `costs`
/// c(k, ·) of the new window, `next` its C(k, ·); `set(s, skip)` records state `s`'s
/// predecessor as `skip` (0 or 1) states back.
fn step_adjacent(
    previous: &[f64],
    shift: usize,
    costs: &[f64],
    next: &mut [f64],
    mut set: impl FnMut(usize, usize),
) {
    let w = costs.len();
    for (s, (c, n)) in costs.iter().zip(next.iter_mut()).enumerate() {
        let p = s + shift;
        let back = if (1..=w).contains(&p) {
            previous[p - 1]
        } else {
            f64::INFINITY
        };
        let here = if p < w { previous[p] } else { f64::INFINITY };
        // As best_predecessor: one back first, the state itself on a strictly lower cost;
        // a state without a finite predecessor stays out of reach.
        let (mut best, mut skip) = (f64::INFINITY, 0);
        if back < best {
            (best, skip) = (back, 1);
        }
        if here < best {
            (best, skip) = (here, 0);
        }
        *n = if best.is_finite() {
            best + c
        } else {
            f64::INFINITY
        };
        set(s, skip);
    }
}

/// [`WindowedViterbi`] over whole slices: the same mapping as
/// [`viterbi_offline`](super::hmm::viterbi_offline) when the window covers what matters.
/// Empty for an empty run or a reference without segments (or `max_skip` > 255).
pub fn viterbi_windowed(
    reference: &ReferencePolyline,
    params: &HmmParams,
    window: usize,
    tips: &[Vector<3>],
    seconds: &[Vector<3>],
) -> Vec<usize> {
    let Some(mut decoder) = WindowedViterbi::new(reference, *params, window) else {
        return Vec::new();
    };
    for (p, q) in tips.iter().zip(seconds) {
        decoder.push(p, q);
    }
    decoder.finish()
}

/// Settings of a whole-run evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunSettings {
    /// The segment mapping's model (costs, skips).
    pub params: HmmParams,
    /// Tool length L of the second points, mm.
    pub tool_length: f64,
    /// Candidate segments per sample of the mapping.
    pub window: usize,
    /// What the per-sample errors are measured against: the points' straight moves or a
    /// smooth curve through them.
    pub reference: ReferenceShape,
    /// Threads the evaluation may use: with 2 or more the mapping's costs are computed
    /// ahead by a second thread and the per-sample errors in two halves; the results are
    /// the same with any number.
    pub threads: usize,
}

impl Default for RunSettings {
    /// K = 4 (a reference sampled up to 4× finer than the measurement), w = 0.1 mm/rad
    /// (the motion direction only breaks near-ties: measured motion per sample is µm
    /// and its direction is noisy), L = 100 mm, 64 candidate segments, straight moves, as
    /// many threads as the machine runs at once.
    fn default() -> Self {
        RunSettings {
            params: HmmParams {
                max_skip: 4,
                angle_weight: 0.1,
            },
            tool_length: 100.0,
            window: 64,
            reference: ReferenceShape::Straight,
            threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
        }
    }
}

/// Errors of one measured sample against the reference near its mapped segment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleContourError {
    /// Mapped segment [R_j, R_j+1].
    pub segment: usize,
    /// Foot-point tip error magnitude, mm.
    pub tip: f64,
    /// Orientation error at the foot point, rad.
    pub orientation: f64,
}

/// The result of [`evaluate_run`].
#[derive(Clone, Debug, PartialEq)]
pub struct RunEvaluation {
    /// One per measured sample.
    pub samples: Vec<SampleContourError>,
    /// One per reference point: the evaluation-function estimate, `None` where no
    /// measured sample with neighbours on both sides is mapped next to the point.
    pub references: Vec<Option<Evaluation>>,
    /// The path-wide mm/rad factor R used by the estimates.
    pub mm_per_rad: f64,
}

/// Why a run could not be evaluated.
#[derive(Clone, Debug, PartialEq)]
pub enum RunError {
    /// Fewer than two reference poses.
    ShortReference(usize),
    /// A reference pose with a non-finite tip or a zero/non-finite axis.
    BadReference(usize),
    /// Consecutive reference axes `i`, `i + 1` are opposite (no unique turn between them).
    OppositeAxes(usize),
    /// A measured sample with a non-finite joint.
    BadSample(usize),
    /// Settings out of range; the message says which.
    Settings(String),
}

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RunError::ShortReference(n) => {
                write!(f, "the reference needs at least two poses, has {n}")
            }
            RunError::BadReference(i) => write!(
                f,
                "reference pose {i} has a non-finite tip or a zero or non-finite axis"
            ),
            RunError::OppositeAxes(i) => write!(
                f,
                "reference axes {i} and {} are opposite: no unique turn between them",
                i + 1
            ),
            RunError::BadSample(k) => write!(f, "measured sample {k} has a non-finite joint"),
            RunError::Settings(m) => write!(f, "{m}"),
        }
    }
}

impl std::error::Error for RunError {}

/// Progress is reported about this often (in work units: samples or reference points).
const PROGRESS_EVERY: usize = 8192;

/// Evaluates a measured run (`measured` joints, one sample each) against `reference`
/// poses on `machine`: maps every sample (windowed Viterbi), gives each its foot-point
/// errors, and estimates the evaluation function at every reference point from the
/// sample nearest it among those mapped to the `max_skip` segments either side of it,
/// with the samples before and after it (docs/design/five-axis.md §5.3). `progress(done, total)` is called now and then and at
/// the end. Memory: O(samples + reference points), never samples × segments.
pub fn evaluate_run(
    machine: &TableTiltingAc,
    reference: &[Pose],
    measured: &[Joints],
    settings: &RunSettings,
    mut progress: impl FnMut(usize, usize),
) -> Result<RunEvaluation, RunError> {
    let reference = checked_reference(reference)?;
    if let Some(k) = measured.iter().position(|q| !geometry::is_finite(q)) {
        return Err(RunError::BadSample(k));
    }
    let length = settings.tool_length;
    if !(length.is_finite() && length >= 0.0) {
        return Err(RunError::Settings(format!(
            "tool length must be finite and ≥ 0 mm, got {length}"
        )));
    }
    let weight = settings.params.angle_weight;
    if !(weight.is_finite() && weight >= 0.0) {
        return Err(RunError::Settings(format!(
            "angle weight must be finite and ≥ 0 mm/rad, got {weight}"
        )));
    }
    if settings.params.max_skip > u8::MAX as usize {
        return Err(RunError::Settings(format!(
            "max skip must be at most {}, got {}",
            u8::MAX,
            settings.params.max_skip
        )));
    }
    let n = measured.len();
    let points = reference.len();
    let total = 2 * n + points;
    let mut done = 0;
    let mut tick = |done: usize| {
        if done.is_multiple_of(PROGRESS_EVERY) {
            progress(done, total);
        }
    };

    // Pass 1: the mapping (poses recomputed rather than held: 48 bytes a sample saved),
    // its costs computed ahead by a second thread where there is a second core.
    let tips: Vec<Vector<3>> = reference.iter().map(|p| p.tip).collect();
    let axes: Vec<Vector<3>> = reference.iter().map(|p| p.axis).collect();
    let polyline = ReferencePolyline::new(&tips, &axes, length);
    let run = Observer {
        machine,
        measured,
        length,
    };
    let helper = settings.threads > 1;
    let (mapping, _) = map_run(
        &polyline,
        settings.params,
        settings.window,
        run,
        helper,
        &mut tick,
    )
    .expect("checked: segments and max skip");
    done += n;

    // Pass 2: per-sample errors, and the nearest sample to each reference point among
    // those mapped to the K segments either side of it (K = max_skip: samples up to one
    // step away; for K = 1 the two segments meeting there, as §5.3 has it — a reference
    // finer than the measurement has points with no sample on either neighbour).
    let reach = settings.params.max_skip.max(1);
    let errors = |samples: std::ops::Range<usize>, tick: &mut dyn FnMut(usize)| {
        let mut nearest: Vec<Option<(f64, usize)>> = vec![None; points];
        let mut errors = Vec::with_capacity(samples.len());
        for k in samples {
            let (pose, j) = (machine.forward(&measured[k]), mapping[k]);
            // The mapping picks the branch; the foot is the nearest point of the reference
            // (as settings.reference reads it) near there, the axis taken at the same point.
            let e = foot_error(settings.reference, &reference, j, &pose)
                .expect("checked: finite poses, no opposite axes");
            errors.push(SampleContourError {
                segment: j,
                tip: geometry::norm(&e.tip),
                orientation: e.orientation,
            });
            for i in j.saturating_sub(reach - 1)..=(j + reach).min(points - 1) {
                let d = geometry::dist2(&pose.tip, &reference[i].tip);
                if nearest[i].is_none_or(|(best, _)| d < best) {
                    nearest[i] = Some((d, k));
                }
            }
            tick(k + 1);
        }
        (errors, nearest)
    };
    // The later half on a second thread where there is one: its nearest samples replace
    // the earlier half's only where strictly nearer, as one pass in order would.
    let half = if helper { n / 2 } else { n };
    let (samples, nearest) = std::thread::scope(|scope| {
        let later = scope.spawn(|| errors(half..n, &mut |_| {}));
        let mut earlier = errors(0..half, &mut |k| tick(done + k));
        let (later_errors, later_nearest) = later.join().expect("no panic in the errors");
        earlier.0.extend(later_errors);
        for (e, l) in earlier.1.iter_mut().zip(later_nearest) {
            if let Some((d, k)) = l {
                if e.is_none_or(|(best, _)| d < best) {
                    *e = Some((d, k));
                }
            }
        }
        earlier
    });
    done += n;

    // Pass 3: the evaluation function at each reference point.
    let ratio = evaluation::mm_per_rad(&reference);
    let mut references = Vec::with_capacity(points);
    for (i, near) in nearest.iter().enumerate() {
        references.push(near.and_then(|(_, k)| {
            let q = three_samples(measured, k)?;
            let before = &reference[i.saturating_sub(1)];
            let after = &reference[(i + 1).min(points - 1)];
            let lambda = evaluation::weights(before, after, ratio);
            Some(evaluation::evaluate(
                machine,
                &reference[i],
                lambda,
                ratio,
                &q,
            ))
        }));
        done += 1;
        tick(done);
    }
    progress(total, total);
    Ok(RunEvaluation {
        samples,
        references,
        mm_per_rad: ratio,
    })
}

/// A `max_skip` for a run: the largest tip move between consecutive measured samples
/// over the median reference segment, with half again as margin (at least 1, at most
/// 255). A reference sampled finer than the measurement needs skips of several segments.
/// With `threads` > 1 the run's two halves are measured at once.
pub fn suggested_max_skip(
    machine: &TableTiltingAc,
    reference: &[Pose],
    measured: &[Joints],
    threads: usize,
) -> usize {
    let mut lengths: Vec<f64> = reference
        .windows(2)
        .map(|w| geometry::dist(&w[0].tip, &w[1].tip))
        .filter(|d| *d > 0.0)
        .collect();
    if lengths.is_empty() {
        return 1;
    }
    let middle = lengths.len() / 2;
    let median = *lengths.select_nth_unstable_by(middle, f64::total_cmp).1;
    let largest_step = |run: &[Joints]| {
        let mut step: f64 = 0.0;
        let mut previous: Option<Vector<3>> = None;
        for q in run {
            let tip = machine.forward(q).tip;
            if let Some(p) = previous {
                step = step.max(geometry::dist(&tip, &p));
            }
            previous = Some(tip);
        }
        step
    };
    // The halves share the sample between them, so every step is in one of them.
    let half = measured.len() / 2;
    let step = if threads > 1 && half > 0 {
        std::thread::scope(|scope| {
            let later = scope.spawn(|| largest_step(&measured[half - 1..]));
            let earlier = largest_step(&measured[..half]);
            earlier.max(later.join().expect("no panic measuring steps"))
        })
    } else {
        largest_step(measured)
    };
    let skips = (1.5 * step / median).ceil();
    if skips.is_finite() {
        (skips as usize).clamp(1, u8::MAX as usize)
    } else {
        u8::MAX as usize
    }
}

/// The samples before, at and after `k`, or `None` at either end of the run (the fit
/// needs both neighbours).
pub fn three_samples(measured: &[Joints], k: usize) -> Option<[Joints; 3]> {
    if k == 0 || k + 1 >= measured.len() {
        return None;
    }
    Some([measured[k - 1], measured[k], measured[k + 1]])
}

/// The reference with unit axes, or why it cannot be used.
fn checked_reference(reference: &[Pose]) -> Result<Vec<Pose>, RunError> {
    if reference.len() < 2 {
        return Err(RunError::ShortReference(reference.len()));
    }
    let poses = reference
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let axis = geometry::unit(&p.axis).filter(|_| geometry::is_finite(&p.tip));
            axis.map(|axis| Pose { tip: p.tip, axis })
                .ok_or(RunError::BadReference(i))
        })
        .collect::<Result<Vec<_>, _>>()?;
    if let Some(i) = poses
        .windows(2)
        .position(|w| slerp(&w[0].axis, &w[1].axis, 0.5).is_none())
    {
        return Err(RunError::OppositeAxes(i));
    }
    Ok(poses)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contour::five_axis::hmm::viterbi_offline;
    use crate::geometry::angle_between;
    use crate::math;

    use rand::rngs::StdRng;
    use rand::{RngExt, SeedableRng};

    type V3 = Vector<3>;

    fn tilted(lean: f64, azimuth: f64) -> V3 {
        V3::new(
            math::sin(lean) * math::sin(azimuth),
            math::sin(lean) * math::cos(azimuth),
            math::cos(lean),
        )
    }

    /// A random wandering reference and a noisy run along it.
    fn random_case(rng: &mut StdRng, m: usize, n: usize) -> (ReferencePolyline, Vec<V3>, Vec<V3>) {
        let mut tips = vec![V3::zeros()];
        let mut heading: f64 = 0.0;
        for _ in 0..m {
            heading += rng.random_range(-1.2..1.2);
            let step = rng.random_range(0.3..2.0);
            let last = *tips.last().unwrap();
            tips.push(
                last + V3::new(
                    math::cos(heading),
                    math::sin(heading),
                    rng.random_range(-0.3..0.3),
                ) * step,
            );
        }
        let axes: Vec<V3> = (0..=m)
            .map(|_| tilted(rng.random_range(0.1..0.6), rng.random_range(-3.0..3.0)))
            .collect();
        let length = rng.random_range(0.0..50.0);
        let reference = ReferencePolyline::new(&tips, &axes, length);
        let (mut run, mut seconds) = (Vec::new(), Vec::new());
        for k in 0..n {
            let u = (k as f64 + rng.random_range(0.0..0.5)) * m as f64 / n as f64;
            let i = (u as usize).min(m - 1);
            let f = u - i as f64;
            let p = tips[i] * (1.0 - f) + tips[i + 1] * f;
            let noise = V3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            let tip = p + noise * 0.4;
            run.push(tip);
            seconds.push(tip + axes[i] * length + noise * 0.2);
        }
        (reference, run, seconds)
    }

    fn decode(
        reference: &ReferencePolyline,
        params: HmmParams,
        window: usize,
        check: usize,
        run: &[V3],
        seconds: &[V3],
    ) -> (Vec<usize>, usize) {
        let mut decoder = WindowedViterbi::new(reference, params, window)
            .unwrap()
            .check_every(check);
        let mut most = 0;
        for (p, q) in run.iter().zip(seconds) {
            decoder.push(p, q);
            most = most.max(decoder.pending());
        }
        (decoder.finish(), most)
    }

    #[test]
    fn with_the_whole_reference_in_the_window_it_decodes_as_offline() {
        let mut rng = StdRng::seed_from_u64(0x5EED_1234_ABCD_0001);
        for case in 0..60 {
            let m = 2 + case % 23;
            let n = 1 + (case * 7) % 40;
            let (reference, run, seconds) = random_case(&mut rng, m, n);
            let params = HmmParams {
                max_skip: 1 + case % 3,
                angle_weight: rng.random_range(0.0..2.0),
            };
            let offline = viterbi_offline(&reference, &params, &run, &seconds);
            // Commit attempts every sample, every third, and never before the end.
            for check in [1, 3, 1000] {
                let (windowed, _) = decode(&reference, params, 64, check, &run, &seconds);
                assert_eq!(windowed, offline, "case {case}, check every {check}");
            }
            assert_eq!(
                viterbi_windowed(&reference, &params, 64, &run, &seconds),
                offline
            );
        }
    }

    #[test]
    fn commits_never_change_the_windowed_decoding() {
        // A window much smaller than the reference: whatever the commit schedule, the
        // mapping is the one traced back at the end.
        let mut rng = StdRng::seed_from_u64(0xC0FF_EE00_0000_0042);
        for case in 0..20 {
            let (reference, run, seconds) = random_case(&mut rng, 120, 300);
            let params = HmmParams {
                max_skip: 2,
                angle_weight: 0.3,
            };
            let (late, _) = decode(&reference, params, 8, usize::MAX, &run, &seconds);
            for check in [1, 2, 17] {
                let (early, _) = decode(&reference, params, 8, check, &run, &seconds);
                assert_eq!(early, late, "case {case}, check every {check}");
            }
            assert!(late.windows(2).all(|w| w[0] <= w[1] && w[1] - w[0] <= 2));
        }
    }

    fn spiral(n: usize) -> (Vec<V3>, Vec<V3>) {
        let tips = (0..n)
            .map(|j| {
                let t = j as f64 * 0.05;
                V3::new(30.0 * math::cos(t), 30.0 * math::sin(t), 0.5 * t)
            })
            .collect();
        let axes = (0..n)
            .map(|j| tilted(0.3 + 0.2 * math::sin(j as f64 * 0.01), j as f64 * 0.05))
            .collect();
        (tips, axes)
    }

    #[test]
    fn a_long_spiral_with_a_following_error_decodes_as_offline_in_bounded_memory() {
        // 800 segments, 2000 samples (2.5 a segment, so skips of 0 and 1) offset from the
        // path, stopping 40 segments short of the end as a run lagging its reference
        // does, with noise: a window of 32 segments decodes what the full table decodes,
        // and only a few hundred samples are ever open at once.
        let (tips, axes) = spiral(801);
        let reference = ReferencePolyline::new(&tips, &axes, 100.0);
        let mut rng = StdRng::seed_from_u64(0x0123_4567_89AB_CDEF);
        let n = 2000;
        let (mut run, mut seconds) = (Vec::new(), Vec::new());
        for k in 0..n {
            let u = k as f64 * (800.0 - 40.0) / n as f64;
            let (i, f) = (u as usize, u.fract());
            let tip = tips[i] * (1.0 - f)
                + tips[i + 1] * f
                + V3::new(0.05, -0.03, 0.02)
                + V3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    0.0,
                ) * 0.01;
            let axis = slerp(&axes[i], &axes[i + 1], f).unwrap();
            run.push(tip);
            seconds.push(tip + axis * 100.0);
        }
        let params = HmmParams {
            max_skip: 2,
            angle_weight: 0.5,
        };
        let offline = viterbi_offline(&reference, &params, &run, &seconds);
        let (windowed, most) = decode(&reference, params, 32, 64, &run, &seconds);
        assert_eq!(windowed, offline);
        assert!(most < 400, "{most} samples open at once");
        // The mapping follows the run (the sample's own segment, give or take one).
        for (k, &j) in windowed.iter().enumerate() {
            let u = k as f64 * (800.0 - 40.0) / n as f64;
            assert!((j as f64 - u).abs() <= 1.5, "sample {k}: {j} vs {u}");
        }
    }

    /// Turns unit `o` by `angle` about the unit `d` ⟂ `o`.
    fn turn(o: &V3, d: &V3, angle: f64) -> V3 {
        o * math::cos(angle) + d.cross(o) * math::sin(angle)
    }

    #[test]
    fn errors_of_a_displaced_run_along_a_line_are_the_displacement() {
        // The reference: x from 0 to 10 mm, the tool leaning from 10° to 40° toward +x,
        // linearly in x (so the slerp between points is the reference itself). The run:
        // 0.02 mm off in +y, the tool turned 1 mrad toward −y.
        let machine = TableTiltingAc {
            a_pivot: V3::new(0.0, 0.0, -50.0),
            c_pivot: V3::new(3.0, -2.0, 0.0),
        };
        let lean = |x: f64| (10.0 + 3.0 * x).to_radians();
        let axis = |x: f64| V3::new(math::sin(lean(x)), 0.0, math::cos(lean(x)));
        let reference: Vec<Pose> = (0..=100)
            .map(|i| {
                let x = i as f64 * 0.1;
                Pose {
                    tip: V3::new(x, 0.0, 0.0),
                    axis: axis(x),
                }
            })
            .collect();
        let mut c = 0.0;
        let measured: Vec<Joints> = (0..=900)
            .map(|k| {
                let x = 0.5 + k as f64 * 0.01;
                let o = axis(x);
                let d = o.cross(&V3::y());
                let pose = Pose {
                    tip: V3::new(x, 0.02, 0.0),
                    axis: turn(&o, &geometry::unit(&d).unwrap(), 1e-3),
                };
                let q = machine.inverse(&pose, c).unwrap();
                c = q[4];
                q
            })
            .collect();
        let mut calls = 0;
        let result = evaluate_run(
            &machine,
            &reference,
            &measured,
            &RunSettings::default(),
            |done, total| {
                calls += 1;
                assert!(done <= total);
            },
        )
        .unwrap();
        assert!(calls >= 1);
        assert_eq!(result.samples.len(), measured.len());
        for (k, s) in result.samples.iter().enumerate() {
            let x = 0.5 + k as f64 * 0.01;
            assert!((s.tip - 0.02).abs() < 1e-12, "sample {k}: {}", s.tip);
            assert!((s.orientation - 1e-3).abs() < 1e-12, "sample {k}");
            // x = 0.1·j … 0.1·(j + 1), rounding aside.
            assert!(
                (x / 0.1 - s.segment as f64) > -1e-9 && (x / 0.1 - s.segment as f64) < 1.0 + 1e-9
            );
        }
        // The run covers x = 0.5 … 9.5: reference points 5 … 95 have estimates (the
        // same displacement), the rest none.
        for (i, e) in result.references.iter().enumerate() {
            match e {
                Some(e) if (6..=94).contains(&i) => {
                    assert!((e.tip - 0.02).abs() < 1e-9, "point {i}: {}", e.tip);
                    assert!((e.orientation - 1e-3).abs() < 1e-9, "point {i}");
                }
                Some(_) if (5..=95).contains(&i) => {}
                None if !(6..=94).contains(&i) => {}
                other => panic!("point {i}: {other:?}"),
            }
        }
        // R: 10 mm of travel over 30° of turn.
        assert!((result.mm_per_rad - 10.0 / 30f64.to_radians()).abs() < 1e-9);
    }

    #[test]
    fn estimates_match_a_dense_minimisation_over_the_true_motion() {
        // The reference: an arc of a tilted helix. The true motion: the same helix with a
        // radial offset and a tool tilt that vary along it, sampled 2.5 times per
        // reference segment; the estimate at each reference point must equal F
        // minimised by brute force over the true (unsampled) motion near the point.
        let machine = TableTiltingAc {
            a_pivot: V3::new(0.0, 0.0, -50.0),
            c_pivot: V3::zeros(),
        };
        let helix = |t: f64, radial: f64, tilt: f64| {
            let (s, c) = math::sincos(t);
            Pose {
                tip: V3::new((20.0 + radial) * c, (20.0 + radial) * s, 0.8 * t),
                axis: V3::new(-math::sin(tilt) * c, -math::sin(tilt) * s, math::cos(tilt)),
            }
        };
        let step = 0.0025; // rad of helix angle per reference point, 0.05 mm
        let reference: Vec<Pose> = (0..=400)
            .map(|i| helix(i as f64 * step, 0.0, 0.35))
            .collect();
        let truth = |t: f64, c: f64| {
            let pose = helix(
                t,
                0.01 + 0.005 * math::sin(7.0 * t),
                0.35 + 2e-4 * math::cos(5.0 * t),
            );
            machine.inverse(&pose, c).unwrap()
        };
        let dt = step / 2.5;
        let mut c = 0.0;
        let measured: Vec<Joints> = (0..=2400)
            .map(|k| {
                let q = truth(0.05 + k as f64 * dt, c);
                c = q[4];
                q
            })
            .collect();
        let result = evaluate_run(
            &machine,
            &reference,
            &measured,
            &RunSettings::default(),
            |_, _| {},
        )
        .unwrap();

        // R and the weights from their definitions (docs/design/five-axis.md §5.3).
        let (mut travel, mut turned) = (0.0, 0.0);
        for w in reference.windows(2) {
            travel += geometry::dist(&w[0].tip, &w[1].tip);
            turned += angle_between(&w[0].axis, &w[1].axis);
        }
        let r = travel / turned;
        let mut checked = 0;
        for i in (30..=380).step_by(17) {
            let e = result.references[i].expect("a sample nearby");
            let vp = 0.5 * geometry::dist(&reference[i + 1].tip, &reference[i - 1].tip);
            let vo = 0.5 * r * angle_between(&reference[i + 1].axis, &reference[i - 1].axis);
            let (l1, l2) = (vp / (vp + vo), vo / (vp + vo));
            // Brute force over ±4 samples of true motion around the point's time: a
            // grid, then a finer grid around its best cell.
            let c_near = measured[((i as f64 * step - 0.05) / dt).round() as usize][4];
            let f_at = |t: f64| {
                let pose = machine.forward(&truth(t, c_near));
                let tip = geometry::dist(&pose.tip, &reference[i].tip);
                let angle = angle_between(&pose.axis, &reference[i].axis);
                (l1 * tip + l2 * r * angle, tip, angle, t)
            };
            let scan = |centre: f64, half: f64| {
                (-2000..=2000)
                    .map(|s| f_at(centre + half * s as f64 / 2000.0))
                    .fold((f64::INFINITY, 0.0, 0.0, 0.0), |b, x| {
                        if x.0 < b.0 {
                            x
                        } else {
                            b
                        }
                    })
            };
            let coarse = scan(i as f64 * step, 4.0 * dt);
            let best = scan(coarse.3, 2.0 * 4.0 * dt / 2000.0);
            let f = l1 * e.tip + l2 * r * e.orientation;
            assert!((f - best.0).abs() < 1e-8, "point {i}: F {f} vs {}", best.0);
            assert!(
                (e.tip - best.1).abs() < 1e-6,
                "point {i}: {} vs {}",
                e.tip,
                best.1
            );
            assert!((e.orientation - best.2).abs() < 1e-7, "point {i}");
            checked += 1;
        }
        assert!(checked > 20);
        // Before the run starts there is nothing to fit.
        assert!(result.references[..10].iter().all(Option::is_none));
    }

    #[test]
    fn bad_inputs_are_refused() {
        let machine = TableTiltingAc::default();
        let pose = |x: f64, axis: V3| Pose {
            tip: V3::new(x, 0.0, 0.0),
            axis,
        };
        let settings = RunSettings::default();
        let q = [Joints::zeros(); 3];
        let run = |reference: &[Pose], measured: &[Joints], settings: &RunSettings| {
            evaluate_run(&machine, reference, measured, settings, |_, _| {}).unwrap_err()
        };
        assert_eq!(
            run(&[pose(0.0, V3::z())], &q, &settings),
            RunError::ShortReference(1)
        );
        let opposite = [pose(0.0, V3::z()), pose(1.0, V3::z()), pose(2.0, -V3::z())];
        assert_eq!(run(&opposite, &q, &settings), RunError::OppositeAxes(1));
        let zero = [pose(0.0, V3::z()), pose(1.0, V3::zeros())];
        assert_eq!(run(&zero, &q, &settings), RunError::BadReference(1));
        let good = [pose(0.0, V3::z()), pose(1.0, V3::z())];
        let mut nan = q;
        nan[2][3] = f64::NAN;
        assert_eq!(run(&good, &nan, &settings), RunError::BadSample(2));
        let mut wide = settings;
        wide.params.max_skip = 256;
        assert!(matches!(run(&good, &q, &wide), RunError::Settings(_)));
        // An empty run is no error: nothing to report.
        let empty = evaluate_run(&machine, &good, &[], &settings, |_, _| {}).unwrap();
        assert!(empty.samples.is_empty() && empty.references == [None, None]);
    }
}
