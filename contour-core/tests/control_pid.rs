//! Discrete PID (contour-core/src/control/pid.rs): responses against sequences worked out by hand, the
//! conditional-integration anti-windup, per-sample gain changes and state round trips.

use contour_core::control::{Pid, PidGains};

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * (1.0 + a.abs().max(b.abs()))
}

fn run(pid: &mut Pid, errors: &[f64]) -> Vec<f64> {
    errors.iter().map(|&e| pid.update(e)).collect()
}

fn assert_seq(got: &[f64], want: &[f64]) {
    assert_eq!(got.len(), want.len());
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(close(*g, *w), "sample {k}: got {g}, want {w}");
    }
}

#[test]
fn proportional_step() {
    let mut pid = Pid::new(PidGains::p(2.5), 0.01, None);
    assert_seq(&run(&mut pid, &[1.0, 1.0, -0.4]), &[2.5, 2.5, -1.0]);
}

#[test]
fn pi_step_integrates_including_current_sample() {
    // Kp = 2, Ki = 10, Ts = 0.1, unit step: I_k = 0.1·k, u_k = 2 + 10·0.1·k = 2 + k.
    let mut pid = Pid::new(PidGains::new(2.0, 10.0, 0.0), 0.1, None);
    assert_seq(&run(&mut pid, &[1.0; 5]), &[3.0, 4.0, 5.0, 6.0, 7.0]);
    assert!(close(pid.integral(), 0.5));
}

#[test]
fn pd_has_no_kick_on_first_sample() {
    // Kp = 1, Kd = 0.5, Ts = 0.1: d_k = 0.5·(e_k − e_{k−1})/0.1 = 5·Δe, with Δe_1 = 0.
    let mut pid = Pid::new(PidGains::new(1.0, 0.0, 0.5), 0.1, None);
    assert_seq(
        &run(&mut pid, &[1.0, 1.0, 3.0, 0.0]),
        &[1.0, 1.0, 3.0 + 10.0, -15.0],
    );
}

#[test]
fn full_pid_sequence() {
    // Kp = 3, Ki = 20, Kd = 0.02, Ts = 0.01, errors 0.5, 0.2, −0.1:
    // k=1: I = 0.005, u = 1.5 + 0.1 + 0           = 1.6
    // k=2: I = 0.007, u = 0.6 + 0.14 + 2·(−0.3)   = 0.14
    // k=3: I = 0.006, u = −0.3 + 0.12 + 2·(−0.3)  = −0.78
    let mut pid = Pid::new(PidGains::new(3.0, 20.0, 0.02), 0.01, None);
    assert_seq(&run(&mut pid, &[0.5, 0.2, -0.1]), &[1.6, 0.14, -0.78]);
}

#[test]
fn gain_change_rescales_stored_integral() {
    // The state is Σe·Ts, so doubling Ki doubles the integral action at once.
    let mut pid = Pid::new(PidGains::new(0.0, 10.0, 0.0), 0.1, None);
    run(&mut pid, &[1.0, 1.0, 1.0]); // I = 0.3
    pid.set_gains(PidGains::new(0.0, 20.0, 0.0));
    assert!(close(pid.update(0.0), 20.0 * 0.3));
    pid.set_gains(PidGains::new(1.0, 0.0, 0.0));
    assert!(close(pid.update(2.0), 2.0));
    assert!(close(pid.integral(), 0.5));
}

#[test]
fn anti_windup_freezes_integral_in_saturation() {
    // Kp = 1, Ki = 10, Ts = 0.1, |u| ≤ 2, unit error:
    // k=1: I = 0.1, u = 1 + 1 = 2 (at, not beyond, the limit → integrates).
    // k≥2: candidate I = 0.2 gives 3 > 2 with a positive push → frozen at 0.1, u = 2.
    let mut pid = Pid::new(PidGains::new(1.0, 10.0, 0.0), 0.1, Some(2.0));
    let out = run(&mut pid, &[1.0; 100]);
    assert!(out.iter().all(|&u| u == 2.0));
    assert!(close(pid.integral(), 0.1));
    // Error reverses: the integrator runs again at once (candidate 0.0 → u = −1).
    assert!(close(pid.update(-1.0), -1.0));
    assert!(close(pid.integral(), 0.0));

    // Without a limit the same run winds up to I = 10 and the reversal is ignored.
    let mut wound = Pid::new(PidGains::new(1.0, 10.0, 0.0), 0.1, None);
    run(&mut wound, &[1.0; 100]);
    assert!(close(wound.update(-1.0), -1.0 + 10.0 * 9.9));
}

