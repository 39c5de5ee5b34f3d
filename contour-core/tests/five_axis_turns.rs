//! The controller's per-sample contour errors in tight turns (docs/design/five-axis.md §5.3),
//! against a brute force on the smooth path.
//!
//! A figure-eight whose loop ends turn at radius ρ (1.5 and 1 mm), the tool axis tilted
//! and leaning along it, sampled every 0.03 mm (30 mm/s at Ts = 1 ms) into reference
//! joints; the "machine" is the reference 3 samples late plus smooth offsets on every
//! joint, so its pose has realistic tip and orientation errors. Its Y offset peaks at the
//! loop ends, where Y runs along the path: through one loop end the tool runs up to
//! 3 samples ahead of its delay, onto the newest reference segment and past it — where
//! the controller knows no reference yet.
//!
//! The truth is the measured tip's nearest point on the smooth curve (a fine scan and
//! golden section, on the branch being traced) and the angle from the measured axis to
//! the curve's axis there. The controller sees only the reference samples: their chords
//! lie inside the curve by up to c²/(8ρ) (0.075 µm at 1.5 mm, 0.11 µm at 1 mm), part of
//! what is measured.

use contour_core::control::{FiveAxisConfig, FiveAxisController};
use contour_core::geometry::{self, Vector};
use contour_core::kinematics::{Joints, Pose, TableTiltingAc};
use contour_core::math;

type V3 = Vector<3>;

const TS: f64 = 1e-3;
const FEED: f64 = 30.0;
const DELAY: usize = 3;

/// x = a·sin t, y = b·sin 2t in z = 0; the loop ends (t = π/2, 3π/2) bend at radius
/// 4b²/a. The tool is tilted 25° toward +y and leans 2.5°·cos t toward x.
struct Eight {
    a: f64,
    b: f64,
}

impl Eight {
    fn with_loop_ends_at(radius: f64) -> Self {
        let a = 10.0;
        Eight {
            a,
            b: (radius * a / 4.0).sqrt(),
        }
    }

    fn tip(&self, t: f64) -> V3 {
        V3::new(self.a * math::sin(t), self.b * math::sin(2.0 * t), 0.0)
    }

    fn velocity(&self, t: f64) -> V3 {
        V3::new(
            self.a * math::cos(t),
            2.0 * self.b * math::cos(2.0 * t),
            0.0,
        )
    }

    fn axis(&self, t: f64) -> V3 {
        let (lean, tilt) = (2.5f64.to_radians() * math::cos(t), 25f64.to_radians());
        V3::new(
            math::sin(lean) * math::cos(tilt),
            math::sin(tilt),
            math::cos(lean) * math::cos(tilt),
        )
    }

    fn bend_radius(&self, t: f64) -> f64 {
        let v = self.velocity(t);
        let acceleration = V3::new(
            -self.a * math::sin(t),
            -4.0 * self.b * math::sin(2.0 * t),
            0.0,
        );
        geometry::norm(&v).powi(3) / geometry::norm(&v.cross(&acceleration))
    }

    /// The parameters of the points every `step` mm of arc length over one turn
    /// (Simpson's rule on 400 000 intervals, linear within one).
    fn stations(&self, step: f64) -> Vec<f64> {
        let n = 400_000;
        let h = std::f64::consts::TAU / n as f64;
        let speed = |t: f64| geometry::norm(&self.velocity(t));
        let mut out = vec![0.0];
        let (mut s, mut next) = (0.0, step);
        for i in 0..n {
            let t = i as f64 * h;
            let ds = h / 6.0 * (speed(t) + 4.0 * speed(t + h / 2.0) + speed(t + h));
            while s + ds >= next {
                out.push(t + h * (next - s) / ds);
                next += step;
            }
            s += ds;
        }
        out
    }

