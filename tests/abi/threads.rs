//! 64 instances of every model stepped from 8 threads at once give bit for bit the
//! outputs of the same instances stepped one after another on one thread: instances share
//! nothing but the handle registry, and nothing in a step depends on which thread runs it
//! or on what the other instances do meanwhile.

use contour_core::math;
use std::ffi::CString;

use crate::common::linked::{
    fmi2DoStep, fmi2EnterInitializationMode, fmi2ExitInitializationMode, fmi2FreeInstance,
    fmi2GetReal, fmi2Instantiate, fmi2SetReal, fmi2SetupExperiment, quiet_callbacks,
};
use contour_fmu::framework::model::ModelInfo;
use contour_fmu::framework::variables::{Causality, VarType};
use contour_fmu::models;
use fmi2_bindings::{
    fmi2CallbackFunctions, fmi2Component, fmi2Type_fmi2CoSimulation, fmi2ValueReference,
};

const INSTANCES: usize = 64;
const THREADS: usize = 8;
const STEPS: usize = 400;
const STEP: f64 = 1e-3;

/// An instance handle that may move to another thread: FMI 2.0 lets an importer call an
/// instance from any thread as long as no two calls on it overlap, which the test keeps
/// (each instance belongs to one thread at a time).
struct Owned(fmi2Component);
// SAFETY: see the type's comment; the library serialises calls per instance anyway.
unsafe impl Send for Owned {}

fn real_variables(model: &ModelInfo, causality: Causality) -> Vec<fmi2ValueReference> {
    model
        .variables
        .iter()
        .filter(|v| v.causality == causality && v.var_type() == VarType::Real)
        .map(|v| v.vr as fmi2ValueReference)
        .collect()
}

/// The inputs of instance `i` at step `k`: smooth, different for every instance and input
/// (joints on a slow tilted circle for a controller, commands for a plant), so each
/// instance has its own history.
fn input(i: usize, j: usize, k: usize) -> f64 {
    let s = 0.002 * k as f64 + 0.37 * i as f64;
    let phase = 0.9 * j as f64;
    match j % 5 {
        3 => 0.3 + 0.1 * math::sin(s + phase),
        4 => 0.2 * s + 0.05 * phase,
        _ => 20.0 * math::cos(s + phase) + (i % 7) as f64,
    }
}

/// Steps `instance` (the `i`-th) through all steps; its outputs after each.
fn run(model: &ModelInfo, instance: &Owned, i: usize) -> Vec<f64> {
    let inputs = real_variables(model, Causality::Input);
    let outputs = real_variables(model, Causality::Output);
    let mut read = vec![0.0; outputs.len()];
    let mut trace = Vec::with_capacity(STEPS * outputs.len());
    for k in 0..STEPS {
        let values: Vec<f64> = (0..inputs.len()).map(|j| input(i, j, k)).collect();
        // SAFETY: a live instance, arrays of the stated lengths.
        unsafe {
            assert_eq!(
                fmi2SetReal(instance.0, inputs.as_ptr(), inputs.len(), values.as_ptr()),
                0
            );
            assert_eq!(fmi2DoStep(instance.0, k as f64 * STEP, STEP, 1), 0);
            assert_eq!(
                fmi2GetReal(
                    instance.0,
                    outputs.as_ptr(),
                    outputs.len(),
                    read.as_mut_ptr()
                ),
                0
            );
        }
        trace.extend_from_slice(&read);
    }
    trace
}

/// 64 started instances; where the model has a `feed` (the interpolators, which have no
/// inputs) each instance gets its own, so every instance has its own trajectory.
fn start(model: &ModelInfo, functions: &fmi2CallbackFunctions) -> Vec<Owned> {
    let feed = model
        .variables
        .iter()
        .find(|v| v.name == "feed")
        .map(|v| v.vr as fmi2ValueReference);
    (0..INSTANCES)
        .map(|i| {
            let name = CString::new(format!("{}-{i}", model.identifier)).unwrap();
            let guid = CString::new(model.guid()).unwrap();
            // SAFETY: NUL-terminated strings and callbacks that outlive the instance
            // (freed below, before `functions` goes); a live instance afterwards.
            unsafe {
                let c = fmi2Instantiate(
                    name.as_ptr(),
                    fmi2Type_fmi2CoSimulation,
                    guid.as_ptr(),
                    std::ptr::null(),
                    functions,
                    0,
                    0,
                );
                assert!(!c.is_null());
                assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), 0);
                assert_eq!(fmi2EnterInitializationMode(c), 0);
                if let Some(vr) = feed {
                    let value = 10.0 + i as f64;
                    assert_eq!(fmi2SetReal(c, &vr, 1, &value), 0);
                }
                assert_eq!(fmi2ExitInitializationMode(c), 0);
                Owned(c)
            }
        })
        .collect()
}

