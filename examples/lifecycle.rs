//! `lifecycle N`: N full life cycles of every model through the C ABI — instantiate, set
//! up, initialise, step with moving inputs, get the FMU state, serialise it, free it,
//! deserialise it, set it, free it, terminate, free the instance — for a leak checker to
//! watch (`valgrind --leak-check=full --error-exitcode=1`, uninitialised values on,
//! tests/fmpy/test_leaks.py).
//! Exits non-zero if any call fails.

#[path = "../tests/abi/common/linked.rs"]
mod linked;

use contour_core::math;
use std::ffi::CString;
use std::ptr;

use contour_fmu::framework::model::ModelInfo;
use contour_fmu::framework::variables::{Causality, VarType};
use contour_fmu::models;
use linked::*;

/// One cycle of `model`; panics on a failed call.
fn cycle(model: &ModelInfo, functions: &fmi2_bindings::fmi2CallbackFunctions, n: usize) {
    let inputs: Vec<u32> = model
        .variables
        .iter()
        .filter(|v| v.causality == Causality::Input && v.var_type() == VarType::Real)
        .map(|v| v.vr as u32)
        .collect();
    let name = CString::new(format!("cycle-{n}")).unwrap();
    // SAFETY: `functions` outlives the instance, freed at the end of this function; every
    // array handed over has the stated length; the state handles are the library's own.
    unsafe {
        let c = instantiate_started(model, &name, functions);
        for k in 0..5 {
            let values: Vec<f64> = (0..inputs.len())
                .map(|j| math::sin(0.01 * (k + n) as f64 + j as f64))
                .collect();
            assert_eq!(
                fmi2SetReal(c, inputs.as_ptr(), inputs.len(), values.as_ptr()),
                0
            );
            assert_eq!(fmi2DoStep(c, k as f64 * 1e-3, 1e-3, 1), 0);
        }
        let mut state = ptr::null_mut();
        assert_eq!(fmi2GetFMUstate(c, &mut state), 0);
        let mut size = 0;
        assert_eq!(fmi2SerializedFMUstateSize(c, state, &mut size), 0);
        let mut bytes = vec![0 as std::ffi::c_char; size];
        assert_eq!(fmi2SerializeFMUstate(c, state, bytes.as_mut_ptr(), size), 0);
        assert_eq!(fmi2FreeFMUstate(c, &mut state), 0);
        let mut restored = ptr::null_mut();
        assert_eq!(
            fmi2DeSerializeFMUstate(c, bytes.as_ptr(), size, &mut restored),
            0
        );
        assert_eq!(fmi2SetFMUstate(c, restored), 0);
        assert_eq!(fmi2FreeFMUstate(c, &mut restored), 0);
        assert_eq!(fmi2DoStep(c, 5e-3, 1e-3, 1), 0);
        assert_eq!(fmi2Terminate(c), 0);
        fmi2FreeInstance(c);
    }
}

fn main() {
    let count: usize = match std::env::args().nth(1).map(|a| a.parse()) {
        Some(Ok(n)) => n,
        None => 100,
        Some(Err(e)) => {
            eprintln!("lifecycle: N must be a whole number ({e})");
            std::process::exit(2);
        }
    };
    let functions = quiet_callbacks();
    for model in models::all() {
        for n in 0..count {
            cycle(model, &functions, n);
        }
        println!("{}: {count} cycles", model.identifier);
    }
}
