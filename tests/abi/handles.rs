//! Handles from the importer are looked up before they are used: a freed, foreign or
//! wrong `fmi2Component` or `fmi2FMUstate` gets `fmi2Error` (and a log line when there
//! is an instance to log to), never a read of freed or foreign memory. Includes fmusim
//! 0.0.39's `fmi2FreeFMUstate(c, state)` and freeing stored states after a fatal error.
//!
//! Needs the `test-hooks` feature (the `FaultProbe` model, for the fatal state).

use crate::common::*;
use contour_fmu::models::{fault_probe as probe, xy_servo_plant as plant};

const POS_X: u32 = plant::POS.at(0).vr() as u32;
const U_X: u32 = plant::U.at(0).vr() as u32;

/// A block of memory that is not an instance or a state of ours, filled with a pattern
/// that would look plausible to a careless check (the library's old "live" tag).
fn foreign_block() -> Box<[u64; 16]> {
    Box::new([0x4343_4346_4d55_3201; 16])
}

fn running_plant(name: &str) -> Instance {
    let i = Instance::named(&plant::INFO, name);
    i.start();
    assert_eq!(i.set_reals(&[U_X], &[10.0]), OK);
    assert_eq!(i.step(0.0, 0.01), OK);
    i
}

/// Every instance function on `c`, which is not a live instance: all answer fmi2Error.
fn every_call_is_refused(c: fmi2Component) {
    let lib = lib();
    let (vr, mut real, mut int, mut boolean) = (0u32, 0.0, 0, 0);
    let mut text: fmi2String = std::ptr::null();
    let mut state: fmi2FMUstate = std::ptr::null_mut();
    let mut size = 0usize;
    let mut status = 0;
    unsafe {
        let statuses = [
            lib.fmi2SetDebugLogging(c, 1, 0, std::ptr::null()),
            lib.fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0),
            lib.fmi2EnterInitializationMode(c),
            lib.fmi2ExitInitializationMode(c),
            lib.fmi2Terminate(c),
            lib.fmi2Reset(c),
            lib.fmi2GetReal(c, &vr, 1, &mut real),
            lib.fmi2GetInteger(c, &vr, 1, &mut int),
            lib.fmi2GetBoolean(c, &vr, 1, &mut boolean),
            lib.fmi2GetString(c, &vr, 1, &mut text),
            lib.fmi2SetReal(c, &vr, 1, &real),
            lib.fmi2SetInteger(c, &vr, 1, &int),
            lib.fmi2SetBoolean(c, &vr, 1, &boolean),
            lib.fmi2GetFMUstate(c, &mut state),
            lib.fmi2SetFMUstate(c, state),
            lib.fmi2FreeFMUstate(c, &mut state),
            lib.fmi2SerializedFMUstateSize(c, state, &mut size),
            lib.fmi2DoStep(c, 0.0, 0.01, 1),
            lib.fmi2CancelStep(c),
            lib.fmi2GetStatus(c, fmi2StatusKind_fmi2DoStepStatus, &mut status),
            lib.fmi2GetRealStatus(c, fmi2StatusKind_fmi2LastSuccessfulTime, &mut real),
            lib.fmi2GetBooleanStatus(c, fmi2StatusKind_fmi2Terminated, &mut boolean),
        ];
        assert!(statuses.iter().all(|&s| s == ERROR), "{statuses:?}");
        // Nothing was written through the output arguments.
        assert_eq!((real, int, boolean, size), (0.0, 0, 0, 0));
        assert!(text.is_null() && state.is_null());
        // fmi2FreeInstance has no status: it must simply not touch `c`.
        lib.fmi2FreeInstance(c);
    }
}

#[test]
fn a_freed_instance_pointer_is_refused_without_being_read() {
    let mut i = running_plant("freed");
    let c = i.c;
    i.free();
    every_call_is_refused(c);
    // A second fmi2FreeInstance on it is harmless, and other instances carry on.
    unsafe { lib().fmi2FreeInstance(c) };
    let other = running_plant("other");
    assert!(other.get_real(POS_X) > 0.0);
}

#[test]
fn null_and_foreign_instance_pointers_are_refused_and_left_untouched() {
    every_call_is_refused(std::ptr::null_mut());
    let mut block = foreign_block();
    let before = *block;
    every_call_is_refused(block.as_mut_ptr() as fmi2Component);
    assert_eq!(*block, before);
    // A value near a live handle is not an instance either (far enough from it that no
    // instance of a test running in parallel can have it).
    let i = running_plant("inside");
    every_call_is_refused((i.c as usize).wrapping_add(1 << 40) as fmi2Component);
    assert!(i.get_real(POS_X) > 0.0);
}

