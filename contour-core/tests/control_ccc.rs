//! Two-axis cross-coupled controller (contour-core/src/control/cross_coupled.rs, ccc_law.rs and
//! config.rs): the correction is n·U_c with U_c recomputed here from the docs/design/two-axis.md
//! §4.2 formula, Off mode is the bare axis loops, fuzzy gains follow Kp0 + kpf·ΔKp′ from the
//! engine, configuration errors name the parameter, state survives serde, and on a closed
//! loop the CCC actually removes contour error.

use contour_core::contour::{ContourEstimate, ContourEstimator};
use contour_core::control::{
    CccConfig, CccLaw, CccMode, ConfigError, ControllerConfig, CrossCoupledController, FuzzyEngine,
    FuzzyFactor, FuzzyFactors, Gain, Parameter, PidGains,
};
use contour_core::geometry::Vector2;
use contour_core::math;
use serde::{Deserialize, Serialize};

/// Exact contour error of a circle (docs/design/two-axis.md §4.1), computed here independently.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct CircleEstimator {
    centre: [f64; 2],
    radius: f64,
    ccw: bool,
}

impl ContourEstimator for CircleEstimator {
    fn estimate(&mut self, _reference: Vector2, actual: Vector2) -> ContourEstimate {
        let d = [actual[0] - self.centre[0], actual[1] - self.centre[1]];
        let rho = math::hypot(d[0], d[1]);
        let s = if self.ccw { 1.0 } else { -1.0 };
        ContourEstimate {
            error: s * (rho - self.radius),
            normal: Vector2::new(-s * d[0] / rho, -s * d[1] / rho),
        }
    }
    fn reset(&mut self) {}
}

/// Replays a fixed list of estimates, so the expected correction can be worked out.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Scripted {
    script: Vec<ContourEstimate>,
    next: usize,
    calls: usize,
}

impl Scripted {
    fn new(script: Vec<ContourEstimate>) -> Self {
        Self {
            script,
            next: 0,
            calls: 0,
        }
    }
}

impl ContourEstimator for Scripted {
    fn estimate(&mut self, _reference: Vector2, _actual: Vector2) -> ContourEstimate {
        let e = self.script[self.next % self.script.len()];
        self.next += 1;
        self.calls += 1;
        e
    }
    fn reset(&mut self) {
        self.next = 0;
    }
}

