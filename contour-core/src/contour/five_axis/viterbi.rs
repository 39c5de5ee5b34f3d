//! The Viterbi core of the HMM segment mapping (docs/design/five-axis.md §5.2), shared by the
//! offline ([`viterbi_offline`](super::hmm::viterbi_offline)), windowed
//! ([`WindowedViterbi`](super::run_evaluation::WindowedViterbi)) and online
//! ([`OnlineMapper`](super::hmm_online::OnlineMapper)) mappers: the transition rule, one
//! forward step of the recursion over a range of candidate states, the first step, the
//! best state, the back-pointer table and the backtrack.
//!
//! States are absolute segment numbers j; the mapping moves from state i at sample k − 1
//! to j ∈ [i, i + max_skip] at sample k, and
//!   C(k, j) = c(k, j) + min over the live i in [j − max_skip, j] of C(k − 1, i),
//! ties to the lower i. The mappers bring the costs c(k, j), choose the candidate states
//! (all, a window, a band) and keep C where they like (a plain index, an offset into a
//! window, a ring slot): the core reads and writes them through closures, which inline
//! into the same loops the mappers had.

use std::ops::Range;

/// The best predecessor of state `j`: the least C(k − 1, i) (`previous(i)`) over the
/// states i in [j − max_skip, j] that are `live` at sample k − 1, ties to the lower i;
/// (∞, j) when none of them costs less than ∞. The cost is never NaN.
#[inline]
pub fn best_predecessor(
    j: usize,
    max_skip: usize,
    live: &Range<usize>,
    previous: impl Fn(usize) -> f64,
) -> (f64, usize) {
    let mut best = (f64::INFINITY, j);
    for i in j.saturating_sub(max_skip).max(live.start)..(j + 1).min(live.end) {
        let c = previous(i);
        if c < best.0 {
            best = (c, i);
        }
    }
    best
}

/// One forward step of the recursion: for every candidate state j in `states`, its best
/// predecessor among the `live` states of the previous sample ([`best_predecessor`]),
/// `score(j, best)` for C(k, j) (the predecessor's cost plus c(k, j): the mapper decides
/// what a state without a finite predecessor costs, and can skip c(k, j) for it), and
/// `store(j, C(k, j), predecessor)`. Returns whether any candidate had a finite
/// predecessor.
#[inline]
pub fn step(
    max_skip: usize,
    states: Range<usize>,
    live: Range<usize>,
    previous: impl Fn(usize) -> f64,
    mut score: impl FnMut(usize, f64) -> f64,
    mut store: impl FnMut(usize, f64, usize),
) -> bool {
    let mut reachable = false;
    for j in states {
        let (best, from) = best_predecessor(j, max_skip, &live, &previous);
        reachable |= best.is_finite();
        store(j, score(j, best), from);
    }
    reachable
}

/// The first step (or a fresh start): C(k, j) = c(k, j) (`cost(j)`) for every state in
/// `states`, each its own predecessor, through `store(j, C(k, j), j)`.
#[inline]
pub fn start(
    states: Range<usize>,
    mut cost: impl FnMut(usize) -> f64,
    mut store: impl FnMut(usize, f64, usize),
) {
    for j in states {
        store(j, cost(j), j);
    }
}

/// The state of `states` of least `cost` (ties to the lower state; the first when none
/// compares less, as when all are NaN). `states.start` when `states` is empty.
#[inline]
pub fn best_state(states: Range<usize>, cost: impl Fn(usize) -> f64) -> usize {
    let first = states.start;
    states.fold(first, |best, j| if cost(j) < cost(best) { j } else { best })
}

/// Traces the path that ends in state `j` at sample `k` back to sample `until` (≤ `k`):
/// `visit(k', j')` for every sample k' from `k` down to `until`, where `predecessor(k',
/// j')` is the state at k' − 1 of the path through j' at k'. Returns the state at
/// `until`.
#[inline]
pub fn backtrack(
    k: usize,
    mut j: usize,
    until: usize,
    predecessor: impl Fn(usize, usize) -> usize,
    mut visit: impl FnMut(usize, usize),
) -> usize {
    visit(k, j);
    for kk in (until..k).rev() {
        j = predecessor(kk + 1, j);
        visit(kk, j);
    }
    j
}

/// A back-pointer as a [`BackTable`] stores it: the skip j − i from a state j to its
/// predecessor i.
pub trait Skip: Copy + Default {
    /// The skip `s` (which the caller keeps within the type's range).
    fn from_skip(s: usize) -> Self;
    /// The skip.
    fn skip(self) -> usize;
}

impl Skip for u8 {
    #[inline]
    fn from_skip(s: usize) -> Self {
        s as u8
    }
    #[inline]
    fn skip(self) -> usize {
        self as usize
    }
}

