//! Proves that a controller sample and a fuzzy evaluation never touch the heap once the
//! controller is built: they run inside `fmi2DoStep`, where allocation means unbounded
//! latency. The same for the other per-sample work: an interpolator step, a free-curve
//! estimate, a true-error query and one closed-loop sample of `sim` (the PSO runs that
//! thousands of times), and the whole `fmi2DoStep`/`fmi2GetReal`/`fmi2SetReal` round of
//! every FMU, called through the C functions linked from the library. A counting global
//! allocator (this test binary only) counts the allocations made by the current thread.

use contour_core::math;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::hint::black_box;

use contour_core::contour::planar::{Estimator, EstimatorKind, TrueErrorIndex};
use contour_core::contour::{ContourEstimate, ContourEstimator};
use contour_core::control::{
    CccConfig, CccMode, ControllerConfig, CrossCoupledController, FiveAxisConfig,
    FiveAxisController, FuzzyEngine,
};
use contour_core::geometry::Vector2;
use contour_core::kinematics::Joints;
use contour_core::path::planar::{builtin, Path};
use contour_core::path::{Curve, Interpolator};
use contour_core::sim::{SimConfig, Simulator};

thread_local! {
    // Const-initialised and without a destructor, so reading it never allocates.
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

struct Counting;

// SAFETY: every call is forwarded unchanged to the system allocator, which upholds the
// `GlobalAlloc` contract; the only extra work is bumping a thread-local counter, which
// neither allocates nor unwinds (`try_with` ignores a torn-down thread-local).
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

// Linked statically from the rlib (not dlopened), so the counting allocator sees what
// they allocate.
use crate::common::linked::{
    fmi2DoStep, fmi2EnterInitializationMode, fmi2ExitInitializationMode, fmi2FreeInstance,
    fmi2GetReal, fmi2Instantiate, fmi2SetReal, fmi2SetupExperiment, fmi3DoStep,
    fmi3EnterInitializationMode, fmi3ExitInitializationMode, fmi3FreeInstance, fmi3GetFloat64,
    fmi3InstantiateCoSimulation, fmi3SetFloat64,
};
use crate::common::{callbacks, cstr, fmi2ValueReference, Log};
use contour_fmu::models;

#[test]
fn an_fmi_step_round_allocates_nothing_with_logging_off() {
    for model in models::all() {
        let log = Log::default();
        let functions = callbacks(&log);
        let (name, guid) = (cstr("no-alloc"), cstr(&model.guid()));
        // SAFETY: valid strings and callbacks that outlive the instance.
        let c = unsafe {
            fmi2Instantiate(
                name.as_ptr(),
                1,
                guid.as_ptr(),
                std::ptr::null(),
                &*functions,
                0,
                0,
            )
        };
        assert!(!c.is_null());
        let inputs: Vec<fmi2ValueReference> = model
            .variables
            .iter()
            .filter(|v| {
                v.causality == contour_fmu::framework::variables::Causality::Input
                    && v.var_type() == contour_fmu::framework::variables::VarType::Real
            })
            .map(|v| v.vr as u32)
            .collect();
        let outputs: Vec<fmi2ValueReference> = model
            .variables
            .iter()
            .filter(|v| {
                v.causality == contour_fmu::framework::variables::Causality::Output
                    && v.var_type() == contour_fmu::framework::variables::VarType::Real
            })
            .map(|v| v.vr as u32)
            .collect();
        let mut read = vec![0.0; outputs.len()];
        let write: Vec<f64> = (0..inputs.len()).map(|i| 0.1 * i as f64).collect();
        // SAFETY: a live instance and arrays of the stated lengths.
        unsafe {
            assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), 0);
            assert_eq!(fmi2EnterInitializationMode(c), 0);
            assert_eq!(fmi2ExitInitializationMode(c), 0);
            let mut round = |k: usize| {
                let t = k as f64 * 1e-3;
                assert_eq!(
                    fmi2SetReal(c, inputs.as_ptr(), inputs.len(), write.as_ptr()),
                    0
                );
                assert_eq!(fmi2DoStep(c, t, 1e-3, 1), 0);
                assert_eq!(
                    fmi2GetReal(c, outputs.as_ptr(), outputs.len(), read.as_mut_ptr()),
                    0
                );
            };
            round(0);
            round(1);
            let n = allocations_during(|| (2..200).for_each(&mut round));
            assert_eq!(
                n, 0,
                "{}: {n} allocations in 198 step rounds",
                model.identifier
            );
            fmi2FreeInstance(c);
        }
        assert!(log.records.lock().unwrap().is_empty());
    }
}

