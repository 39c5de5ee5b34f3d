//! Bad values and calls checked one by one, beside the catalogue: non-finite values,
//! unknown references, wrong types, ranges, tunable parameters, step checks, panics and
//! failing steps.

use crate::common::plant_vr::{POS_X, U_X, U_Y, X_J};
use crate::common::*;
use contour_fmu::models::{fault_probe as probe, xy_servo_plant as plant};

#[test]
fn non_finite_values_are_refused_and_the_old_value_kept() {
    let i = Instance::new(&plant::INFO);
    i.start();
    assert_eq!(i.set_reals(&[U_X], &[3.0]), OK);
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert_eq!(i.set_reals(&[U_Y, U_X], &[1.0, bad]), ERROR);
        assert!(i.last_error().contains("non-finite"), "{}", i.last_error());
        // Atomic: neither value of the refused call was stored.
        assert_eq!(i.get_reals(&[U_X, U_Y]), (OK, vec![3.0, 0.0]));
    }
    // The instance carries on.
    assert_eq!(i.step(0.0, 0.01), OK);
}

#[test]
fn unknown_references_wrong_types_and_outputs_are_errors() {
    let i = Instance::new(&plant::INFO);
    i.start();
    let (s, _) = i.get_reals(&[POS_X, 999]);
    assert_eq!(s, ERROR);
    assert!(i.last_error().contains("unknown value reference 999"));
    assert_eq!(i.set_reals(&[1000], &[1.0]), ERROR);
    assert_eq!(i.get_integer(POS_X).0, ERROR);
    assert!(
        i.last_error()
            .contains("'pos.x' (value reference 2) is of type Real, not Integer"),
        "{}",
        i.last_error()
    );
    assert_eq!(i.set_boolean(U_X, true), ERROR);
    assert!(i.last_error().contains("is of type Real, not Boolean"));
    assert_eq!(i.set_reals(&[POS_X], &[1.0]), ERROR);
    assert!(i.last_error().contains("'pos.x' is an output"));
    // A fixed parameter after initialization.
    assert_eq!(i.set_reals(&[X_J], &[0.02]), ERROR);
    assert!(i.last_error().contains("parameter 'x.J' is fixed"));
    // NULL arrays with a non-zero length.
    let s = unsafe { lib().fmi2GetReal(i.c, std::ptr::null(), 1, std::ptr::null_mut()) };
    assert_eq!(s, ERROR);
    // Zero-length requests are fine.
    let s = unsafe { lib().fmi2GetReal(i.c, std::ptr::null(), 0, std::ptr::null_mut()) };
    assert_eq!(s, OK);
}

#[test]
fn parameters_are_range_checked() {
    let i = Instance::new(&plant::INFO);
    assert_eq!(i.setup(0.0, None), OK);
    assert_eq!(i.enter_init(), OK);
    assert_eq!(i.set_reals(&[X_J], &[-1.0]), ERROR);
    assert!(i.last_error().contains("'x.J' = -1 is below its minimum 0"));
    // Zero passes the bound but is unphysical: refused when initialization ends, and the
    // instance stays in initialization mode so the value can be corrected.
    assert_eq!(i.set_reals(&[X_J], &[0.0]), OK);
    assert_eq!(i.exit_init(), ERROR);
    assert!(
        i.last_error().contains("parameter 'x.J' must be > 0"),
        "{}",
        i.last_error()
    );
    assert_eq!(i.set_reals(&[X_J], &[0.015]), OK);
    assert_eq!(i.exit_init(), OK);
    assert_eq!(i.step(0.0, 0.01), OK);
}

#[test]
fn tunable_parameters_are_checked_by_the_model_and_restored_when_refused() {
    let i = Instance::new(&probe::INFO);
    i.start();
    let gain = probe::GAIN.vr() as u32;
    assert_eq!(i.set_reals(&[gain], &[5.0]), OK);
    assert_eq!(i.set_reals(&[gain], &[12.0]), ERROR);
    assert!(i.last_error().contains("'gain' must be < 10"));
    assert_eq!(i.get_real(gain), 5.0);
}

