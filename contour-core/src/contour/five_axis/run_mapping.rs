//! The windowed mapping of a whole measured run on two threads (docs/design/five-axis.md
//! §5.3a): the same mapping as [`WindowedViterbi`] fed sample by sample, bit for bit,
//! with most window costs computed ahead by a second thread.
//!
//! The recursion is sequential, but its costs c(k, j) are not: they need only the
//! sample and the segment. What a sample's window will be is known only once the
//! previous sample is decoded, so the helper predicts it: it follows the segment nearest
//! each sample (tip and second point) and costs a band of the window's width plus
//! [`MARGIN`] either side around it, with the same function the decoder uses. Where the
//! band covers the window the decoder takes those costs; where it does not, the decoder
//! computes them itself. Either way each cost has the same bits, so the mapping never
//! depends on the prediction or the timing, only its speed does.
//!
//! The run is cut into chunks of [`CHUNK`] samples; each chunk's costs come from one
//! thread. The decoder takes every chunk nobody has claimed when it gets there and costs
//! it inline; the helper claims chunks ahead of it, always leaving one unclaimed chunk
//! between the decoder's and its own, so that the decoder, busy with that one, does
//! not catch up with a chunk still being costed.

use std::sync::atomic::{AtomicU8, AtomicUsize, Ordering};
use std::sync::mpsc;

use super::hmm::{HmmParams, ReferencePolyline};
use super::run_evaluation::WindowedViterbi;
use super::window_costs::{CostScratch, SegmentTable};
use crate::geometry::Vector;
use crate::kinematics::{Joints, TableTiltingAc};

/// Samples per chunk of costs.
const CHUNK: usize = 2048;
/// Segments a band adds either side of the predicted window.
const MARGIN: usize = 4;
/// Samples between the helper's looks at the nearest segment in the decoder's chunks.
const FOLLOW_EVERY: usize = 8;

/// Who costs a chunk.
const FREE: u8 = 0;
const DECODER: u8 = 1;
const HELPER: u8 = 2;

/// A chunk's costs from the helper: for its i-th sample, the costs of segments
/// `firsts[i] ..` in `costs[i * width ..][.. width]`.
struct Band {
    firsts: Vec<usize>,
    costs: Vec<f64>,
    width: usize,
}

impl Band {
    fn sample(&self, i: usize) -> (usize, &[f64]) {
        (
            self.firsts[i],
            &self.costs[i * self.width..(i + 1) * self.width],
        )
    }
}

/// A run's samples as the mapping observes them: tool tip and second point.
#[derive(Clone, Copy)]
pub struct Observer<'a> {
    /// The machine whose joints were measured.
    pub machine: &'a TableTiltingAc,
    /// The measured joints, one sample each.
    pub measured: &'a [Joints],
    /// Tool length L of the second points, mm.
    pub length: f64,
}

impl Observer<'_> {
    fn at(&self, k: usize) -> (Vector<3>, Vector<3>) {
        let pose = self.machine.forward(&self.measured[k]);
        (pose.tip, pose.tip + pose.axis * self.length)
    }
}