/// The same round through FMI 3.0 (fmi3SetFloat64, fmi3DoStep, fmi3GetFloat64), every
/// model in both unit systems: its own exports and result pointers allocate nothing either.
#[test]
fn an_fmi3_step_round_allocates_nothing_with_logging_off() {
    use contour_fmu::framework::variables::{Causality, VarType};
    for interface in models::interfaces() {
        let real = |causality| -> Vec<u32> {
            let of = |v: &&contour_fmu::framework::variables::Variable| {
                v.causality == causality && v.var_type() == VarType::Real
            };
            interface
                .variables
                .iter()
                .filter(of)
                .map(|v| v.vr as u32)
                .collect()
        };
        let (inputs, outputs) = (real(Causality::Input), real(Causality::Output));
        let (name, token) = (cstr("no-alloc"), cstr(&interface.instantiation_token));
        // SAFETY: valid strings; no logger, no intermediate variables.
        let c = unsafe {
            fmi3InstantiateCoSimulation(
                name.as_ptr(),
                token.as_ptr(),
                std::ptr::null(),
                false,
                false,
                false,
                false,
                std::ptr::null(),
                0,
                std::ptr::null_mut(),
                None,
                None,
            )
        };
        assert!(!c.is_null());
        let mut read = vec![0.0; outputs.len()];
        let write: Vec<f64> = (0..inputs.len()).map(|i| 0.1 * i as f64).collect();
        let (mut event, mut terminate, mut early, mut last) = (false, false, false, 0.0);
        // SAFETY: a live instance, arrays of the stated lengths, writable results.
        unsafe {
            assert_eq!(
                fmi3EnterInitializationMode(c, false, 0.0, 0.0, false, 0.0),
                0
            );
            assert_eq!(fmi3ExitInitializationMode(c), 0);
            let mut round = |k: usize| {
                let t = k as f64 * 1e-3;
                let (n, m) = (inputs.len(), outputs.len());
                assert_eq!(fmi3SetFloat64(c, inputs.as_ptr(), n, write.as_ptr(), n), 0);
                let stepped = fmi3DoStep(
                    c,
                    t,
                    1e-3,
                    true,
                    &mut event,
                    &mut terminate,
                    &mut early,
                    &mut last,
                );
                assert_eq!(stepped, 0);
                assert_eq!(
                    fmi3GetFloat64(c, outputs.as_ptr(), m, read.as_mut_ptr(), m),
                    0
                );
            };
            round(0);
            round(1);
            let n = allocations_during(|| (2..200).for_each(&mut round));
            assert_eq!(
                n,
                0,
                "{} ({}): {n} allocations in 198 FMI 3.0 step rounds",
                interface.model.identifier,
                interface.units.name()
            );
            assert_eq!(last, 0.2, "lastSuccessfulTime after 200 steps of 1 ms");
            fmi3FreeInstance(c);
        }
    }
}

