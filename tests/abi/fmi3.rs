//! FMI 3.0 Co-Simulation from the same library: every model and unit system computes
//! through the fmi3 functions exactly what it computes through the fmi2 ones, states
//! travel between FMI 3.0 instances, a handle of one standard is refused by the other's
//! functions, and FMI 3.0's own misuse (a Boolean byte that is not 0 or 1, values and
//! references of different counts, the independent variable set, an FMI 2.0 GUID as the
//! token) gets an error status and a message.

use std::ffi::CString;

use crate::common::fmi3::*;
use crate::common::{instantiate_raw, lib, Log, ERROR, OK};
use contour_fmu::framework::interface::{Interface, UnitSystem};
use contour_fmu::framework::variables::{Causality, VarType};
use contour_fmu::models;
use fmi2_bindings::{fmi2CallbackFunctions, fmi2Component, fmi2Type_fmi2CoSimulation};

fn vrs_of(interface: &Interface, causality: Causality) -> Vec<u32> {
    interface
        .variables
        .iter()
        .filter(|v| v.causality == causality && v.var_type() == VarType::Real)
        .map(|v| v.vr as u32)
        .collect()
}

/// An FMI 2.0 instance of any interface (mm or SI) with its log and callbacks, which must
/// outlive it; freed on drop.
struct Fmi2 {
    c: fmi2Component,
    _log: Box<Log>,
    _callbacks: Box<fmi2CallbackFunctions>,
}

impl Drop for Fmi2 {
    fn drop(&mut self) {
        unsafe { lib().fmi2FreeInstance(self.c) };
    }
}

fn fmi2_instance(interface: &Interface) -> Fmi2 {
    let (c, log, callbacks) = instantiate_raw(
        Some("fmi2"),
        fmi2Type_fmi2CoSimulation,
        Some(&interface.guid),
        None,
        false,
    );
    assert!(!c.is_null(), "{:?}", log.records.lock().unwrap());
    Fmi2 {
        c,
        _log: log,
        _callbacks: callbacks,
    }
}

/// Inputs that move: a different smooth signal on every input at every step.
fn inputs(k: usize, n: usize) -> Vec<f64> {
    (0..n)
        .map(|j| 0.5 * contour_core::math::sin(0.01 * k as f64 * (j + 1) as f64))
        .collect()
}

#[test]
fn every_model_computes_through_fmi3_what_it_computes_through_fmi2_bit_for_bit() {
    let lib2 = lib();
    for interface in models::interfaces() {
        let label = format!(
            "{} ({})",
            interface.model.identifier,
            interface.units.name()
        );
        let (ins, outs) = (
            vrs_of(interface, Causality::Input),
            vrs_of(interface, Causality::Output),
        );
        let h = interface.model.default_experiment.step_size;
        let fmi2 = fmi2_instance(interface);
        let c2 = fmi2.c;
        let i3 = Instance3::new(interface);
        unsafe {
            assert_eq!(lib2.fmi2SetupExperiment(c2, 0, 0.0, 0.0, 0, 0.0), OK);
            assert_eq!(lib2.fmi2EnterInitializationMode(c2), OK);
            assert_eq!(lib2.fmi2ExitInitializationMode(c2), OK, "{label}");
        }
        i3.start();
        for k in 0..300 {
            let t = k as f64 * h;
            let u = inputs(k, ins.len());
            let mut y2 = vec![0.0; outs.len()];
            unsafe {
                assert_eq!(
                    lib2.fmi2SetReal(c2, ins.as_ptr(), ins.len(), u.as_ptr()),
                    OK
                );
                assert_eq!(lib2.fmi2DoStep(c2, t, h, 1), OK, "{label} step {k}");
                assert_eq!(
                    lib2.fmi2GetReal(c2, outs.as_ptr(), outs.len(), y2.as_mut_ptr()),
                    OK
                );
            }
            assert_eq!(
                i3.set_float64(&ins, &u),
                OK3,
                "{label}: {:?}",
                i3.messages()
            );
            let (status, last) = i3.step(t, h);
            assert_eq!(status, OK3, "{label} step {k}: {}", i3.last_error());
            assert_eq!(last, t + h, "{label}: lastSuccessfulTime");
            let (status, y3) = i3.get_float64(&outs);
            assert_eq!(status, OK3);
            let bits = |y: &[f64]| y.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&y3), bits(&y2), "{label} step {k}");
        }
        // The independent variable reads the instance's time.
        let (status, time) = i3.get_float64(&[interface.time_vr()]);
        assert_eq!((status, time[0]), (OK3, 300.0 * h), "{label}");
    }
}