fn free(instances: Vec<Owned>) {
    for instance in instances {
        // SAFETY: a live instance, freed once.
        unsafe { fmi2FreeInstance(instance.0) };
    }
}

#[test]
fn instances_stepped_on_eight_threads_match_the_same_instances_stepped_serially() {
    let functions = quiet_callbacks();
    for model in models::all() {
        let serial_instances = start(model, &functions);
        let serial: Vec<Vec<f64>> = serial_instances
            .iter()
            .enumerate()
            .map(|(i, instance)| run(model, instance, i))
            .collect();
        free(serial_instances);

        // Eight groups of eight, each group moved to its own thread and back.
        let mut instances = start(model, &functions).into_iter();
        let groups: Vec<Vec<Owned>> = (0..THREADS)
            .map(|_| instances.by_ref().take(INSTANCES / THREADS).collect())
            .collect();
        let per_thread = INSTANCES / THREADS;
        let (groups, parallel): (Vec<Vec<Owned>>, Vec<Vec<Vec<f64>>>) =
            std::thread::scope(|scope| {
                let handles: Vec<_> = groups
                    .into_iter()
                    .enumerate()
                    .map(|(t, group)| {
                        scope.spawn(move || {
                            let traces: Vec<Vec<f64>> = group
                                .iter()
                                .enumerate()
                                .map(|(n, instance)| run(model, instance, t * per_thread + n))
                                .collect();
                            (group, traces)
                        })
                    })
                    .collect();
                handles
                    .into_iter()
                    .map(|h| h.join().expect("a stepping thread panicked"))
                    .unzip()
            });
        free(groups.into_iter().flatten().collect());
        let parallel: Vec<Vec<f64>> = parallel.into_iter().flatten().collect();

        assert_eq!(serial.len(), parallel.len());
        for (i, (a, b)) in serial.iter().zip(&parallel).enumerate() {
            let same =
                a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
            assert!(
                same,
                "{}: instance {i} differs on threads",
                model.identifier
            );
        }
        // The instances did differ from one another (a test of copies would be empty).
        assert!(
            serial[0] != serial[1],
            "{}: instances alike",
            model.identifier
        );
    }
}

// Instances through the dlopened library, interleaved and across threads.

mod interleaved {
    use crate::common::plant_vr::{POS0_X, POS_X, U_X};
    use crate::common::*;
    use contour_fmu::models::xy_servo_plant as plant;

    #[test]
    fn instances_are_independent_when_interleaved_and_across_threads() {
        let alone = Instance::new(&plant::INFO);
        alone.start();
        let reference = run_plant(&alone, 0, 200);

        let a = Instance::named(&plant::INFO, "a");
        let b = Instance::named(&plant::INFO, "b");
        a.start();
        assert_eq!(b.setup(0.0, None), OK);
        assert_eq!(b.enter_init(), OK);
        assert_eq!(b.set_reals(&[POS0_X], &[5.0]), OK);
        assert_eq!(b.exit_init(), OK);
        let mut from_a = Vec::new();
        for k in 0..200 {
            from_a.extend(run_plant(&a, k, k + 1));
            assert_eq!(b.set_reals(&[U_X], &[-100.0]), OK);
            assert_eq!(b.step(k as f64 * 0.001, 0.001), OK);
        }
        assert_eq!(from_a, reference);
        assert!(b.get_real(POS_X) < 5.0 - 10.0);

        // Each instance stepped on its own thread, concurrently.
        let results: Vec<Vec<[f64; 3]>> = std::thread::scope(|scope| {
            let handles: Vec<_> = (0..2)
                .map(|_| {
                    scope.spawn(|| {
                        let i = Instance::new(&plant::INFO);
                        i.start();
                        run_plant(&i, 0, 200)
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        assert_eq!(results[0], reference);
        assert_eq!(results[1], reference);
    }

    #[test]
    fn reset_restores_start_values() {
        let i = Instance::new(&plant::INFO);
        assert_eq!(i.setup(0.0, None), OK);
        assert_eq!(i.enter_init(), OK);
        assert_eq!(i.set_reals(&[POS0_X], &[7.0]), OK);
        assert_eq!(i.exit_init(), OK);
        assert_eq!(i.get_real(POS_X), 7.0);
        run_plant(&i, 0, 20);
        assert_eq!(i.reset(), OK);
        assert_eq!(i.setup(0.0, None), OK);
        assert_eq!(i.enter_init(), OK);
        assert_eq!(
            i.get_reals(&[POS0_X, POS_X, U_X]),
            (OK, vec![0.0, 0.0, 0.0])
        );
    }
}