#[test]
fn a_contour_ccc_5x_round_on_a_moving_path_allocates_nothing() {
    // The round above holds every input constant, so ContourCCC5X's mapping never moves
    // past its first segment and never produces an evaluation estimate. Here the reference
    // joints run along a helix and the measured ones trail 35 samples behind: the online
    // mapping, the foot-point errors, both laws and the evaluation estimate all run, the
    // mapping's rings wrap, through the ABI, every sample.
    let model = crate::common::linked::model("ContourCCC5X");
    let inputs = crate::common::linked::vrs(
        model,
        &[
            "ref.X", "ref.Y", "ref.Z", "ref.A", "ref.C", "pos.X", "pos.Y", "pos.Z", "pos.A",
            "pos.C",
        ],
    );
    let outputs = crate::common::linked::vrs(
        model,
        &[
            "u.X",
            "u.Y",
            "u.Z",
            "u.A",
            "u.C",
            "contourError.tip",
            "contourError.orientation",
            "evaluation.tip",
            "evaluation.delay",
        ],
    );
    let q = |k: usize| {
        let t = k as f64 * 2.5e-3;
        [
            30.0 + 20.0 * math::cos(t),
            10.0 + 20.0 * math::sin(t),
            0.8 * t,
            0.35 + 0.1 * math::sin(0.3 * t),
            t,
        ]
    };
    let write: Vec<[f64; 10]> = (0..2_300)
        .map(|k| {
            let (r, a) = (q(k), q(k.saturating_sub(35)));
            std::array::from_fn(|i| if i < 5 { r[i] } else { a[i - 5] + 2e-3 })
        })
        .collect();
    let log = Log::default();
    let functions = callbacks(&log);
    let name = cstr("no-alloc-5x");
    // SAFETY: the callbacks (and the log they point to) outlive the instance.
    let c = unsafe { crate::common::linked::instantiate_started(model, &name, &*functions) };
    let mut read = [0.0; 9];
    let (mut max_tip, mut max_u) = (0.0f64, 0.0f64);
    let mut round = |k: usize| {
        // SAFETY: a live instance and arrays of the stated lengths.
        unsafe {
            assert_eq!(fmi2SetReal(c, inputs.as_ptr(), 10, write[k].as_ptr()), 0);
            assert_eq!(fmi2DoStep(c, k as f64 * 1e-3, 1e-3, 1), 0);
            assert_eq!(fmi2GetReal(c, outputs.as_ptr(), 9, read.as_mut_ptr()), 0);
        }
        max_tip = max_tip.max(read[5]);
        max_u = max_u.max(read[0].abs());
    };
    (0..300).for_each(&mut round);
    let n = allocations_during(|| (300..write.len()).for_each(&mut round));
    assert_eq!(n, 0, "{n} allocations in 2000 ContourCCC5X step rounds");
    // The paths the constant inputs miss did run: a contour error, an evaluation estimate
    // describing a tool some samples back, velocity commands.
    assert!(read.iter().all(|v| v.is_finite()), "{read:?}");
    assert!(max_tip > 1e-4 && max_u > 1.0, "tip {max_tip}, u.X {max_u}");
    assert!(read[8] > 0.0, "no evaluation estimate: {read:?}");
    // SAFETY: a live instance, freed once.
    unsafe { fmi2FreeInstance(c) };
    assert!(log.records.lock().unwrap().is_empty());
}

fn allocations_during(f: impl FnOnce()) -> u64 {
    let before = ALLOCATIONS.with(Cell::get);
    f();
    ALLOCATIONS.with(Cell::get) - before
}

/// Exact circle error, like the estimators of docs/design/two-axis.md §4.1 (no history needed).
struct Circle;

impl ContourEstimator for Circle {
    fn estimate(&mut self, _reference: Vector2, p: Vector2) -> ContourEstimate {
        let d = [p[0] + 10.0, p[1]];
        let rho = math::hypot(d[0], d[1]);
        ContourEstimate {
            error: rho - 10.0,
            normal: Vector2::new(-d[0] / rho, -d[1] / rho),
        }
    }
    fn reset(&mut self) {}
}

fn point(t: f64) -> Vector2 {
    let a = std::f64::consts::PI * t;
    Vector2::new(10.0 * math::cos(a) - 10.0, 10.0 * math::sin(a))
}