/// The mapping of every sample of `run` onto `reference` (a decoder of `window`
/// segments, `params`), with a helper thread when `helper` and the run has enough
/// chunks, and the number of samples whose window the helper had costed;
/// `progress(samples decoded)` after every sample. `None` where [`WindowedViterbi`]
/// cannot decode (no segment, a skip above 255).
pub fn map_run(
    reference: &ReferencePolyline,
    params: HmmParams,
    window: usize,
    run: Observer<'_>,
    helper: bool,
    mut progress: impl FnMut(usize),
) -> Option<(Vec<usize>, usize)> {
    let mut decoder = WindowedViterbi::new(reference, params, window)?;
    let n = run.measured.len();
    let chunks = n.div_ceil(CHUNK);
    let claims: Vec<AtomicU8> = (0..chunks).map(|_| AtomicU8::new(FREE)).collect();
    let position = AtomicUsize::new(0);
    let mut costed_ahead = 0;
    let (sender, receiver) = mpsc::sync_channel::<Band>(4);
    // Bands the decoder is done with go back to the helper (their memory reused).
    let (recycle, recycled) = mpsc::channel::<Band>();
    std::thread::scope(|scope| {
        if helper && chunks >= 4 {
            let (table, width) = (decoder.segments(), decoder.width());
            let (claims, position) = (&claims, &position);
            scope.spawn(move || {
                let helper = Helper {
                    table: &table,
                    params,
                    width,
                    run,
                    claims,
                    position,
                };
                helper.run(sender, recycled);
            });
        } else {
            drop(sender);
        }
        for (c, claim) in claims.iter().enumerate() {
            position.store(c, Ordering::Release);
            let inline = claim
                .compare_exchange(FREE, DECODER, Ordering::AcqRel, Ordering::Acquire)
                .is_ok();
            // The helper's chunks arrive in order; a helper that ended early leaves the
            // decoder to cost its chunk.
            let band = if inline { None } else { receiver.recv().ok() };
            for (i, k) in (c * CHUNK..((c + 1) * CHUNK).min(n)).enumerate() {
                let (tip, second) = run.at(k);
                let given = band.as_ref().map(|b| b.sample(i));
                costed_ahead += usize::from(decoder.push_costed(&tip, &second, given));
                progress(k + 1);
            }
            if let Some(band) = band {
                // A helper that has ended no longer takes them.
                let _ = recycle.send(band);
            }
        }
        // A helper still sending (it never is: every claimed chunk was received) ends.
        drop(receiver);
    });
    Some((decoder.finish(), costed_ahead))
}

/// The thread that costs chunks ahead of the decoder.
struct Helper<'a> {
    table: &'a SegmentTable,
    params: HmmParams,
    /// The decoder's window.
    width: usize,
    run: Observer<'a>,
    claims: &'a [AtomicU8],
    /// The chunk the decoder is in.
    position: &'a AtomicUsize,
}

impl Helper<'_> {
    fn run(&self, sender: mpsc::SyncSender<Band>, recycled: mpsc::Receiver<Band>) {
        let m = self.table.segments();
        let band_width = (self.width + 2 * MARGIN).min(m);
        let (tip, second) = self.run.at(0);
        let mut nearest = Nearest::scan(self.table, &tip, &second);
        let (mut followed, mut previous_tip) = (1, tip);
        let mut scratch = CostScratch::default();
        let mut last = 0;
        while let Some(c) = self.claim(last) {
            last = c;
            let samples = c * CHUNK..((c + 1) * CHUNK).min(self.run.measured.len());
            // Follow the nearest segment through the decoder's chunks up to this one, every
            // FOLLOW_EVERY samples (walking downhill covers the gaps), and the last.
            let skipped = followed..samples.start;
            let last = skipped.end.checked_sub(1).filter(|l| skipped.contains(l));
            for k in skipped.clone().step_by(FOLLOW_EVERY).chain(last) {
                let (tip, second) = self.run.at(k);
                nearest.follow(self.table, &tip, &second);
                previous_tip = tip;
            }
            let mut band = recycled.try_recv().unwrap_or(Band {
                firsts: Vec::new(),
                costs: Vec::new(),
                width: band_width,
            });
            band.firsts.clear();
            band.costs.resize(samples.len() * band_width, 0.0);
            for (k, out) in samples.clone().zip(band.costs.chunks_exact_mut(band_width)) {
                let (tip, second) = self.run.at(k);
                let centre = nearest.follow(self.table, &tip, &second);
                let first = centre
                    .saturating_sub(self.width / 2 + MARGIN)
                    .min(m - band_width);
                let motion = tip - previous_tip;
                let observation = [&tip, &second, &motion];
                self.table
                    .costs(&self.params, first, observation, out, &mut scratch);
                band.firsts.push(first);
                previous_tip = tip;
            }
            followed = samples.end;
            if sender.send(band).is_err() {
                return;
            }
        }
    }

    /// Claims the first free chunk after `last` that lies beyond a free chunk after the
    /// decoder's (the one the decoder will cost while this one is costed); `None` when
    /// there is none left.
    fn claim(&self, last: usize) -> Option<usize> {
        let chunks = self.claims.len();
        let decoder = self.position.load(Ordering::Acquire);
        let free = |c: &usize| self.claims[*c].load(Ordering::Acquire) == FREE;
        let gap = (decoder + 1..chunks).find(free)?;
        (gap.max(last) + 1..chunks).find(|&c| {
            self.claims[c]
                .compare_exchange(FREE, HELPER, Ordering::AcqRel, Ordering::Acquire)
                .is_ok()
        })
    }
}

