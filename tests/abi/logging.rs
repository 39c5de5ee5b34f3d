//! Logging: categories honoured, errors always logged, a logger that calls back into the
//! instance, messages passed through a `%s` format.

use crate::common::plant_vr::POS_X;
use crate::common::*;
use contour_fmu::models::xy_servo_plant as plant;

#[test]
fn logging_categories_are_honoured_and_errors_always_logged() {
    let i = Instance::new(&plant::INFO);
    // Logging was off at instantiation: no event messages.
    assert!(i.records().is_empty());
    i.start();
    assert!(i.records().is_empty());
    // An error is logged even so.
    assert_eq!(i.step(0.0, -1.0), ERROR);
    let records = i.records();
    assert_eq!(records.len(), 1);
    assert_eq!(records[0].category, "logStatusError");
    assert!(records[0]
        .message
        .starts_with("fmi2DoStep: communication step size must be finite and > 0"));
    assert_eq!(records[0].instance, "test");
    i.clear_log();

    // Events only.
    assert_eq!(i.set_debug_logging(true, &["logEvents"]), OK);
    assert_eq!(i.terminate(), OK);
    let records = i.records();
    assert_eq!(records.len(), 1, "{records:?}");
    assert_eq!(records[0].category, "logEvents");
    assert!(records[0].message.starts_with("terminated at t = 0"));
    i.clear_log();

    // logAll traces every call.
    assert_eq!(i.set_debug_logging(true, &["logAll"]), OK);
    i.clear_log();
    let _ = i.get_real(POS_X);
    assert!(i
        .records()
        .iter()
        .any(|r| r.message == "fmi2GetReal called"));

    // Off for everything: only errors remain.
    assert_eq!(i.set_debug_logging(false, &[]), OK);
    i.clear_log();
    assert_eq!(i.reset(), OK);
    assert!(i.records().is_empty());

    // Unknown category: refused, nothing changed.
    assert_eq!(
        i.set_debug_logging(true, &["logEvents", "logNonsense"]),
        ERROR
    );
    assert!(i
        .last_error()
        .contains("unknown log category 'logNonsense'"));
    i.clear_log();
    assert_eq!(i.setup(0.0, None), OK);
    assert!(i.records().is_empty(), "logEvents must still be off");
}

#[test]
fn a_logger_may_call_back_into_the_instance() {
    let i = Instance::new(&plant::INFO);
    i.start();
    i.log
        .reenter
        .store(i.c, std::sync::atomic::Ordering::SeqCst);
    // The error is logged while the call is in progress; the logger's own call must get
    // through instead of deadlocking on the instance.
    let c = i.c as usize;
    let (sender, receiver) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let status = unsafe { lib().fmi2DoStep(c as fmi2Component, 0.0, -1.0, 1) };
        sender.send(status).unwrap();
    });
    let status = receiver
        .recv_timeout(std::time::Duration::from_secs(10))
        .expect("fmi2DoStep deadlocked in its logger callback");
    assert_eq!(status, ERROR);
    let records = i.records();
    assert!(
        records
            .iter()
            .any(|r| r.category == "reentered" && r.message.ends_with("returned 0")),
        "{records:?}"
    );
}

#[test]
fn debug_logging_with_categories_logs_only_those() {
    let (c, log, _cb) = instantiate_raw(
        Some("cat"),
        fmi2Type_fmi2CoSimulation,
        Some(&plant::INFO.guid()),
        None,
        true,
    );
    let only = cstr("logStatusWarning");
    let p = only.as_ptr();
    assert_eq!(unsafe { lib().fmi2SetDebugLogging(c, 1, 1, &p) }, OK);
    log.records.lock().unwrap().clear();
    unsafe {
        assert_eq!(lib().fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), OK);
        assert_eq!(lib().fmi2EnterInitializationMode(c), OK);
        assert_eq!(lib().fmi2ExitInitializationMode(c), OK);
    }
    // Neither call traces (logAll) nor events (logEvents): only warnings were asked for.
    assert!(
        log.records.lock().unwrap().is_empty(),
        "{:?}",
        log.records.lock().unwrap()
    );
    unsafe { lib().fmi2FreeInstance(c) };
}

#[test]
fn messages_are_always_passed_through_a_percent_s_format() {
    let (c, log, _cb) = instantiate_raw(
        Some("%s%n%x"),
        fmi2Type_fmi2CoSimulation,
        Some(&plant::INFO.guid()),
        None,
        true,
    );
    assert!(!c.is_null());
    let nasty = cstr("%s%n%p%s");
    let p = nasty.as_ptr();
    let status = unsafe { lib().fmi2SetDebugLogging(c, 1, 1, &p) };
    assert_eq!(status, ERROR);
    let records = log.records.lock().unwrap().clone();
    assert!(!records.is_empty());
    for r in &records {
        assert_eq!(r.format, "%s");
        assert_eq!(r.instance, "%s%n%x");
    }
    assert!(records
        .iter()
        .any(|r| r.message.contains("unknown log category '%s%n%p%s'")));
    unsafe { lib().fmi2FreeInstance(c) };
}