impl Skip for usize {
    #[inline]
    fn from_skip(s: usize) -> Self {
        s
    }
    #[inline]
    fn skip(self) -> usize {
        self
    }
}

/// The back-pointers of consecutive samples, from the oldest one held on: a row per
/// sample over `width` consecutive states from the row's lowest state, each entry the
/// skip to the state's predecessor (`u8` where skips stay below 256: an eighth of the
/// memory of full indices). Rows grow at the end and are dropped from the front as the
/// mapping of their samples is decided.
#[derive(Clone, Debug, PartialEq)]
pub struct BackTable<T> {
    width: usize,
    skips: Vec<T>,
    lows: Vec<usize>,
    first: usize,
}

impl<T: Skip> BackTable<T> {
    /// An empty table of rows of `width` states.
    pub fn new(width: usize) -> Self {
        Self::with_capacity(width, 0)
    }

    /// An empty table of rows of `width` states, with room for `samples` rows.
    pub fn with_capacity(width: usize, samples: usize) -> Self {
        BackTable {
            width,
            skips: Vec::with_capacity(width * samples),
            lows: Vec::with_capacity(samples),
            first: 0,
        }
    }

    /// States per row.
    pub fn width(&self) -> usize {
        self.width
    }

    /// The oldest sample held.
    pub fn first(&self) -> usize {
        self.first
    }

    /// The sample after the newest held.
    pub fn end(&self) -> usize {
        self.first + self.lows.len()
    }

    /// Appends the row of the next sample, states `low .. low + width`, each its own
    /// predecessor until [`Row::set`] says otherwise.
    pub fn push_row(&mut self, low: usize) -> Row<'_, T> {
        let start = self.skips.len();
        self.skips.resize(start + self.width, T::default());
        self.lows.push(low);
        Row {
            low,
            skips: &mut self.skips[start..],
        }
    }

    /// The predecessor of state `j` (in its row) at the held sample `k`.
    #[inline]
    pub fn predecessor(&self, k: usize, j: usize) -> usize {
        let r = k - self.first;
        j - self.skips[r * self.width + j - self.lows[r]].skip()
    }

    /// Drops the rows of the samples before `k` (at most [`BackTable::end`]).
    pub fn drop_before(&mut self, k: usize) {
        let count = k - self.first;
        self.skips.drain(..count * self.width);
        self.lows.drain(..count);
        self.first = k;
    }
}

/// The newest row of a [`BackTable`], being written.
#[derive(Debug)]
pub struct Row<'a, T> {
    low: usize,
    skips: &'a mut [T],
}

