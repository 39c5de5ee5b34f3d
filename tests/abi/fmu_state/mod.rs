//! FMU state: save, restore and serialization give bit-identical trajectories, bad bytes
//! are refused, a restored state brings back its mode; the restored values are checked
//! like parameters (`validation`).

mod validation;

use crate::common::plant_vr::{POS0_X, POS_X, U_X};
use crate::common::*;
#[cfg(feature = "test-hooks")]
use contour_fmu::models::fault_probe as probe;
use contour_fmu::models::xy_servo_plant as plant;

#[test]
fn state_save_restore_and_serialization_give_bit_identical_trajectories() {
    let i = Instance::new(&plant::INFO);
    i.start();
    run_plant(&i, 0, 50);
    let (s, mut state) = i.get_state();
    assert_eq!(s, OK);
    let reference = run_plant(&i, 50, 120);

    // Restore in place.
    assert_eq!(i.set_state(state), OK);
    assert_eq!(run_plant(&i, 50, 120), reference);

    // Serialize, deserialize into a fresh instance, continue there.
    let (s, bytes) = i.serialize(state);
    assert_eq!(s, OK);
    // A state saved after initialization goes into an initialized instance.
    let other = Instance::new(&plant::INFO);
    other.start();
    let (s, mut restored) = other.deserialize(&bytes);
    assert_eq!(s, OK);
    assert_eq!(other.set_state(restored), OK);
    assert_eq!(run_plant(&other, 50, 120), reference);

    // Overwriting an existing state object in place (FMI allows passing it back).
    let mut reuse = state;
    assert_eq!(unsafe { lib().fmi2GetFMUstate(i.c, &mut reuse) }, OK);
    assert_eq!(reuse, state);

    assert_eq!(i.free_state(&mut state), OK);
    assert_eq!(other.free_state(&mut restored), OK);
}

#[test]
#[cfg(feature = "test-hooks")]
fn corrupt_truncated_and_foreign_state_bytes_are_refused() {
    let i = Instance::new(&plant::INFO);
    i.start();
    run_plant(&i, 0, 10);
    let (_, mut state) = i.get_state();
    let (_, bytes) = i.serialize(state);
    let before = i.get_real(POS_X);

    let mut corrupt = bytes.clone();
    let middle = corrupt.len() / 2;
    corrupt[middle] ^= 0x01;
    for bad in [
        corrupt,
        bytes[..bytes.len() - 1].to_vec(),
        b"not a state at all".to_vec(),
        Vec::new(),
    ] {
        let (s, st) = i.deserialize(&bad);
        assert_eq!(s, ERROR);
        assert!(st.is_null());
    }
    // A state of another model.
    let probe = Instance::new(&probe::INFO);
    probe.start();
    let (_, mut probe_state) = probe.get_state();
    let (_, probe_bytes) = probe.serialize(probe_state);
    assert_eq!(i.deserialize(&probe_bytes).0, ERROR);
    assert!(i.last_error().contains("belongs to another model"));
    // Too small a buffer.
    let mut small = vec![0u8; 4];
    let s = unsafe {
        lib().fmi2SerializeFMUstate(i.c, state, small.as_mut_ptr() as *mut fmi2Byte, small.len())
    };
    assert_eq!(s, ERROR);
    // Nothing above disturbed the instance.
    assert_eq!(i.get_real(POS_X), before);
    i.free_state(&mut state);
    probe.free_state(&mut probe_state);
}

/// fmi2SetFMUstate restores the mode the state was saved in, whatever the mode now (as
/// the Reference FMUs do): the instance then behaves exactly like the one that saved it.
#[test]
fn restoring_a_state_brings_back_the_mode_it_was_saved_in() {
    let i = Instance::new(&plant::INFO);
    let (_, mut early) = i.get_state();
    i.start();
    run_plant(&i, 0, 10);
    let (_, mut running) = i.get_state();
    let reference = run_plant(&i, 10, 30);

    // Saved before initialization: the instance is back in Instantiated with start values.
    assert_eq!(i.set_state(early), OK);
    assert_eq!(i.step(0.01, 0.001), ERROR);
    assert!(i
        .last_error()
        .contains("illegal call sequence (state Instantiated)"));
    assert_eq!(
        i.get_reals(&[POS0_X]).0,
        ERROR,
        "no fmi2GetReal before initialization"
    );
    assert_eq!(i.setup(0.0, None), OK);
    assert_eq!(i.enter_init(), OK);
    assert_eq!(i.get_reals(&[U_X, POS_X]), (OK, vec![0.0, 0.0]));

    // Terminated, then a state saved while stepping: stepping again, bit for bit.
    assert_eq!(i.exit_init(), OK);
    assert_eq!(i.terminate(), OK);
    assert_eq!(i.set_state(running), OK);
    assert_eq!(run_plant(&i, 10, 30), reference);

    // A state set into a freshly instantiated instance: no initialization needed.
    let fresh = Instance::new(&plant::INFO);
    let (_, bytes) = i.serialize(running);
    let (s, mut restored) = fresh.deserialize(&bytes);
    assert_eq!(s, OK);
    assert_eq!(fresh.set_state(restored), OK);
    assert_eq!(run_plant(&fresh, 10, 30), reference);

    assert_eq!(i.free_state(&mut early), OK);
    assert_eq!(i.free_state(&mut running), OK);
    assert_eq!(fresh.free_state(&mut restored), OK);
}