#[test]
fn anti_windup_judges_the_output_with_its_feed_forward() {
    // Kp = 1, Ki = 10, Ts = 0.1, |u| ≤ 2, unit error and a feed-forward of 1.5 the limit
    // also bounds: k=1: candidate I = 0.1 gives 1 + 1 + 1.5 = 3.5 > 2 with a positive
    // push → frozen at 0, u = 2 (the sum clamped), 3.5 asked.
    let mut pid = Pid::new(PidGains::new(1.0, 10.0, 0.0), 0.1, Some(2.0));
    for _ in 0..100 {
        assert_eq!(pid.update_unclamped(1.0, true, 1.5), (2.0, 2.5));
    }
    assert_eq!(pid.integral(), 0.0);
    // Without the offset in the test the integral wound up under the clamped sum.
    let mut wound = Pid::new(PidGains::new(1.0, 10.0, 0.0), 0.1, Some(2.0));
    for _ in 0..100 {
        let u = wound.update(1.0);
        assert!((u + 1.5).min(2.0) == 2.0);
    }
    assert!(close(wound.integral(), 0.1));
}

#[test]
fn anti_windup_negative_side_and_clamped_output() {
    // Kp = 4, Ki = 1, Ts = 0.5, |u| ≤ 3, error −1:
    // k=1: candidate I = −0.5 → −4.5 < −3 with a negative push → frozen at 0, u = −3.
    let mut pid = Pid::new(PidGains::new(4.0, 1.0, 0.0), 0.5, Some(3.0));
    assert_eq!(pid.update(-1.0), -3.0);
    assert_eq!(pid.integral(), 0.0);
    // Small positive error integrates normally: I = 0.05, u = 0.4 + 0.05.
    assert!(close(pid.update(0.1), 0.45));
    // e = 1: candidate I = 0.55 → 4.55 > 3 with a positive push → frozen, u = 3.
    assert_eq!(pid.update(1.0), 3.0);
    assert!(close(pid.integral(), 0.05));
}

#[test]
fn integration_resumes_when_output_leaves_saturation() {
    // |u| ≤ 5, Ts = 1. Pre-charge I = −2 with Ki = 1 alone, then Kp = 10, Ki = 1.
    let mut pid = Pid::new(PidGains::new(0.0, 1.0, 0.0), 1.0, Some(5.0));
    assert_eq!(pid.update(-2.0), -2.0);
    pid.set_gains(PidGains::new(10.0, 1.0, 0.0));
    // e = −1: candidate I = −3, u = −10 − 3 = −13 < −5, push −1 < 0 → frozen at −2.
    assert_eq!(pid.update(-1.0), -5.0);
    assert_eq!(pid.integral(), -2.0);
    // e = 0.8: candidate I = −1.2, u = 8 − 1.2 = 6.8 > 5, push > 0 → frozen.
    assert_eq!(pid.update(0.8), 5.0);
    assert_eq!(pid.integral(), -2.0);
    // e = 0.6: candidate I = −1.4, u = 6 − 1.4 = 4.6 within limits → integrates.
    assert!(close(pid.update(0.6), 4.6));
    assert!(close(pid.integral(), -1.4));
}

#[test]
fn difference_and_reset() {
    let mut pid = Pid::new(PidGains::new(1.0, 1.0, 1.0), 0.1, None);
    assert_eq!(pid.difference(5.0), 0.0);
    pid.update(2.0);
    assert_eq!(pid.previous_error(), Some(2.0));
    assert_eq!(pid.difference(5.0), 3.0);
    pid.reset();
    assert_eq!(pid.previous_error(), None);
    assert_eq!(pid.integral(), 0.0);
    assert_eq!(pid.gains(), PidGains::new(1.0, 1.0, 1.0));
    let mut fresh = Pid::new(PidGains::new(1.0, 1.0, 1.0), 0.1, None);
    assert_eq!(pid.update(0.7), fresh.update(0.7));
}

#[test]
fn state_round_trips_through_serde() {
    let mut pid = Pid::new(PidGains::new(1.5, 30.0, 0.01), 0.001, Some(50.0));
    run(&mut pid, &[0.3, -0.2, 0.25]);
    let bytes = postcard::to_stdvec(&pid).unwrap();
    let mut from_bytes: Pid = postcard::from_bytes(&bytes).unwrap();
    let text = serde_json::to_string(&pid).unwrap();
    let mut from_json: Pid = serde_json::from_str(&text).unwrap();
    assert_eq!(from_bytes, pid);
    assert_eq!(from_json, pid);
    for e in [0.1, 0.4, -0.9] {
        let u = pid.update(e);
        assert_eq!(from_bytes.update(e), u);
        assert_eq!(from_json.update(e), u);
    }
}

#[test]
#[should_panic(expected = "sample period")]
fn zero_period_is_refused() {
    let _ = Pid::new(PidGains::p(1.0), 0.0, None);
}