fn est(error: f64, angle: f64) -> ContourEstimate {
    ContourEstimate {
        error,
        normal: Vector2::new(math::cos(angle), math::sin(angle)),
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * (1.0 + a.abs().max(b.abs()))
}

/// Scripted contour errors (mm) and normals, with reference/actual points.
fn script() -> Vec<(ContourEstimate, [f64; 2], [f64; 2])> {
    vec![
        (est(0.004, 0.3), [1.0, 2.0], [0.99, 2.003]),
        (est(0.0065, 1.2), [1.1, 2.05], [1.08, 2.06]),
        (est(-0.002, 2.0), [1.2, 2.1], [1.21, 2.08]),
        (est(-0.0005, -0.7), [1.3, 2.15], [1.295, 2.151]),
        (est(0.0, 3.0), [1.4, 2.2], [1.4, 2.2]),
        (est(0.03, 0.1), [1.5, 2.25], [1.52, 2.2]),
    ]
}

fn controller(mode: CccMode, gains0: PidGains) -> CrossCoupledController<Scripted> {
    let config = ControllerConfig {
        ts: 2e-3,
        axis: [PidGains::p(28.5), PidGains::p(31.0)],
        ccc: CccConfig {
            mode,
            gains0,
            limit: None,
            ..CccConfig::default()
        },
        ..ControllerConfig::default()
    };
    let estimates = script().into_iter().map(|(e, _, _)| e).collect();
    CrossCoupledController::new(config, Scripted::new(estimates)).unwrap()
}

#[test]
fn off_mode_is_pure_axis_loops() {
    let mut c = controller(CccMode::Off, PidGains::new(100.0, 5000.0, 1.0));
    for (e, r, p) in script() {
        let out = c.sample(r.into(), p.into());
        let ex = r[0] - p[0];
        let ey = r[1] - p[1];
        assert_eq!(out.following_error, Vector2::new(ex, ey));
        assert_eq!(out.u, Vector2::new(28.5 * ex, 31.0 * ey));
        assert_eq!(out.gains, (0.0, 0.0, 0.0));
        assert_eq!(out.contour, e); // the estimate is still reported
    }
    assert_eq!(c.estimator().calls, script().len());
}

#[test]
fn fixed_mode_correction_is_normal_times_uc() {
    let (kp, ki, kd, ts) = (120.0, 4000.0, 0.5, 2e-3);
    let mut c = controller(CccMode::Fixed, PidGains::new(kp, ki, kd));
    let mut sum = 0.0;
    let mut prev: Option<f64> = None;
    for (e, r, p) in script() {
        let out = c.sample(r.into(), p.into());
        let eps = e.error;
        sum += eps;
        let deps = prev.map_or(0.0, |q| eps - q);
        prev = Some(eps);
        let uc = kp * eps + ki * sum * ts + kd * deps / ts;
        let want = [
            28.5 * (r[0] - p[0]) + e.normal[0] * uc,
            31.0 * (r[1] - p[1]) + e.normal[1] * uc,
        ];
        assert!(close(out.u[0], want[0]), "{:?} vs {:?}", out.u, want);
        assert!(close(out.u[1], want[1]), "{:?} vs {:?}", out.u, want);
        assert_eq!(out.gains, (kp, ki, kd));
    }
}

#[test]
fn fuzzy_gains_follow_the_engine() {
    // Small Kp0 so that a negative ΔKp′ drives Kp below zero and the clamp shows.
    let g0 = PidGains::new(10.0, 50.0, 1.0);
    let f = FuzzyFactors::default();
    let ts = 2e-3;
    let mut c = controller(CccMode::Fuzzy, g0);
    let engine = FuzzyEngine::default();
    let (mut sum, mut prev) = (0.0, None::<f64>);
    let mut clamped = 0;
    for (e, r, p) in script() {
        let out = c.sample(r.into(), p.into());
        let eps = e.error;
        let deps = prev.map_or(0.0, |q| eps - q);
        prev = Some(eps);
        sum += eps;
        // ε and Δε in µm (per sample), folded onto E ≤ 0 (the sign of ε, or of Δε at
        // ε = 0, moves to EC); the engine clamps at ±3 itself.
        let sign = if eps != 0.0 {
            eps.signum()
        } else {
            deps.signum()
        };
        let e_in = -(f.ke * eps * 1000.0).abs();
        let ec_in = -sign * f.kde * deps * 1000.0;
        let d = engine.evaluate(e_in, ec_in);
        let kp = (g0.kp + f.kpf * d.dkp).max(0.0);
        let ki = (g0.ki + f.kif * d.dki).max(0.0);
        let kd = (g0.kd + f.kdf * d.dkd).max(0.0);
        clamped += [kp, ki, kd].iter().filter(|&&k| k == 0.0).count();
        assert!(close(out.gains.0, kp) && close(out.gains.1, ki) && close(out.gains.2, kd));
        let uc = kp * eps + ki * sum * ts + kd * deps / ts;
        assert!(close(out.u[0], 28.5 * (r[0] - p[0]) + e.normal[0] * uc));
        assert!(close(out.u[1], 31.0 * (r[1] - p[1]) + e.normal[1] * uc));
    }
    assert!(clamped > 0, "the script should exercise the >= 0 clamp");
}

#[test]
fn fuzzy_gains_are_plain_at_zero_error() {
    // At ε = Δε = 0 only the ZO/ZO rule fires: ΔKp′ = ΔKi′ = 0, ΔKd′ = NS = −1.
    let mut c = CrossCoupledController::new(
        ControllerConfig::default(),
        Scripted::new(vec![est(0.0, 0.0)]),
    )
    .unwrap();
    let out = c.sample(Vector2::new(0.0, 0.0), Vector2::new(0.0, 0.0));
    let g0 = CccConfig::default().gains0;
    assert!(close(out.gains.0, g0.kp));
    assert!(close(out.gains.1, g0.ki));
    assert!(close(out.gains.2, (g0.kd - 4.0).max(0.0)));
}

/// The scheduled gains depend on |ε| and on whether |ε| grows, never on the sign of ε:
/// (ε, Δε) and (−ε, −Δε) give bit-identical gains, on a grid that crosses ε = 0 and
/// Δε = 0 and reaches past the ±3 clamp, for the paper's factors and a large-kp set.
#[test]
fn fuzzy_gains_are_the_same_for_mirrored_errors() {
    let large_kp = FuzzyFactors {
        ke: 4.0,
        kde: 0.3,
        kpf: 900.0,
        kif: 40.0,
        kdf: 2.0,
    };
    let mut checked = 0;
    for factors in [FuzzyFactors::PAPER, large_kp] {
        let config = CccConfig {
            fuzzy: factors,
            ..CccConfig::default()
        };
        let law = CccLaw::new(config, 1e-3).unwrap();
        let steps = [
            -5e-3, -2.4e-3, -1e-3, -3.3e-4, -1e-6, 0.0, 1e-6, 3.3e-4, 1e-3, 2.4e-3, 5e-3,
        ];
        let mut distinct = std::collections::BTreeSet::new();
        for &eps in &steps {
            for &deps in &steps {
                let (g, _) = law.schedule(eps, deps);
                let (m, _) = law.schedule(-eps, -deps);
                assert_eq!(g, m, "eps {eps} deps {deps}");
                // Only |ε| and the sign of ε·Δε (of Δε at ε = 0) matter.
                let grows = if eps != 0.0 { eps * deps } else { deps.abs() };
                let (a, _) = law.schedule(eps.abs(), grows.signum() * deps.abs());
                assert_eq!(g, a, "eps {eps} deps {deps}");
                distinct.insert(format!("{g:?}"));
                checked += 1;
            }
        }
        // The schedule is not constant, so the equalities above carry information.
        assert!(distinct.len() > 20, "{} distinct gain sets", distinct.len());
    }
    assert_eq!(checked, 2 * 11 * 11);
}

#[test]
fn non_finite_estimate_gives_no_correction_and_keeps_state() {
    let script = vec![
        est(0.01, 0.0),
        ContourEstimate {
            error: f64::NAN,
            normal: Vector2::new(1.0, 0.0),
        },
        ContourEstimate {
            error: 0.01,
            normal: Vector2::new(f64::NAN, 0.0),
        },
        est(0.01, 0.0),
    ];
    let config = ControllerConfig {
        ccc: CccConfig {
            mode: CccMode::Fixed,
            gains0: PidGains::new(100.0, 1000.0, 0.0),
            ..CccConfig::default()
        },
        ..ControllerConfig::default()
    };
    let mut c = CrossCoupledController::new(config, Scripted::new(script)).unwrap();
    let first = c.sample(Vector2::new(0.0, 0.0), Vector2::new(0.0, 0.0));
    assert!(close(first.u[0], 100.0 * 0.01 + 1000.0 * 0.01 * 1e-3));
    for _ in 0..2 {
        let out = c.sample(Vector2::new(0.0, 0.0), Vector2::new(0.0, 0.0));
        assert_eq!(out.u, Vector2::new(0.0, 0.0));
        assert_eq!(out.gains, (0.0, 0.0, 0.0));
    }
    assert_eq!(c.law().pid().integral(), 0.01 * 1e-3);
    let last = c.sample(Vector2::new(0.0, 0.0), Vector2::new(0.0, 0.0));
    assert!(close(last.u[0], 100.0 * 0.01 + 1000.0 * 0.02 * 1e-3));
}

#[test]
fn correction_is_limited_with_anti_windup() {
    let config = ControllerConfig {
        ccc: CccConfig {
            mode: CccMode::Fixed,
            gains0: PidGains::new(100.0, 5000.0, 0.0),
            limit: Some(2.0),
            ..CccConfig::default()
        },
        ..ControllerConfig::default()
    };
    let mut c = CrossCoupledController::new(config, Scripted::new(vec![est(0.05, 0.0)])).unwrap();
    for _ in 0..1000 {
        let out = c.sample(Vector2::new(0.0, 0.0), Vector2::new(0.0, 0.0));
        assert_eq!(out.u, Vector2::new(2.0, 0.0)); // Kp·ε alone is 5 mm/s
    }
    assert_eq!(c.law().pid().integral(), 0.0); // never integrated while saturated
}

#[test]
fn validate_names_the_offending_parameter() {
    let base = ControllerConfig::default();
    assert_eq!(base.validate(), Ok(()));
    let cases: Vec<(ControllerConfig, Parameter)> = vec![
        (ControllerConfig { ts: 0.0, ..base }, Parameter::Ts),
        (ControllerConfig { ts: -1e-3, ..base }, Parameter::Ts),
        (
            ControllerConfig {
                ts: f64::NAN,
                ..base
            },
            Parameter::Ts,
        ),
        (
            ControllerConfig {
                ts: f64::INFINITY,
                ..base
            },
            Parameter::Ts,
        ),
        (
            ControllerConfig {
                axis: [PidGains::p(-1.0), PidGains::p(28.5)],
                ..base
            },
            Parameter::AxisGain(0, Gain::Kp),
        ),
        (
            ControllerConfig {
                axis: [PidGains::p(28.5), PidGains::new(28.5, f64::NAN, 0.0)],
                ..base
            },
            Parameter::AxisGain(1, Gain::Ki),
        ),
        (
            ControllerConfig {
                axis_limit: Some(0.0),
                ..base
            },
            Parameter::AxisLimit,
        ),
    ];
    let ccc_cases: Vec<(CccConfig, Parameter)> = vec![
        (
            CccConfig {
                gains0: PidGains::new(-5.0, 0.0, 0.0),
                ..base.ccc
            },
            Parameter::ContourGain(Gain::Kp),
        ),
        (
            CccConfig {
                gains0: PidGains::new(1.0, f64::INFINITY, 0.0),
                ..base.ccc
            },
            Parameter::ContourGain(Gain::Ki),
        ),
        (
            CccConfig {
                gains0: PidGains::new(1.0, 1.0, -0.1),
                ..base.ccc
            },
            Parameter::ContourGain(Gain::Kd),
        ),
        (
            CccConfig {
                limit: Some(f64::NAN),
                ..base.ccc
            },
            Parameter::ContourLimit,
        ),
    ];
    type Edit = fn(&mut FuzzyFactors);
    let fuzzy_cases: [(Edit, Parameter); 6] = [
        (|f| f.ke = -1.0, Parameter::Fuzzy(FuzzyFactor::Ke)),
        (|f| f.kde = -0.5, Parameter::Fuzzy(FuzzyFactor::Kde)),
        (|f| f.kpf = -87.0, Parameter::Fuzzy(FuzzyFactor::Kpf)),
        (|f| f.kif = f64::NAN, Parameter::Fuzzy(FuzzyFactor::Kif)),
        (|f| f.kdf = -4.0, Parameter::Fuzzy(FuzzyFactor::Kdf)),
        (
            |f| f.ke = f64::NEG_INFINITY,
            Parameter::Fuzzy(FuzzyFactor::Ke),
        ),
    ];
    let mut all = cases;
    for (ccc, name) in ccc_cases {
        all.push((ControllerConfig { ccc, ..base }, name));
    }
    for (edit, name) in fuzzy_cases {
        let mut cfg = base;
        edit(&mut cfg.ccc.fuzzy);
        all.push((cfg, name));
    }
    for (cfg, name) in all {
        let err: ConfigError = cfg.validate().unwrap_err();
        assert_eq!(err.parameter, name, "{err}");
        assert!(err.to_string().contains(&name.to_string()));
        let estimator = CircleEstimator {
            centre: [0.0, 0.0],
            radius: 1.0,
            ccw: true,
        };
        let from_new = CrossCoupledController::new(cfg, estimator).unwrap_err();
        assert_eq!(from_new.parameter, name); // (NaN values defeat a whole-struct ==)
    }
}

#[test]
fn defaults_are_documented_values() {
    let c = ControllerConfig::default();
    assert_eq!(c.ts, 1e-3);
    assert_eq!(c.axis, [PidGains::p(28.5); 2]);
    assert_eq!(c.ccc.mode, CccMode::Fuzzy);
    let f = c.ccc.fuzzy;
    assert_eq!(
        (f.ke, f.kde, f.kpf, f.kif, f.kdf),
        (1.0, 1.2, 87.0, 8.5, 4.0)
    );
}

/// Circle of the paper: centre (−10, 0), radius 10, counter-clockwise, half a turn per s.
fn circle_point(t: f64) -> [f64; 2] {
    let a = std::f64::consts::PI * t;
    [10.0 * math::cos(a) - 10.0, 10.0 * math::sin(a)]
}

fn circle_controller(mode: CccMode) -> CrossCoupledController<CircleEstimator> {
    let config = ControllerConfig {
        ccc: CccConfig {
            mode,
            ..CccConfig::default()
        },
        ..ControllerConfig::default()
    };
    let estimator = CircleEstimator {
        centre: [-10.0, 0.0],
        radius: 10.0,
        ccw: true,
    };
    CrossCoupledController::new(config, estimator).unwrap()
}

/// Closed loop with an ideal velocity-following axis (p ← p + u·Ts), one full turn;
/// returns the largest |ε| over the second turn-half (after the start transient).
fn closed_loop_max_error(c: &mut CrossCoupledController<CircleEstimator>) -> f64 {
    let ts = c.config().ts;
    let mut p = circle_point(0.0);
    let mut worst: f64 = 0.0;
    for k in 0..2000 {
        let out = c.sample(circle_point(k as f64 * ts).into(), p.into());
        if k >= 1000 {
            worst = worst.max(out.contour.error.abs());
        }
        p = [p[0] + out.u[0] * ts, p[1] + out.u[1] * ts];
    }
    worst
}

#[test]
fn ccc_removes_contour_error_on_a_circle() {
    let off = closed_loop_max_error(&mut circle_controller(CccMode::Off));
    // Sampled P loop around an integrator: the actual circle shrinks by the loop's
    // magnitude response |K/(s + K)| at ω = π (about 60 µm here).
    let (k, w) = (28.5_f64, std::f64::consts::PI);
    let analytic = 10.0 * (1.0 - k / (k * k + w * w).sqrt());
    assert!(
        (off - analytic).abs() < 0.05 * analytic,
        "{off} vs {analytic}"
    );
    let fixed = closed_loop_max_error(&mut circle_controller(CccMode::Fixed));
    let fuzzy = closed_loop_max_error(&mut circle_controller(CccMode::Fuzzy));
    println!(
        "max |ε| over the second half-turn: off {off:.3e}, fixed {fixed:.3e}, fuzzy {fuzzy:.3e} mm"
    );
    assert!(fixed < off / 100.0, "fixed CCC: {fixed} vs off {off}");
    assert!(fuzzy < off / 100.0, "fuzzy CCC: {fuzzy} vs off {off}");
}

#[test]
fn reset_and_serde_restore_reproduce_the_run() {
    let mut c = circle_controller(CccMode::Fuzzy);
    let drive = |c: &mut CrossCoupledController<CircleEstimator>, from: usize, n: usize| {
        (from..from + n)
            .map(|k| {
                let t = k as f64 * 1e-3;
                let p = circle_point(t - 0.02); // a lagging "actual" point
                c.sample(circle_point(t).into(), Vector2::new(p[0] + 1e-3, p[1]))
            })
            .collect::<Vec<_>>()
    };
    let first = drive(&mut c, 0, 50);
    let bytes = postcard::to_stdvec(&c).unwrap();
    let json = serde_json::to_string(&c).unwrap();
    let after = drive(&mut c, 50, 50);
    let mut restored: CrossCoupledController<CircleEstimator> =
        postcard::from_bytes(&bytes).unwrap();
    assert_eq!(drive(&mut restored, 50, 50), after);
    // serde_json's default float parser may be 1 ulp off, so JSON is checked loosely.
    let mut restored: CrossCoupledController<CircleEstimator> =
        serde_json::from_str(&json).unwrap();
    for (a, b) in drive(&mut restored, 50, 50).iter().zip(&after) {
        for i in 0..2 {
            assert!((a.u[i] - b.u[i]).abs() < 1e-9 * (1.0 + b.u[i].abs()));
        }
    }
    c.reset();
    assert_eq!(drive(&mut c, 0, 50), first);
    assert_ne!(first[49], after[0]);
}
