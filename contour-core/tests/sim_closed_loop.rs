//! The in-process closed loop (`contour_core::sim`): the documented sample sequence, the
//! effect of cross-coupling on the built-in paths, metrics, and divergence handling.
//! The independent plant model is in tests/reference/test_closed_loop_scipy.py.

use contour_core::contour::planar::{true_error, Estimator, EstimatorKind};
use contour_core::control::{CccMode, ControllerConfig, CrossCoupledController, PidGains};
use contour_core::math;
use contour_core::path::planar::builtin;
use contour_core::path::Interpolator;
use contour_core::plant::{XyTable, XyTableParams};
use contour_core::sim::{
    DivergenceKind, Metrics, SimConfig, SimResult, Simulator, FREE_CURVE_FEED, PAPER_CIRCLE_FEED,
};

fn run(config: SimConfig) -> SimResult {
    let r = Simulator::new(config).unwrap().run();
    assert!(r.metrics.is_stable(), "{:?}", r.metrics.divergence);
    r
}

/// Max |true contour error| (mm) without, with fixed-gain and with fuzzy-PID CCC.
fn three_modes(config: &SimConfig) -> [Metrics; 3] {
    [CccMode::Off, CccMode::Fixed, CccMode::Fuzzy].map(|m| run(config.clone().with_mode(m)).metrics)
}

#[test]
fn ccc_reduces_contour_error_on_the_paper_circle() {
    for plant in [XyTableParams::PAPER, XyTableParams::mismatched()] {
        let [off, fixed, fuzzy] = three_modes(&SimConfig::paper_circle().with_plant(plant));
        // docs/design/two-axis.md §4.2: 47.7 µm without CCC (the paper: 0.049 mm).
        assert!(
            (0.045..0.050).contains(&off.max_abs_error),
            "no CCC: {off:?}"
        );
        for (name, m) in [("fixed", fixed), ("fuzzy", fuzzy)] {
            assert!(
                m.max_abs_error < 0.2 * off.max_abs_error,
                "{name}: {m:?} vs {off:?}"
            );
            assert!(m.mean_abs_error < 0.1 * off.mean_abs_error, "{name}: {m:?}");
            // After the start-up transient the PI CCC holds the circle within a µm
            // (docs/design/two-axis.md §4.2 measured 0.08 µm for the fixed gains).
            assert!(m.settled_max_abs_error < 1e-3, "{name}: {m:?}");
        }
    }
}

#[test]
fn ccc_reduces_contour_error_on_free_curves() {
    // The preset feed of the free curves (50 mm/s, see FREE_CURVE_FEED).
    for name in ["infinity", "trident"] {
        let config = SimConfig::builtin(name).unwrap();
        assert_eq!(config.feed, FREE_CURVE_FEED);
        let [off, fixed, fuzzy] = three_modes(&config);
        // The curvature leaves tens of µm without CCC at this feed.
        assert!(off.max_abs_error > 0.05, "{name}: {off:?}");
        for (mode, m) in [("fixed", fixed), ("fuzzy", fuzzy)] {
            assert!(
                m.max_abs_error < 0.5 * off.max_abs_error
                    && m.mean_abs_error < 0.5 * off.mean_abs_error,
                "{name} {mode}: {m:?} vs {off:?}"
            );
        }
    }
}

#[test]
fn metrics_only_equals_recorded_metrics() {
    for name in ["circle", "trident"] {
        for mode in [CccMode::Off, CccMode::Fuzzy] {
            let sim = Simulator::new(SimConfig::builtin(name).unwrap().with_mode(mode)).unwrap();
            let recorded = sim.run();
            assert_eq!(sim.metrics(), recorded.metrics, "{name} {mode:?}");
            let m = recorded.metrics;
            // Recomputed here from the trace, in the same order: bit for bit.
            let tr = &recorded.trace;
            assert_eq!(m.samples, tr.len());
            let abs: Vec<f64> = tr.true_error.iter().map(|e| e.abs()).collect();
            assert_eq!(m.max_abs_error, abs.iter().cloned().fold(0.0, f64::max));
            assert_eq!(m.mean_abs_error, abs.iter().sum::<f64>() / abs.len() as f64);
            let settled: Vec<f64> =
                tr.t.iter()
                    .zip(&abs)
                    .filter(|(t, _)| **t >= 0.2 - 1e-12)
                    .map(|(_, e)| *e)
                    .collect();
            assert_eq!(m.settled_samples, settled.len());
            assert_eq!(
                m.settled_max_abs_error,
                settled.iter().cloned().fold(0.0, f64::max)
            );
            assert_eq!(
                m.settled_mean_abs_error,
                settled.iter().sum::<f64>() / settled.len() as f64
            );
            // The controller-swapping entry point the PSO uses gives the same answer.
            let c = sim.config().controller;
            assert_eq!(sim.metrics_with(&c).unwrap(), m);
        }
    }
}