#[test]
fn a_state_serialized_by_an_fmi3_instance_continues_in_a_fresh_one() {
    let interface = models::interface(&models::contour_ccc_2d::INFO, UnitSystem::Millimetre);
    let ins = vrs_of(interface, Causality::Input);
    let outs = vrs_of(interface, Causality::Output);
    let h = interface.model.default_experiment.step_size;
    let run = |i: &Instance3, from: usize, to: usize| -> Vec<Vec<u64>> {
        (from..to)
            .map(|k| {
                assert_eq!(i.set_float64(&ins, &inputs(k, ins.len())), OK3);
                assert_eq!(i.step(k as f64 * h, h).0, OK3, "{}", i.last_error());
                i.get_float64(&outs).1.iter().map(|x| x.to_bits()).collect()
            })
            .collect()
    };
    let first = Instance3::new(interface);
    first.start();
    run(&first, 0, 150);
    let saved = first.serialize();
    let expected = run(&first, 150, 300);
    let fresh = Instance3::new(interface);
    assert_eq!(fresh.restore(&saved), OK3, "{:?}", fresh.messages());
    assert_eq!(run(&fresh, 150, 300), expected);
}

#[test]
fn a_handle_of_one_standard_is_refused_by_the_other_standards_functions() {
    let interface = models::interface(&models::xy_servo_plant::INFO, UnitSystem::Millimetre);
    let lib2 = lib();
    let i3 = Instance3::new(interface);
    i3.start();
    let c3 = i3.c as fmi2Component;
    unsafe {
        assert_eq!(lib2.fmi2DoStep(c3, 0.0, 0.001, 1), ERROR);
        // fmi2FreeInstance leaves an FMI 3.0 instance alive.
        lib2.fmi2FreeInstance(c3);
    }
    let refusal = "fmi2DoStep: called with an instance made by fmi3InstantiateCoSimulation: \
                   an FMI 3.0 instance answers only the fmi3 functions";
    assert!(
        i3.messages().iter().any(|m| m == refusal),
        "{:?}",
        i3.messages()
    );
    assert_eq!(i3.step(0.0, 0.001).0, OK3, "{}", i3.last_error());

    let fmi2 = fmi2_instance(interface);
    let c2 = fmi2.c;
    unsafe {
        assert_eq!(lib2.fmi2SetupExperiment(c2, 0, 0.0, 0.0, 0, 0.0), OK);
        assert_eq!(lib2.fmi2EnterInitializationMode(c2), OK);
        assert_eq!(lib2.fmi2ExitInitializationMode(c2), OK);
        let (mut a, mut b, mut e, mut last) = (false, false, false, 0.0);
        let status = lib3().fmi3DoStep(
            c2 as fmi3Instance,
            0.0,
            0.001,
            false,
            &mut a,
            &mut b,
            &mut e,
            &mut last,
        );
        assert_eq!(status, ERROR3);
        lib3().fmi3FreeInstance(c2 as fmi3Instance);
        // Still alive for its own standard.
        assert_eq!(lib2.fmi2DoStep(c2, 0.0, 0.001, 1), OK);
    }
}