#[test]
fn sample_and_fuzzy_evaluation_do_not_allocate() {
    // The counter works: a visible allocation is seen.
    let seen = allocations_during(|| {
        black_box(vec![1u8; 64]);
    });
    assert!(seen >= 1, "counting allocator is not active");

    let engine = FuzzyEngine::default();
    let fuzzy = allocations_during(|| {
        let mut acc = 0.0;
        for k in 0..20_000 {
            let x = math::sin(k as f64 * 0.37) * 3.5;
            let y = math::cos(k as f64 * 0.11) * 3.5;
            let out = engine.evaluate(black_box(x), black_box(y));
            acc += out.dkp + out.dki + out.dkd;
        }
        black_box(acc);
    });
    assert_eq!(fuzzy, 0, "fuzzy evaluation allocated");

    for mode in [CccMode::Off, CccMode::Fixed, CccMode::Fuzzy] {
        let config = ControllerConfig {
            ccc: CccConfig {
                mode,
                ..CccConfig::default()
            },
            ..ControllerConfig::default()
        };
        let mut controller = CrossCoupledController::new(config, Circle).unwrap();
        let ts = config.ts;
        let mut p = point(0.0);
        let count = allocations_during(|| {
            for k in 0..5_000 {
                let out = controller.sample(black_box(point(k as f64 * ts)), black_box(p));
                p = Vector2::new(p[0] + out.u[0] * ts, p[1] + out.u[1] * ts);
            }
            controller.reset();
            black_box(controller.sample(point(0.0), point(0.0)));
        });
        assert_eq!(count, 0, "{mode:?}: sample() allocated");
        assert!(p[0].is_finite() && p[1].is_finite());
    }
}

#[test]
fn path_estimator_and_true_error_do_not_allocate() {
    let part = "G1 X30 F600\nG3 X35 Y5 R5\nG1 Y20\nX0\nY0\n";
    let part =
        Path::Program(contour_core::path::planar::Program::parse_gcode(part, "p.ngc").unwrap());
    let paths = ["circle", "infinity", "trident"].map(|n| (n, builtin::by_name(n).unwrap()));
    for (name, path) in paths.into_iter().chain([("program", part)]) {
        let mut interp = Interpolator::new(path.clone(), 50.0, 1e-3).unwrap();
        let mut refs = Vec::with_capacity(10_000);
        let count = allocations_during(|| {
            let mut s = interp.current();
            while !s.done {
                s = interp.step();
                // Capacity reserved above: pushing does not allocate.
                refs.push(black_box(s));
            }
        });
        assert_eq!(count, 0, "{name}: Interpolator::step allocated");
        assert!(refs.len() > 1000 && refs.len() < 10_000);

        // The free-curve and program estimators and the true error of a point lagging 35
        // samples and 0.1 mm off the path, as in the closed loop.
        let mut free_curve = Estimator::for_path(EstimatorKind::FreeCurve, &path);
        let mut program = Estimator::for_path(EstimatorKind::Program, &path);
        let index = TrueErrorIndex::new(&path);
        let mut acc = 0.0;
        let count = allocations_during(|| {
            let mut hint = 0.0;
            for k in 0..refs.len() {
                let lag = refs[k.saturating_sub(35)];
                let d = path.eval(lag.u).d1;
                let s = 0.1 / math::hypot(d[0], d[1]);
                let p = Vector2::new(lag.point[0] - d[1] * s, lag.point[1] + d[0] * s);
                let est = free_curve.estimate(black_box(refs[k].point), black_box(p));
                let exact = program.estimate(black_box(refs[k].point), black_box(p));
                let truth = index.error(black_box(p), hint);
                hint = truth.u;
                acc += est.error + exact.error + truth.error;
            }
        });
        assert_eq!(count, 0, "{name}: an estimate or the true error allocated");
        assert!(acc.is_finite());
    }
}

#[test]
fn a_planned_xy_reference_samples_without_allocating() {
    use contour_core::path::planar::{XyLimits, XyReference};
    let part = "G64 P0.02\nG1 X30 F1200\nG3 X35 Y5 R5\nG1 Y20\nX0\nY0\n";
    let part =
        Path::Program(contour_core::path::planar::Program::parse_gcode(part, "p.ngc").unwrap());
    let limits = XyLimits {
        feed: 20.0,
        rapid: 100.0,
        accel: 2000.0,
        jerk: 1e5,
        tolerance: 0.01,
        ts: 1e-3,
    };
    // A program, and a NURBS on its arc-length map.
    for path in [part, builtin::by_name("trident").unwrap()] {
        let mut reference = XyReference::new(path, limits).unwrap();
        let mut acc = 0.0;
        let count = allocations_during(|| {
            while !reference.done() {
                let p = reference.step();
                acc += black_box(p.point[0] + p.speed);
            }
        });
        assert_eq!(count, 0, "a planned sample allocated");
        assert!(acc.is_finite() && reference.duration() > 5.0);
    }
}