#[test]
fn do_step_checks_step_size_communication_point_and_stop_time() {
    let i = Instance::new(&plant::INFO);
    assert_eq!(i.setup(0.0, Some(0.05)), OK);
    assert_eq!(i.enter_init(), OK);
    assert_eq!(i.exit_init(), OK);
    for h in [0.0, -0.01, f64::NAN, f64::INFINITY] {
        assert_eq!(i.step(0.0, h), ERROR, "h = {h}");
    }
    assert_eq!(i.step(0.001, 0.01), ERROR);
    assert!(i
        .last_error()
        .contains("does not match the instance time 0"));
    // fmpy-style rounding: t = 0.01 computed as 0.009999999999999998.
    assert_eq!(i.step(0.0, 0.009999999999999998), OK);
    assert_eq!(i.step(0.01, 0.01), OK);
    // Past the stop time.
    assert_eq!(i.step(0.02, 0.04), ERROR);
    assert!(i.last_error().contains("would pass the stop time 0.05"));
    // Exactly to the stop time, with rounding.
    assert_eq!(i.step(0.02, 0.030000000000000002), OK);
    // Refused calls did not change the mode.
    assert_eq!(i.terminate(), OK);
}

#[test]
fn a_panic_in_a_model_becomes_fatal_and_the_instance_refuses_further_work() {
    let mut i = Instance::new(&probe::INFO);
    i.start();
    assert_eq!(i.step(0.0, 0.1), OK);
    assert_eq!(i.set_boolean(probe::PANIC.vr() as u32, true), OK);
    assert_eq!(i.step(0.1, 0.1), FATAL);
    let fatal = i.messages(FATAL);
    assert_eq!(fatal.len(), 1);
    assert!(fatal[0].contains("fmi2DoStep: internal error (panic): FaultProbe: injected panic"));
    assert_eq!(i.get_integer(probe::STEPS.vr() as u32).0, ERROR);
    assert_eq!(i.reset(), ERROR);
    // Other instances are unaffected.
    let other = Instance::new(&probe::INFO);
    other.start();
    assert_eq!(other.step(0.0, 0.1), OK);
    i.free();
}

#[test]
fn a_failing_step_moves_to_error_and_a_saved_state_recovers() {
    let i = Instance::new(&probe::INFO);
    i.start();
    assert_eq!(i.step(0.0, 0.1), OK);
    let (s, mut state) = i.get_state();
    assert_eq!(s, OK);
    assert_eq!(i.set_boolean(probe::FAIL.vr() as u32, true), OK);
    assert_eq!(i.step(0.1, 0.1), ERROR);
    assert!(i.last_error().contains("FaultProbe: injected failure"));
    assert_eq!(i.step(0.1, 0.1), ERROR);
    assert!(i
        .last_error()
        .contains("illegal call sequence (state Error)"));
    assert_eq!(i.set_state(state), OK);
    assert_eq!(i.get_boolean(probe::FAIL.vr() as u32), (OK, false));
    assert_eq!(i.step(0.1, 0.1), OK);
    assert_eq!(i.get_integer(probe::STEPS.vr() as u32), (OK, 2));
    assert_eq!(i.free_state(&mut state), OK);
    assert!(state.is_null());
}

#[test]
fn strings_stay_valid_until_the_next_call() {
    let i = Instance::new(&probe::INFO);
    assert_eq!(i.setup(0.0, None), OK);
    assert_eq!(i.enter_init(), OK);
    assert_eq!(i.set_string(probe::LABEL.vr() as u32, "spindle ✓"), OK);
    let (s, ptr, text) = i.get_string(probe::ECHO.vr() as u32);
    assert_eq!((s, text.as_str()), (OK, "spindle ✓"));
    // Still readable after the caller's own work, before the next call.
    let again = unsafe { std::ffi::CStr::from_ptr(ptr) }
        .to_str()
        .unwrap()
        .to_owned();
    assert_eq!(again, "spindle ✓");
    assert_eq!(i.exit_init(), OK);
}