#[test]
fn fmi3_misuse_gets_an_error_and_a_message() {
    let interface = models::interface(&models::contour_ccc_2d::INFO, UnitSystem::Millimetre);
    let lib = lib3();
    let i = Instance3::new(interface);
    assert_eq!(i.enter_init(0.0, Some(1.0)), OK3);
    let real = vrs_of(interface, Causality::Input)[0];
    let estimator = interface
        .variables
        .iter()
        .find(|v| v.name == "estimator")
        .expect("ContourCCC2D's estimator enumeration")
        .vr as u32;
    let boolean = interface
        .variables
        .iter()
        .find(|v| v.var_type() == VarType::Boolean)
        .expect("a Boolean variable")
        .vr as u32;
    unsafe {
        // A C bool byte other than 0 or 1.
        let byte = 2u8;
        let status = lib.fmi3SetBoolean(i.c, &boolean, 1, &byte as *const u8 as *const bool, 1);
        assert_eq!(status, ERROR3);
        assert!(
            i.last_error().contains("fmi3Boolean is a C bool, 0 or 1"),
            "{}",
            i.last_error()
        );
        // Values and references of different counts.
        let values = [1.0, 2.0];
        assert_eq!(
            lib.fmi3SetFloat64(i.c, &real, 1, values.as_ptr(), 2),
            ERROR3
        );
        assert!(i
            .last_error()
            .contains("nValues = 2 but nValueReferences = 1"));
        // The independent variable cannot be set.
        let time_vr = interface.time_vr();
        assert_eq!(
            lib.fmi3SetFloat64(i.c, &time_vr, 1, values.as_ptr(), 1),
            ERROR3
        );
        assert!(i.last_error().contains("'time'"), "{}", i.last_error());
        // An enumeration is an Int64, not an Int32; Float32 exists nowhere here.
        let mut v32 = 0i32;
        assert_eq!(lib.fmi3GetInt32(i.c, &estimator, 1, &mut v32, 1), ERROR3);
        assert!(
            i.last_error()
                .contains("is of type Enumeration (Int64), not Int32"),
            "{}",
            i.last_error()
        );
        let mut v64 = 0i64;
        assert_eq!(lib.fmi3GetInt64(i.c, &estimator, 1, &mut v64, 1), OK3);
        assert_eq!(v64, 1, "the free-curve estimator is item 1");
        let mut f32v = 0f32;
        assert_eq!(lib.fmi3GetFloat32(i.c, &real, 1, &mut f32v, 1), ERROR3);
        assert!(
            i.last_error().contains("is of type Float64, not Float32"),
            "{}",
            i.last_error()
        );
        // The counts are checked for the types no variable has too.
        assert_eq!(
            lib.fmi3GetFloat32(i.c, std::ptr::null(), 0, &mut f32v, 1),
            ERROR3
        );
        assert!(i
            .last_error()
            .contains("nValues = 1 but nValueReferences = 0"));
        let unknown = 100_000u32;
        assert_eq!(lib.fmi3GetFloat32(i.c, &unknown, 1, &mut f32v, 1), ERROR3);
        assert!(i.last_error().contains("unknown value reference 100000"));
        // No event mode, no Model Exchange.
        assert_eq!(lib.fmi3EnterEventMode(i.c), ERROR3);
        assert!(
            i.last_error().contains("no event mode"),
            "{}",
            i.last_error()
        );
        assert_eq!(i.exit_init(), OK3);
        let (mut a, mut b, mut e) = (false, false, false);
        let status = lib.fmi3DoStep(
            i.c,
            0.0,
            0.001,
            false,
            &mut a,
            &mut b,
            &mut e,
            std::ptr::null_mut(),
        );
        assert_eq!(status, ERROR3);
        assert!(
            i.last_error().contains("lastSuccessfulTime is NULL"),
            "{}",
            i.last_error()
        );
    }
    // An FMI 2.0 GUID is not an instantiation token; the message says which is which.
    let wrong = instantiate3_raw("wrong", &interface.guid, None);
    assert!(wrong.c.is_null());
    assert!(
        wrong
            .messages()
            .iter()
            .any(|m| m.contains("it is an FMI 2.0 GUID")),
        "{:?}",
        wrong.messages()
    );
    let name = CString::new("me").unwrap();
    let token = CString::new(interface.instantiation_token.as_str()).unwrap();
    let me = unsafe {
        lib.fmi3InstantiateModelExchange(
            name.as_ptr(),
            token.as_ptr(),
            std::ptr::null(),
            false,
            false,
            std::ptr::null_mut(),
            None,
        )
    };
    assert!(me.is_null());
}