/// The segment nearest the samples (least summed tip and second-point distance),
/// followed from one sample to the next by walking downhill.
struct Nearest {
    segment: usize,
}

impl Nearest {
    fn scan(table: &SegmentTable, tip: &Vector<3>, second: &Vector<3>) -> Self {
        let distance = |j: usize| table.distances(j, tip, second);
        let segment = (0..table.segments())
            .min_by(|&a, &b| distance(a).total_cmp(&distance(b)))
            .unwrap_or(0);
        Nearest { segment }
    }

    fn follow(&mut self, table: &SegmentTable, tip: &Vector<3>, second: &Vector<3>) -> usize {
        let distance = |j: usize| table.distances(j, tip, second);
        let (mut j, mut d) = (self.segment, distance(self.segment));
        while j + 1 < table.segments() {
            let next = distance(j + 1);
            if next >= d {
                break;
            }
            (j, d) = (j + 1, next);
        }
        while j > 0 {
            let next = distance(j - 1);
            if next >= d {
                break;
            }
            (j, d) = (j - 1, next);
        }
        self.segment = j;
        j
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{self, slerp};
    use crate::kinematics::Pose;
    use crate::math;
    use rand::rngs::StdRng;
    use rand::{RngExt, SeedableRng};

    type V3 = Vector<3>;

    /// A helix with the tool leaning 0.3 ± 0.1 rad, turning with it: `points` poses
    /// `step` rad of the helix apart.
    fn helix(points: usize, step: f64) -> Vec<Pose> {
        (0..points)
            .map(|j| {
                let t = j as f64 * step;
                let lean = 0.3 + 0.1 * math::sin(3.0 * t);
                let axis = V3::new(
                    math::sin(lean) * math::cos(t + 3.0),
                    math::sin(lean) * math::sin(t + 3.0),
                    math::cos(lean),
                );
                Pose {
                    tip: V3::new(30.0 * math::cos(t), 30.0 * math::sin(t), 5.0 + 0.2 * t),
                    axis,
                }
            })
            .collect()
    }

    /// Joints of a run along `reference` at `rate` segments a sample (`stall`: the
    /// samples from `stall.0` on stand `stall.1` samples still, then jump ahead as far),
    /// off the path by `offset` mm with noise of `noise` mm.
    fn run_along(
        machine: &TableTiltingAc,
        reference: &[Pose],
        samples: usize,
        rate: f64,
        offset: f64,
        noise: f64,
        stall: Option<(usize, usize)>,
    ) -> Vec<Joints> {
        let mut rng = StdRng::seed_from_u64(43);
        let mut c = 0.0;
        (0..samples)
            .map(|k| {
                let at = match stall {
                    Some((from, length)) if (from..from + length).contains(&k) => from,
                    _ => k,
                };
                let u = (at as f64 * rate).min((reference.len() - 2) as f64);
                let (i, f) = (u as usize, u.fract());
                let (a, b) = (&reference[i], &reference[i + 1]);
                let wobble = V3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                let pose = Pose {
                    tip: a.tip * (1.0 - f)
                        + b.tip * f
                        + V3::new(offset, -offset, 0.0)
                        + wobble * noise,
                    axis: slerp(&a.axis, &b.axis, f).unwrap(),
                };
                let q = machine.inverse(&pose, c).unwrap();
                c = q[4];
                q
            })
            .collect()
    }

    fn polyline(poses: &[Pose]) -> ReferencePolyline {
        let tips: Vec<V3> = poses.iter().map(|p| p.tip).collect();
        let axes: Vec<V3> = poses.iter().map(|p| p.axis).collect();
        ReferencePolyline::new(&tips, &axes, 100.0)
    }

    /// The mapping as the decoder alone makes it, sample by sample.
    fn alone(
        reference: &ReferencePolyline,
        params: HmmParams,
        window: usize,
        run: Observer<'_>,
    ) -> Vec<usize> {
        let mut decoder = WindowedViterbi::new(reference, params, window).unwrap();
        for k in 0..run.measured.len() {
            let (tip, second) = run.at(k);
            decoder.push(&tip, &second);
        }
        decoder.finish()
    }

    #[test]
    fn the_helper_changes_nothing_but_who_computes_the_costs() {
        let machine = TableTiltingAc::default();
        let poses = helix(3001, 0.01);
        let reference = polyline(&poses);
        let samples = 8 * CHUNK + 123;
        // (segments a sample, offset, noise, a stall and jump, max skip, angle weight,
        // window): a slow run lagging its path; a fast noisy one with skips of 3; a run
        // that stands 500 samples and then jumps 150 segments ahead (the nearest segment
        // leaves the decoder's window behind: the helper's bands miss and the decoder
        // costs those samples itself); a heavy angle weight.
        let cases = [
            (0.25, 0.01, 0.001, None, 1, 0.1, 64),
            (0.5, 0.02, 0.05, None, 3, 0.1, 32),
            (0.25, 0.0, 0.0005, Some((4000, 600)), 1, 0.1, 64),
            (0.25, 0.03, 0.01, None, 2, 5.0, 40),
        ];
        for (case, &(rate, offset, noise, stall, max_skip, angle_weight, window)) in
            cases.iter().enumerate()
        {
            let measured = run_along(&machine, &poses, samples, rate, offset, noise, stall);
            let run = Observer {
                machine: &machine,
                measured: &measured,
                length: 100.0,
            };
            let params = HmmParams {
                max_skip,
                angle_weight,
            };
            let expected = alone(&reference, params, window, run);
            let mut seen = 0;
            let (mapping, ahead) =
                map_run(&reference, params, window, run, true, |k| seen = k).unwrap();
            assert_eq!(mapping, expected, "case {case}");
            assert_eq!(seen, samples);
            // Which chunks the helper takes depends on timing, the mapping never does;
            // the first chunk is the decoder's. One thread: none costed ahead.
            assert!(ahead > 0, "case {case}: the helper costed nothing");
            assert!(
                ahead <= samples - CHUNK,
                "case {case}: {ahead} of {samples}"
            );
            let (single, none) = map_run(&reference, params, window, run, false, |_| {}).unwrap();
            assert_eq!((single, none), (expected, 0), "case {case}");
        }
    }

    #[test]
    fn a_short_run_or_a_bad_reference_is_as_the_decoder_makes_it() {
        let machine = TableTiltingAc::default();
        let poses = helix(50, 0.02);
        let reference = polyline(&poses);
        let measured = run_along(&machine, &poses, 300, 0.1, 0.01, 0.0, None);
        let run = Observer {
            machine: &machine,
            measured: &measured,
            length: 100.0,
        };
        let params = HmmParams {
            max_skip: 1,
            angle_weight: 0.1,
        };
        let (mapping, ahead) = map_run(&reference, params, 64, run, true, |_| {}).unwrap();
        assert_eq!(mapping, alone(&reference, params, 64, run));
        assert_eq!(ahead, 0, "one chunk: no helper");
        let empty = Observer {
            measured: &[],
            ..run
        };
        assert_eq!(
            map_run(&reference, params, 64, empty, true, |_| {}),
            Some((vec![], 0))
        );
        let point = polyline(&poses[..1]);
        assert_eq!(map_run(&point, params, 64, run, true, |_| {}), None);
        let too_far = HmmParams {
            max_skip: 256,
            ..params
        };
        assert_eq!(map_run(&reference, too_far, 64, run, true, |_| {}), None);
        assert!(geometry::is_finite(&run.at(0).0));
    }
}