#[test]
fn a_five_axis_reference_and_its_derivatives_sample_without_allocating() {
    use contour_core::kinematics::TableTiltingAc;
    use contour_core::limits::{JointLimits, PathLimits};
    use contour_core::path::five_axis::{FiveAxisInputs, FiveAxisReference, Planner, ToolPath};
    // At constant feed (the interpolator's look-ahead and the inverse kinematics) and
    // planned (the jerk filter's look-ahead), to the end of the path.
    for accel in [0.0, 2000.0] {
        let limits = PathLimits {
            accel,
            ..PathLimits::at_feed(50.0)
        };
        let inputs = FiveAxisInputs {
            path: ToolPath::builtin("tilted_helix").unwrap(),
            builtin: Some("tilted_helix".into()),
            feeds: Vec::new(),
            machine: TableTiltingAc::ORIGIN,
            joints: JointLimits::DEFAULT,
            limits,
            ts: 1e-3,
        };
        let mut reference =
            FiveAxisReference::new(inputs, &Planner::new(), &|i| format!("pose {i}")).unwrap();
        let mut acc = 0.0;
        let count = allocations_during(|| {
            while !reference.current().done {
                let sample = reference.step().unwrap();
                let (v, a) = reference.derivatives();
                acc += black_box(sample.joints[0] + v[0] + a[0]);
            }
        });
        assert_eq!(count, 0, "accel {accel}: a five-axis sample allocated");
        assert!(acc.is_finite());
    }
}

#[test]
fn closed_loop_samples_do_not_allocate() {
    for name in ["circle", "trident"] {
        let sim = Simulator::new(SimConfig::builtin(name).unwrap()).unwrap();
        let mut run = sim.start();
        let mut n = 0;
        let count = allocations_during(|| {
            for r in run.by_ref() {
                black_box(r);
                n += 1;
            }
        });
        assert_eq!(count, 0, "{name}: a closed-loop sample allocated");
        assert_eq!(n, sim.samples());
        assert!(run.metrics().is_stable());

        // A whole metrics-only run allocates a fixed amount (the controller), however
        // long it is.
        let mut short = sim.config().clone();
        short.duration = Some(0.5);
        let short = Simulator::new(short).unwrap();
        let long_count = allocations_during(|| {
            black_box(sim.metrics());
        });
        let short_count = allocations_during(|| {
            black_box(short.metrics());
        });
        assert_eq!(
            long_count, short_count,
            "{name}: allocations grow with run length"
        );
    }
}

#[test]
fn a_five_axis_sample_does_not_allocate() {
    // Mapping, foot-point errors, both laws and the damped least squares, every sample,
    // once the controller (and its mapper's rings) exist; longer than the band, so the
    // rings wrap.
    for mode in [CccMode::Off, CccMode::Fixed, CccMode::Fuzzy] {
        let mut controller =
            FiveAxisController::new(FiveAxisConfig::DEFAULT.with_mode(mode)).unwrap();
        let reference = |k: usize| {
            let t = k as f64 * 1e-3;
            Joints::new(
                20.0 * math::cos(t),
                20.0 * math::sin(t),
                5.0 * t,
                0.35 + 0.1 * math::sin(t),
                2.5 * t,
            )
        };
        let mut sum = 0.0;
        let count = allocations_during(|| {
            for k in 0..2_000usize {
                let actual = reference(k.saturating_sub(35)) + Joints::repeat(1e-3);
                let out = controller
                    .sample(black_box(&reference(k)), black_box(&actual))
                    .unwrap();
                sum += out.u.sum();
            }
        });
        assert_eq!(count, 0, "{mode:?}: five-axis sample() allocated");
        assert!(sum.is_finite() && controller.mapper().samples() > 1_900);
    }
}