#[test]
fn a_state_of_another_instance_is_refused_and_stays_usable_there() {
    let a = running_plant("a");
    let b = running_plant("b");
    let (s, mut state) = a.get_state();
    assert_eq!(s, OK);
    let before_b = b.get_real(POS_X);

    assert_eq!(b.set_state(state), ERROR);
    let message = b.last_error();
    assert!(
        message.starts_with("fmi2SetFMUstate: FMUstate 0x")
            && message.contains("belongs to instance 'a', not to this one"),
        "{message}"
    );
    assert_eq!(b.state_size(state).0, ERROR);
    assert!(b.last_error().starts_with("fmi2SerializedFMUstateSize: "));
    let mut buffer = [0 as fmi2Byte; 8];
    assert_eq!(
        unsafe { lib().fmi2SerializeFMUstate(b.c, state, buffer.as_mut_ptr(), 8) },
        ERROR
    );
    // b cannot free a's state, nor overwrite it.
    let mut copy = state;
    assert_eq!(b.free_state(&mut copy), ERROR);
    assert_eq!(copy, state, "the variable is left as it was");
    assert_eq!(unsafe { lib().fmi2GetFMUstate(b.c, &mut copy) }, ERROR);
    // ... nor free it through fmusim's misuse.
    assert_eq!(b.free_state_raw(state as *mut fmi2FMUstate), ERROR);
    assert_eq!(b.get_real(POS_X), before_b);

    // a still has it, untouched.
    assert_eq!(a.step(0.01, 0.01), OK);
    assert_eq!(a.set_state(state), OK);
    assert_eq!(a.free_state(&mut state), OK);
    assert!(state.is_null());
}

#[test]
fn freed_and_made_up_state_handles_are_refused() {
    let i = running_plant("states");
    let (_, mut state) = i.get_state();
    let stale = state;
    assert_eq!(i.free_state(&mut state), OK);
    assert!(state.is_null());
    // The variable holds NULL now: freeing again is the standard's no-op.
    assert_eq!(i.free_state(&mut state), OK);
    // A stale copy of the handle.
    assert_eq!(i.set_state(stale), ERROR);
    assert!(
        i.last_error()
            .contains("is not a live FMU state of this instance"),
        "{}",
        i.last_error()
    );
    let mut copy = stale;
    assert_eq!(i.free_state(&mut copy), ERROR);
    assert_eq!(i.state_size(stale).0, ERROR);
    // Overwriting a stale state with fmi2GetFMUstate.
    assert_eq!(unsafe { lib().fmi2GetFMUstate(i.c, &mut copy) }, ERROR);
    assert_eq!(copy, stale);

    // A made-up handle (memory that is not ours) is never read or written.
    let mut block = foreign_block();
    let before = *block;
    let fake = block.as_mut_ptr() as fmi2FMUstate;
    assert_eq!(i.set_state(fake), ERROR);
    assert_eq!(i.state_size(fake).0, ERROR);
    let mut fake_copy = fake;
    assert_eq!(i.free_state(&mut fake_copy), ERROR);
    assert_eq!(i.free_state_raw(fake as *mut fmi2FMUstate), ERROR);
    assert_eq!(*block, before);
    // NULL.
    assert_eq!(i.set_state(std::ptr::null_mut()), ERROR);
    assert_eq!(i.last_error(), "fmi2SetFMUstate: FMUstate is NULL");
    assert_eq!(
        i.free_state_raw(std::ptr::null_mut()),
        OK,
        "ignored, as FMI 2.0 says"
    );

    // The instance was not disturbed by any of it.
    assert_eq!(i.step(0.01, 0.01), OK);
}

/// The allocator reuses freed memory at once; handles must not follow it. A freed state
/// handle stays refused after new states are made (which used to land at the freed
/// address and be accepted through the stale handle), and a freed instance handle after
/// new instances are made.
#[test]
fn freed_handles_stay_refused_after_new_ones_are_made() {
    let i = running_plant("reuse");
    let (_, mut state) = i.get_state();
    let stale = state;
    assert_eq!(i.free_state(&mut state), OK);
    let fresh: Vec<fmi2FMUstate> = (0..16).map(|_| i.get_state().1).collect();
    assert!(fresh.iter().all(|&s| s != stale));
    assert_eq!(i.set_state(stale), ERROR);
    assert_eq!(i.state_size(stale).0, ERROR);
    for s in fresh {
        assert_eq!(i.set_state(s), OK);
        let mut s = s;
        assert_eq!(i.free_state(&mut s), OK);
    }

    let mut gone = running_plant("gone");
    let stale_instance = gone.c;
    gone.free();
    let others: Vec<Instance> = (0..16).map(|_| running_plant("new")).collect();
    assert!(others.iter().all(|o| o.c != stale_instance));
    every_call_is_refused(stale_instance);
    assert!(others.iter().all(|o| o.get_real(POS_X) > 0.0));
}

