//! fmi2Instantiate: the GUID, the type, the callbacks and the name it refuses, and the
//! resource locations it accepts.

use crate::common::*;
use contour_fmu::models::xy_servo_plant as plant;

#[test]
fn instantiate_refuses_wrong_guid_type_callbacks_and_name() {
    let guid = plant::INFO.guid();
    let (c, log, _cb) = instantiate_raw(
        Some("a"),
        fmi2Type_fmi2CoSimulation,
        Some("{00000000-0000-0000-0000-000000000000}"),
        None,
        false,
    );
    assert!(c.is_null());
    let messages = log.records.lock().unwrap().clone();
    assert!(
        messages
            .iter()
            .any(|r| r.status == ERROR && r.message.contains("unknown GUID")),
        "{messages:?}"
    );

    let (c, log, _cb) = instantiate_raw(
        Some("a"),
        fmi2Type_fmi2ModelExchange,
        Some(&guid),
        None,
        false,
    );
    assert!(c.is_null());
    assert!(log.records.lock().unwrap()[0]
        .message
        .contains("Co-Simulation only"));

    let (c, _log, _cb) = instantiate_raw(Some("a"), fmi2Type_fmi2CoSimulation, None, None, false);
    assert!(c.is_null());
    let (c, _log, _cb) = instantiate_raw(
        Some(" "),
        fmi2Type_fmi2CoSimulation,
        Some(&guid),
        None,
        false,
    );
    assert!(c.is_null());
    let (c, _log, _cb) = instantiate_raw(None, fmi2Type_fmi2CoSimulation, Some(&guid), None, false);
    assert!(c.is_null());

    // NULL callbacks, and callbacks without a logger: refused without a crash.
    let name = cstr("a");
    let guid_c = cstr(&guid);
    let c = unsafe {
        lib().fmi2Instantiate(
            name.as_ptr(),
            fmi2Type_fmi2CoSimulation,
            guid_c.as_ptr(),
            std::ptr::null(),
            std::ptr::null(),
            0,
            0,
        )
    };
    assert!(c.is_null());
    let log = Log::default();
    let mut callbacks = callbacks(&log);
    callbacks.logger = None;
    let c = unsafe {
        lib().fmi2Instantiate(
            name.as_ptr(),
            fmi2Type_fmi2CoSimulation,
            guid_c.as_ptr(),
            std::ptr::null(),
            &*callbacks,
            0,
            0,
        )
    };
    assert!(c.is_null());
}

#[test]
fn resource_locations_in_every_common_form_are_accepted() {
    let guid = plant::INFO.guid();
    let forms = [
        Some("file:///tmp/some%20dir/resources"),
        Some("file:///tmp/some%20dir/resources/"),
        Some("file:/tmp/some%20dir/resources"),
        Some("file://localhost/tmp/resources/"),
        None,
    ];
    for form in forms {
        let (c, log, _cb) = instantiate_raw(
            Some("r"),
            fmi2Type_fmi2CoSimulation,
            Some(&guid),
            form,
            true,
        );
        assert!(!c.is_null(), "{form:?}");
        let records = log.records.lock().unwrap().clone();
        assert!(
            records.iter().all(|r| r.status == OK),
            "{form:?}: {records:?}"
        );
        unsafe { lib().fmi2FreeInstance(c) };
    }
    // Not a local folder: the instance still works, with a warning.
    let (c, log, _cb) = instantiate_raw(
        Some("r"),
        fmi2Type_fmi2CoSimulation,
        Some(&guid),
        Some("http://host/r"),
        true,
    );
    assert!(!c.is_null());
    assert!(log
        .records
        .lock()
        .unwrap()
        .iter()
        .any(|r| r.status == WARNING && r.message.contains("not a file: URI")));
    unsafe { lib().fmi2FreeInstance(c) };
}