impl<T: Skip> Row<'_, T> {
    /// Records `from` (≤ `j`, within the table's skip range) as the predecessor of state
    /// `j` of the row.
    #[inline]
    pub fn set(&mut self, j: usize, from: usize) {
        self.skips[j - self.low] = T::from_skip(j - from);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contour::five_axis::hmm::{viterbi_offline, HmmParams, ReferencePolyline};
    use crate::contour::five_axis::hmm_online::OnlineMapper;
    use crate::contour::five_axis::run_evaluation::viterbi_windowed;
    use crate::geometry::{self, Vector};
    use crate::math;

    use rand::rngs::StdRng;
    use rand::{RngExt, SeedableRng};

    type V3 = Vector<3>;

    /// The least summed cost over every admissible path, each state j_k in `windows[k]`,
    /// moving by 0 ..= `max_skip` a sample (summed in sample order, as the recursion
    /// does); `None` when no path is admissible.
    fn brute_force(
        costs: &[Vec<f64>],
        windows: &[Range<usize>],
        max_skip: usize,
    ) -> Option<(f64, Vec<usize>)> {
        fn walk(
            k: usize,
            path: &mut Vec<usize>,
            total: f64,
            ctx: (&[Vec<f64>], &[Range<usize>], usize),
            best: &mut Option<(f64, Vec<usize>)>,
        ) {
            let (costs, windows, max_skip) = ctx;
            if k == costs.len() {
                if best.as_ref().is_none_or(|b| total < b.0) {
                    *best = Some((total, path.clone()));
                }
                return;
            }
            for j in windows[k].clone() {
                if k > 0 && !(path[k - 1] <= j && j <= path[k - 1] + max_skip) {
                    continue;
                }
                path.push(j);
                let total = if k == 0 {
                    costs[k][j]
                } else {
                    total + costs[k][j]
                };
                walk(k + 1, path, total, ctx, best);
                path.pop();
            }
        }
        let mut best = None;
        walk(
            0,
            &mut Vec::new(),
            0.0,
            (costs, windows, max_skip),
            &mut best,
        );
        best
    }

    /// A decoder made of the core alone over windows of `width` states: the windowed
    /// form's rules (states without a finite predecessor stay out of reach). `drop_every`
    /// drops the back-pointer rows of decided samples now and then, as the windowed form
    /// does.
    fn core_decode(
        costs: &[Vec<f64>],
        windows: &[Range<usize>],
        max_skip: usize,
    ) -> Option<(f64, Vec<usize>)> {
        let width = windows[0].len();
        let m = costs[0].len();
        let (mut cost, mut next) = (vec![f64::NAN; m], vec![f64::NAN; m]);
        let mut back = BackTable::<u8>::new(width);
        for (k, window) in windows.iter().enumerate() {
            let mut row = back.push_row(window.start);
            let c = |j: usize| costs[k][j];
            if k == 0 {
                start(window.clone(), c, |j, cj, i| {
                    next[j] = cj;
                    row.set(j, i);
                });
            } else {
                let previous = |i: usize| cost[i];
                let score = |j, best: f64| {
                    if best.is_finite() {
                        best + c(j)
                    } else {
                        f64::INFINITY
                    }
                };
                step(
                    max_skip,
                    window.clone(),
                    windows[k - 1].clone(),
                    previous,
                    score,
                    |j, cj, i| {
                        next[j] = cj;
                        row.set(j, i);
                    },
                );
            }
            std::mem::swap(&mut cost, &mut next);
        }
        let last = windows.last().unwrap();
        let j = best_state(last.clone(), |j| cost[j]);
        if !cost[j].is_finite() {
            return None;
        }
        let mut path = vec![usize::MAX; costs.len()];
        let n = costs.len();
        let predecessor = |k, j| back.predecessor(k, j);
        let first = backtrack(n - 1, j, 0, predecessor, |k, j| path[k] = j);
        assert_eq!(first, path[0]);
        Some((cost[j], path))
    }

    #[test]
    fn the_recursion_equals_a_brute_force_enumeration() {
        let mut rng = StdRng::seed_from_u64(0xB0A7_F0CE_0000_0001);
        let mut unreachable = 0;
        for case in 0..400 {
            let n = 1 + case % 6;
            let m = 1 + (case / 6) % 7;
            let max_skip = rng.random_range(0..4usize);
            let width = rng.random_range(1..=m);
            // Windows that never move back, as the windowed form's; a full-width window
            // every fourth case, as the offline form's.
            let mut lo = rng.random_range(0..=m - width);
            let windows: Vec<Range<usize>> = (0..n)
                .map(|_| {
                    if case % 4 == 0 {
                        return 0..m;
                    }
                    lo = rng.random_range(lo..=(lo + 2).min(m - width));
                    lo..lo + width
                })
                .collect();
            // Integer costs every other case: ties everywhere.
            let costs: Vec<Vec<f64>> = (0..n)
                .map(|_| {
                    (0..m)
                        .map(|_| {
                            if case % 2 == 0 {
                                rng.random_range(0..4u32) as f64
                            } else {
                                rng.random_range(0.0..10.0)
                            }
                        })
                        .collect()
                })
                .collect();
            let expected = brute_force(&costs, &windows, max_skip);
            let got = core_decode(&costs, &windows, max_skip);
            match (&expected, &got) {
                (None, None) => unreachable += 1,
                (Some((best, brute)), Some((total, path))) => {
                    assert_eq!(total, best, "case {case}");
                    let sum = (1..n).fold(costs[0][path[0]], |s, k| s + costs[k][path[k]]);
                    assert_eq!(sum, *total, "case {case}: {path:?}");
                    for k in 0..n {
                        assert!(windows[k].contains(&path[k]), "case {case}: {path:?}");
                        if k > 0 {
                            assert!(path[k - 1] <= path[k] && path[k] <= path[k - 1] + max_skip);
                        }
                    }
                    // Without ties the optimum is one path.
                    if case % 2 == 1 {
                        assert_eq!(path, brute, "case {case}");
                    }
                }
                _ => panic!("case {case}: {expected:?} vs {got:?}"),
            }
        }
        assert!(unreachable > 0, "no case without an admissible path");
    }

    #[test]
    fn predecessors_tie_low_and_keep_to_the_live_states() {
        let costs = [3.0, 1.0, 1.0, 0.5, f64::NAN, 2.0];
        let previous = |i: usize| costs[i];
        assert_eq!(best_predecessor(2, 2, &(0..6), previous), (1.0, 1));
        assert_eq!(best_predecessor(3, 1, &(0..6), previous), (0.5, 3));
        assert_eq!(best_predecessor(3, 2, &(0..3), previous), (1.0, 1));
        assert_eq!(best_predecessor(3, 2, &(2..3), previous), (1.0, 2));
        // NaN never wins; nothing live: (∞, j).
        assert_eq!(
            best_predecessor(4, 0, &(0..6), previous),
            (f64::INFINITY, 4)
        );
        assert_eq!(best_predecessor(5, 1, &(0..6), previous), (2.0, 5));
        assert_eq!(
            best_predecessor(2, 3, &(3..6), previous),
            (f64::INFINITY, 2)
        );
        assert_eq!(
            best_predecessor(2, 3, &(0..0), previous),
            (f64::INFINITY, 2)
        );
        assert_eq!(best_state(0..6, previous), 3);
        assert_eq!(best_state(4..6, previous), 4);
        assert_eq!(best_state(2..2, previous), 2);
    }

    /// A wandering random reference (`m` segments, unit axes, tool length `length`) and a
    /// noisy run of `n` samples along it, some standing still.
    fn random_run(rng: &mut StdRng, m: usize, n: usize) -> (Vec<V3>, Vec<V3>, Vec<V3>, Vec<V3>) {
        let mut tips = vec![V3::zeros()];
        let mut heading: f64 = 0.0;
        for _ in 0..m {
            heading += rng.random_range(-1.2..1.2);
            let step = rng.random_range(0.3..2.0);
            let dz = rng.random_range(-0.3..0.3);
            let last = *tips.last().unwrap();
            tips.push(last + V3::new(math::cos(heading), math::sin(heading), dz) * step);
        }
        let tilted = |rng: &mut StdRng| {
            let (lean, azimuth): (f64, f64) =
                (rng.random_range(0.1..0.6), rng.random_range(-3.0..3.0));
            let o = V3::new(
                math::sin(lean) * math::sin(azimuth),
                math::sin(lean) * math::cos(azimuth),
                math::cos(lean),
            );
            geometry::unit(&o).unwrap()
        };
        let axes: Vec<V3> = (0..=m).map(|_| tilted(rng)).collect();
        let (mut run, mut run_axes) = (Vec::new(), Vec::new());
        for k in 0..n {
            if k > 0 && rng.random_range(0..8) == 0 {
                // Standing still: no motion, no angle term.
                run.push(run[k - 1]);
                run_axes.push(run_axes[k - 1]);
                continue;
            }
            let u = (k as f64 + rng.random_range(0.0..0.5)) * m as f64 / n as f64;
            let i = (u as usize).min(m - 1);
            let f = u - i as f64;
            let noise = V3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            run.push(tips[i] * (1.0 - f) + tips[i + 1] * f + noise * 0.4);
            run_axes.push(tilted(rng));
        }
        (tips, axes, run, run_axes)
    }

    #[test]
    fn the_three_mappers_agree_on_random_runs() {
        for seed in [1u64, 2, 3, 0xDEC0DE, 0x5EED_0005] {
            let mut rng = StdRng::seed_from_u64(seed);
            for case in 0..12 {
                let m = rng.random_range(1..40);
                let n = rng.random_range(1..60);
                let (tips, axes, run, run_axes) = random_run(&mut rng, m, n);
                let length = rng.random_range(1.0..120.0);
                let params = HmmParams {
                    max_skip: rng.random_range(1..5),
                    angle_weight: rng.random_range(0.0..2.0),
                };
                let what = format!("seed {seed}, case {case}: {m} segments, {n} samples");
                let reference = ReferencePolyline::new(&tips, &axes, length);
                let seconds: Vec<V3> = run
                    .iter()
                    .zip(&run_axes)
                    .map(|(p, o)| p + o * length)
                    .collect();
                let offline = viterbi_offline(&reference, &params, &run, &seconds);
                assert_eq!(offline.len(), n);

                // The windowed form over a window holding every segment.
                for window in [m, m + 7] {
                    let windowed = viterbi_windowed(&reference, &params, window, &run, &seconds);
                    assert_eq!(windowed, offline, "{what}, window {window}");
                }

                // The online form, no beam, a band holding every segment: with a lag
                // covering the run it reads back the offline mapping; with a short lag,
                // after every sample, what offline decodes for the run so far.
                let mut whole = OnlineMapper::new(params, length, m, n);
                let lag = 3;
                let mut short = OnlineMapper::new(params, length, m + 2, lag);
                for (p, o) in tips.iter().zip(&axes) {
                    whole.push_reference(*p, *o);
                    short.push_reference(*p, *o);
                }
                for k in 0..n {
                    whole.push_sample(run[k], run_axes[k]);
                    let newest = short.push_sample(run[k], run_axes[k]);
                    let prefix = viterbi_offline(&reference, &params, &run[..=k], &seconds[..=k]);
                    assert_eq!(newest, Some(prefix[k]), "{what}, sample {k}");
                    for s in 0..=lag.min(k) {
                        assert_eq!(short.mapped(s), Some(prefix[k - s]), "{what}, {k} − {s}");
                    }
                    assert_eq!(short.mapped(lag + 1), None);
                }
                for (k, &j) in offline.iter().enumerate() {
                    assert_eq!(whole.mapped(n - 1 - k), Some(j), "{what}, sample {k}");
                }
            }
        }
    }
}