/// fmusim 0.0.39 calls `fmi2FreeFMUstate(c, FMUState)`: the state where the address of the
/// variable holding it belongs. It used to crash the host (SIGSEGV); now the state is
/// freed, with a warning, and the call answers fmi2OK so that fmusim carries on.
#[test]
fn fmusims_free_with_the_state_instead_of_its_address_frees_it_safely() {
    let i = running_plant("fmusim");
    assert_eq!(i.set_debug_logging(true, &["logStatusWarning"]), OK);
    let (_, state) = i.get_state();
    let (_, other) = i.get_state();
    assert_ne!(state, other);

    assert_eq!(i.free_state_raw(state as *mut fmi2FMUstate), OK);
    let warnings = i.messages(WARNING);
    assert_eq!(warnings.len(), 1, "{:?}", i.records());
    assert!(
        warnings[0].starts_with("fmi2FreeFMUstate: the argument is the FMU state 0x")
            && warnings[0].contains("itself, not the address of a variable holding it"),
        "{}",
        warnings[0]
    );
    // Freed: every later use of the stale handle is refused.
    assert_eq!(i.set_state(state), ERROR);
    assert_eq!(i.state_size(state).0, ERROR);
    assert_eq!(i.free_state_raw(state as *mut fmi2FMUstate), ERROR);
    // The other state is unaffected.
    assert_eq!(i.set_state(other), OK);
    // The same confusion in fmi2GetFMUstate and fmi2DeSerializeFMUstate is refused
    // before anything is written through the "address".
    assert_eq!(
        unsafe { lib().fmi2GetFMUstate(i.c, other as *mut fmi2FMUstate) },
        ERROR
    );
    assert!(i
        .last_error()
        .contains("is an FMU state, not the address of a variable holding one"));
    let (_, bytes) = i.serialize(other);
    let s = unsafe {
        lib().fmi2DeSerializeFMUstate(
            i.c,
            bytes.as_ptr() as *const fmi2Byte,
            bytes.len(),
            other as *mut fmi2FMUstate,
        )
    };
    assert_eq!(s, ERROR);
    assert_eq!(i.state_size(other), (OK, bytes.len()));
    assert_eq!(i.free_state_raw(other as *mut fmi2FMUstate), OK);
}

#[test]
fn stored_states_can_be_freed_after_a_fatal_error() {
    let mut i = Instance::new(&probe::INFO);
    i.start();
    let (_, mut first) = i.get_state();
    let (_, second) = i.get_state();
    assert_eq!(i.set_boolean(probe::PANIC.vr() as u32, true), OK);
    assert_eq!(i.step(0.0, 0.1), FATAL);
    // Nothing but freeing is allowed now ...
    assert_eq!(i.set_state(first), ERROR);
    assert!(i
        .last_error()
        .contains("illegal call sequence (state Fatal)"));
    assert_eq!(i.get_state().0, ERROR);
    // ... and freeing works, also through fmusim's misuse.
    assert_eq!(i.free_state(&mut first), OK);
    assert!(first.is_null());
    assert_eq!(i.free_state_raw(second as *mut fmi2FMUstate), OK);
    i.free();
}

/// Instances created, stepped and freed on many threads at once while another thread
/// keeps calling with freed pointers: the registry keeps every answer straight.
#[test]
fn the_registry_is_thread_safe() {
    let freed: Vec<usize> = (0..4)
        .map(|_| {
            let mut i = running_plant("gone");
            let c = i.c as usize;
            i.free();
            c
        })
        .collect();
    let stop = std::sync::atomic::AtomicBool::new(false);
    let positions: Vec<f64> = std::thread::scope(|scope| {
        let prober = scope.spawn(|| {
            let mut refused = 0u64;
            // At least one round: on a loaded machine the workers may all finish before
            // this thread is first scheduled.
            loop {
                for &c in &freed {
                    let mut v = 0.0;
                    let s = unsafe { lib().fmi2GetReal(c as fmi2Component, &0, 1, &mut v) };
                    // Handles are never reused: a freed one stays refused while new
                    // instances come and go.
                    assert_eq!(s, ERROR);
                    refused += 1;
                }
                if stop.load(std::sync::atomic::Ordering::Relaxed) {
                    break;
                }
            }
            refused
        });
        let workers: Vec<_> = (0..6)
            .map(|_| {
                scope.spawn(|| {
                    let mut last = 0.0;
                    for _ in 0..40 {
                        let i = running_plant("worker");
                        let (_, mut st) = i.get_state();
                        assert_eq!(i.step(0.01, 0.01), OK);
                        assert_eq!(i.set_state(st), OK);
                        assert_eq!(i.step(0.01, 0.01), OK);
                        last = i.get_real(POS_X);
                        assert_eq!(i.free_state(&mut st), OK);
                    }
                    last
                })
            })
            .collect();
        let positions = workers.into_iter().map(|w| w.join().unwrap()).collect();
        stop.store(true, std::sync::atomic::Ordering::Relaxed);
        assert!(prober.join().unwrap() > 0);
        positions
    });
    // Every worker computed the same trajectory.
    let reference = {
        let i = running_plant("reference");
        assert_eq!(i.step(0.01, 0.01), OK);
        i.get_real(POS_X)
    };
    assert!(positions.iter().all(|&p| p == reference), "{positions:?}");
}