    /// The parameter of the point of the curve nearest `p` within [lo, hi]: a scan of
    /// 4000 points (under 1 µm apart here), then golden section around the best.
    fn nearest(&self, p: &V3, lo: f64, hi: f64) -> f64 {
        let d2 = |t: f64| geometry::dist2(&self.tip(t), p);
        let n = 4000;
        let h = (hi - lo) / n as f64;
        let best = (0..=n)
            .map(|i| lo + h * i as f64)
            .min_by(|x, y| d2(*x).total_cmp(&d2(*y)))
            .unwrap();
        assert!(
            best > lo && best < hi,
            "the nearest point is inside the window"
        );
        let (mut a, mut b) = (best - h, best + h);
        let g = (5f64.sqrt() - 1.0) / 2.0;
        while b - a > 1e-13 {
            let (c, d) = (b - g * (b - a), a + g * (b - a));
            if d2(c) < d2(d) {
                b = d;
            } else {
                a = c;
            }
        }
        (a + b) / 2.0
    }
}

/// Smooth joint offsets at time `tau` (s): tens of µm on X, Z, a few 10⁻⁴ rad on A, C,
/// and on Y ±0.1 mm peaking at the loop ends (reached at 0.38 s and 1.13 s on the 1.5 mm
/// path, 0.37 s and 1.12 s on the 1 mm one) and near zero on the legs.
fn offset(tau: f64, loop_end: f64) -> Joints {
    let w = std::f64::consts::TAU;
    Joints::new(
        0.04 * math::sin(w * 0.9 * tau + 0.3),
        0.1 * math::cos(w * (tau - loop_end) / 1.5).powi(3),
        0.01 * math::sin(w * 0.4 * tau + 2.0),
        3.5e-4 * math::sin(w * 0.7 * tau + 0.5),
        5e-4 * math::sin(w * 0.5 * tau + 1.5),
    )
}

/// What one run measures: the largest true errors, and the largest and median
/// |estimate − truth| in the turns (bend radius under 2ρ) and elsewhere.
#[derive(Debug)]
struct Summary {
    peak: (f64, f64),
    turns: Deviations,
    elsewhere: Deviations,
    /// Samples whose true foot lies on the newest reference segment, and past it.
    on_newest: usize,
    past_newest: usize,
    /// The largest |estimate − truth| (tip, orientation) where the true foot lies on an
    /// older segment, on the newest and past it.
    by_place: [(f64, f64); 3],
}

#[derive(Debug, Default)]
struct Deviations {
    samples: usize,
    max: (f64, f64),
    median: (f64, f64),
}