#[test]
fn trace_follows_the_documented_sample_sequence() {
    let mut config = SimConfig::builtin("infinity").unwrap();
    config.plant = XyTableParams::mismatched();
    config.settle = 0.1;
    let sim = Simulator::new(config.clone()).unwrap();
    let tr = sim.run().trace;

    // References: current() at k = 0, then step(); the path end + 100 samples of settle.
    let mut interp = Interpolator::new(config.path.clone(), config.feed, config.ts).unwrap();
    let mut refs = vec![interp.current()];
    while !refs.last().unwrap().done {
        refs.push(interp.step());
    }
    for _ in 0..100 {
        refs.push(interp.step());
    }
    assert_eq!(tr.len(), refs.len());

    // Replay with independent instances: the plant starts at rest at the path start and
    // P_k is its position at t_k; u_k is held over [t_k, t_k+1).
    let mut plant = XyTable::new(config.plant, config.path.start_point());
    let estimator = Estimator::for_path(EstimatorKind::FreeCurve, &config.path);
    let mut ctl = CrossCoupledController::new(config.controller, estimator).unwrap();
    for (k, r) in refs.iter().enumerate() {
        assert_eq!(tr.t[k], k as f64 * config.ts);
        assert_eq!(tr.reference[k], r.point, "k={k}");
        assert_eq!(tr.actual[k], plant.position(), "k={k}");
        let out = ctl.sample(r.point, plant.position());
        assert_eq!(tr.u[k], out.u, "k={k}");
        assert_eq!(tr.estimated_error[k], out.contour.error);
        assert_eq!(tr.gains[k], [out.gains.0, out.gains.1, out.gains.2]);
        plant.step(out.u, config.ts);
        // The recorded true error is the global distance to the path (brute force).
        if k % 97 == 0 {
            let g = true_error(&config.path, tr.actual[k]);
            assert!((g.error - tr.true_error[k]).abs() < 1e-12, "k={k}");
        }
    }
    // 100 ms after the path end the table has nearly caught up with the end point.
    let end = config.path.end_point();
    let last = tr.actual[tr.len() - 1];
    assert!(math::hypot(last[0] - end[0], last[1] - end[1]) < 0.1);
}

#[test]
fn absurd_gain_is_flagged_not_panicking() {
    let mut config = SimConfig::paper_circle();
    config.controller.axis = [PidGains::p(1e6); 2];
    let sim = Simulator::new(config).unwrap();
    let r = sim.run();
    let d = r.metrics.divergence.expect("Kpp = 1e6 must diverge");
    assert_eq!(d.kind, DivergenceKind::ErrorLimit);
    assert!(d.k < 100 && d.k == r.trace.len(), "{d:?}");
    assert!(d.value > 10.0 && d.value.is_finite());
    let m = sim.metrics();
    assert_eq!(m, r.metrics);
    assert!(!m.is_stable() && m.max_abs_error.is_finite() && m.mean_abs_error.is_finite());
    assert!(r.trace.true_error.iter().all(|e| e.abs() <= 10.0));

    // A huge CCC gain through the PSO's entry point: also flagged, never NaN.
    let good = Simulator::new(SimConfig::paper_circle()).unwrap();
    let mut c = ControllerConfig::default();
    c.ccc.mode = CccMode::Fixed;
    c.ccc.gains0 = PidGains::new(1e9, 1e12, 1e6);
    c.ccc.limit = None;
    let m = good.metrics_with(&c).unwrap();
    assert!(!m.is_stable(), "{m:?}");
    assert!(m.mean_abs_error.is_finite());
}

#[test]
fn paper_circle_preset() {
    let c = SimConfig::paper_circle();
    assert_eq!(c.feed, PAPER_CIRCLE_FEED);
    assert_eq!(c, SimConfig::builtin("circle").unwrap());
    assert_eq!(c.path, builtin::by_name("circle").unwrap());
    assert_eq!(c.estimator, EstimatorKind::FreeCurve);
    assert_eq!(c.controller.ccc.mode, CccMode::Fuzzy);
}