impl Deviations {
    fn of(deviations: &[(f64, f64)]) -> Self {
        let median = |pick: fn(&(f64, f64)) -> f64| {
            let mut v: Vec<f64> = deviations.iter().map(pick).collect();
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        Deviations {
            samples: deviations.len(),
            max: deviations
                .iter()
                .fold((0.0, 0.0), |m, d| (m.0.max(d.0), m.1.max(d.1))),
            median: (median(|d| d.0), median(|d| d.1)),
        }
    }
}

fn run(radius: f64, reverse: bool) -> Summary {
    let eight = Eight::with_loop_ends_at(radius);
    // The loop ends are as tight as asked, and the tightest bends.
    let tightest = (0..10_000)
        .map(|i| eight.bend_radius(i as f64 * std::f64::consts::TAU / 10_000.0))
        .fold(f64::INFINITY, f64::min);
    assert!((tightest - radius).abs() < 1e-3 * radius, "{tightest}");
    let mut stations = eight.stations(FEED * TS);
    if reverse {
        stations.reverse();
    }
    let machine = TableTiltingAc::ORIGIN;
    let mut c = 0.0;
    let reference: Vec<Joints> = stations
        .iter()
        .map(|&t| {
            let pose = Pose {
                tip: eight.tip(t),
                axis: eight.axis(t),
            };
            let q = machine.inverse(&pose, c).unwrap();
            c = q[4];
            q
        })
        .collect();
    let n = reference.len();
    // When the run reaches the first loop end (t = π/2, or 3π/2 in reverse: the same
    // time), so that the Y offset peaks there.
    let loop_end = stations
        .iter()
        .position(|t| (t - std::f64::consts::FRAC_PI_2).abs() < 0.01)
        .map(|k| if reverse { n - k } else { k })
        .unwrap() as f64
        * TS;

    let mut controller = FiveAxisController::new(FiveAxisConfig::DEFAULT).unwrap();
    let (mut turns, mut elsewhere) = (Vec::new(), Vec::new());
    let (mut peak, mut on_newest, mut past_newest) = ((0.0f64, 0.0f64), 0, 0);
    let mut by_place = [(0.0f64, 0.0f64); 3];
    for k in 0..n {
        let delayed = k.saturating_sub(DELAY);
        let actual = reference[delayed] + offset(k as f64 * TS, loop_end);
        let out = controller.sample(&reference[k], &actual).unwrap();
        if delayed < 10 {
            continue;
        }
        let pose = machine.forward(&actual);
        // On the branch being traced: within 1 mm of path of the delayed sample.
        let t0 = stations[delayed];
        let t = eight.nearest(&pose.tip, t0 - 0.25, t0 + 0.25);
        let truth = (
            geometry::dist(&eight.tip(t), &pose.tip),
            geometry::angle_between(&eight.axis(t), &pose.axis),
        );
        let e = out.error.expect("an estimate every sample");
        let estimate = (geometry::norm(&e.tip), e.orientation);
        let deviation = ((estimate.0 - truth.0).abs(), (estimate.1 - truth.1).abs());
        peak = (peak.0.max(truth.0), peak.1.max(truth.1));
        // Where the truth's foot lies against the newest reference points k − 1 and k.
        let along = |i: usize| (stations[i] - t) * if reverse { -1.0 } else { 1.0 };
        let place = if along(k) < 0.0 {
            past_newest += 1;
            2
        } else if along(k - 1) < 0.0 {
            on_newest += 1;
            1
        } else {
            0
        };
        let worst = &mut by_place[place];
        *worst = (worst.0.max(deviation.0), worst.1.max(deviation.1));
        if eight.bend_radius(t) < 2.0 * radius {
            turns.push(deviation);
        } else {
            elsewhere.push(deviation);
        }
    }
    Summary {
        peak,
        turns: Deviations::of(&turns),
        elsewhere: Deviations::of(&elsewhere),
        on_newest,
        past_newest,
        by_place,
    }
}

/// Both directions at one radius: in the turns and elsewhere the estimate is within 1 %
/// of the largest true error, tip and orientation separately.
fn check(radius: f64) {
    let runs = [false, true].map(|reverse| run(radius, reverse));
    for (s, reverse) in runs.iter().zip([false, true]) {
        eprintln!("ρ = {radius} mm, reverse {reverse}: {s:?}");
    }
    for s in runs {
        // The run is what it is meant to be: errors of tens of µm and about a mrad, turns
        // of over a hundred samples, and the tool ahead of the newest reference in some.
        assert!(s.peak.0 > 0.04 && s.peak.0 < 0.15, "{s:?}");
        assert!(s.peak.1 > 5e-4 && s.peak.1 < 5e-3, "{s:?}");
        assert!(s.turns.samples > 150 && s.elsewhere.samples > 800, "{s:?}");
        assert!(s.on_newest > 20 && s.past_newest > 10, "{s:?}");
        for (name, d) in [("turns", &s.turns), ("elsewhere", &s.elsewhere)] {
            assert!(d.max.0 <= 0.01 * s.peak.0, "{name}: tip {s:?}");
            assert!(d.max.1 <= 0.01 * s.peak.1, "{name}: orientation {s:?}");
            // Typically far closer: the chords' sagitta in the turns (30–40 nm), a few nm
            // and 10⁻⁸ rad elsewhere.
            assert!(d.median.0 <= 5e-4 * s.peak.0, "{name}: tip {s:?}");
            assert!(d.median.1 <= 5e-4 * s.peak.1, "{name}: orientation {s:?}");
        }
        // Where the foot lies past the newest reference point too (clamped there, the
        // estimate was off by 0.5–1.7 µm and 63–116 µrad).
        let past = s.by_place[2];
        assert!(
            past.0 <= 0.01 * s.peak.0 && past.1 <= 0.01 * s.peak.1,
            "{s:?}"
        );
    }
}

#[test]
fn in_1_5_mm_turns_the_estimate_is_within_1_percent_of_the_peak_both_ways() {
    check(1.5);
}

#[test]
fn in_1_mm_turns_the_estimate_is_within_1_percent_of_the_peak_both_ways() {
    check(1.0);
}
