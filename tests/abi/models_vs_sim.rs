//! The three FMU models, driven in-process through their variable values the way the FMI
//! layer drives them (no FMI types), reproduce the in-process simulator (`contour_core::sim`)
//! sample for sample.
//!
//! The importer here is a few lines over `contour_fmu::models`: each unit holds its
//! model's [`Values`] built from the variable table's start values; a value is set by
//! looking the variable up by name in the table and checking it with [`Variable::check`]
//! (type, bounds, enumeration), as `fmi2Set*` does; outputs are read by value reference.
//! Initialization calls [`Model::initialize`] at t = 0, stepping [`Model::do_step`] with
//! t_k = k·Ts and h = Ts. Parameters are set by name with the values the simulator's
//! configuration uses (path, feed, CCC mode); everything else keeps the tables' start
//! values, which must therefore equal the simulator's defaults (controller, plant, Ts). The
//! `estimator` parameter is not set: its default is the free-curve estimator the simulator
//! uses.
//!
//! Coupling (as `contour_fmu.master` (python/) in its Gauss-Seidel scheme, and README): at each
//! step the controller reads ref (interpolator output) and pos (plant output) at t_k and
//! steps, the plant reads the controller's u and steps over [t_k, t_k+1), then the
//! interpolator steps. The plant's `pos0.*` get the interpolator's initial output (the path
//! start), as the masters' PATH_START connection does. Then sample k of the simulator's
//! trace is: reference = interpolator output and actual = plant output before step k; u,
//! estimated contour error and CCC gains = controller outputs after step k.
//!
//! Agreement is asserted bit for bit (`==` on every f64), not to a tolerance: both sides
//! run the same deterministic library code (`Interpolator::step`,
//! `CrossCoupledController::sample`, `XyTable::step(u, Ts)`) on identical inputs in the
//! same order, and the models add no arithmetic of their own on the values passed (they
//! copy inputs and outputs, and the sample clocks fire once per step at h = Ts). Any
//! difference at all means the models and the simulator have drifted apart.

use contour_core::control::CccMode;
use contour_core::math;
use contour_core::sim::{SimConfig, Simulator, Trace};
use contour_fmu::framework::model::{Environment, Model, ModelInfo};
use contour_fmu::framework::variables::{Causality, Value, Values, Variable, Vr};
use contour_fmu::models;

/// One model instance with its values.
struct Unit {
    info: &'static ModelInfo,
    model: Box<dyn Model>,
    values: Values,
}

impl Unit {
    fn new(identifier: &str) -> Self {
        let info = models::all()
            .into_iter()
            .find(|m| m.identifier == identifier)
            .unwrap_or_else(|| panic!("no model {identifier}"));
        Unit {
            info,
            model: (info.create)(&Environment::default()),
            values: Values::from_table(info.variables),
        }
    }

    fn variable(&self, name: &str) -> &'static Variable {
        self.info
            .variables
            .iter()
            .find(|v| v.name == name)
            .unwrap_or_else(|| panic!("{} has no variable {name}", self.info.identifier))
    }

    fn vr(&self, name: &str) -> Vr {
        self.variable(name).vr
    }

    /// Sets an input or parameter by name, checked against the table as `fmi2Set*` does.
    fn set(&mut self, name: &str, value: Value) {
        let v = self.variable(name);
        assert_ne!(v.causality, Causality::Output, "{name} is an output");
        v.check(&value)
            .unwrap_or_else(|e| panic!("{}: {e}", self.info.identifier));
        self.values.set(v.vr, value);
    }

    fn real(&self, vr: Vr) -> f64 {
        self.values.real(vr)
    }

    fn initialize(&mut self) {
        self.model
            .initialize(&mut self.values, 0.0)
            .unwrap_or_else(|e| panic!("{}: {e}", self.info.identifier));
    }

    fn step(&mut self, t: f64, h: f64) {
        self.model
            .do_step(&mut self.values, t, h)
            .unwrap_or_else(|e| panic!("{} at t = {t}: {e}", self.info.identifier));
    }
}

/// The closed loop through the models, recorded like the simulator's trace.
fn run_models(name: &str, config: &SimConfig, samples: usize) -> (Trace, Vec<bool>) {
    let h = config.ts;
    let mut interpolator = Unit::new("PathInterpolator2D");
    let mut controller = Unit::new("ContourCCC2D");
    let mut plant = Unit::new("XYServoPlant");

    interpolator.set("path", Value::String(name.to_string()));
    interpolator.set("feed", Value::Real(config.feed));
    interpolator.set("Ts", Value::Real(h));
    controller.set("Ts", Value::Real(h));
    let mode = config.controller.ccc.mode;
    controller.set("ccc.enable", Value::Boolean(mode != CccMode::Off));
    controller.set("fuzzy.enable", Value::Boolean(mode == CccMode::Fuzzy));

    interpolator.initialize();
    let (ref_x, ref_y, done) = (
        interpolator.vr("ref.x"),
        interpolator.vr("ref.y"),
        interpolator.vr("done"),
    );
    // The plant starts at the path start, taken from the interpolator's initial output.
    plant.set("pos0.x", Value::Real(interpolator.real(ref_x)));
    plant.set("pos0.y", Value::Real(interpolator.real(ref_y)));
    plant.initialize();
    controller.initialize();

    let c_out =
        ["u.x", "u.y", "contourError", "ccc.Kp", "ccc.Ki", "ccc.Kd"].map(|n| controller.vr(n));
    let (pos_x, pos_y) = (plant.vr("pos.x"), plant.vr("pos.y"));

    let mut trace = Trace::default();
    let mut dones = Vec::with_capacity(samples);
    for k in 0..samples {
        let t = k as f64 * h;
        let reference = [interpolator.real(ref_x), interpolator.real(ref_y)];
        let actual = [plant.real(pos_x), plant.real(pos_y)];
        dones.push(match interpolator.values.get(done) {
            Value::Boolean(b) => *b,
            other => panic!("done holds {other:?}"),
        });
        controller.set("ref.x", Value::Real(reference[0]));
        controller.set("ref.y", Value::Real(reference[1]));
        controller.set("pos.x", Value::Real(actual[0]));
        controller.set("pos.y", Value::Real(actual[1]));
        controller.step(t, h);
        let out = c_out.map(|vr| controller.real(vr));
        plant.set("u.x", Value::Real(out[0]));
        plant.set("u.y", Value::Real(out[1]));
        plant.step(t, h);
        interpolator.step(t, h);

        trace.t.push(t);
        trace.reference.push(reference.into());
        trace.actual.push(actual.into());
        trace.u.push([out[0], out[1]].into());
        trace.estimated_error.push(out[2]);
        trace.gains.push([out[3], out[4], out[5]]);
    }
    (trace, dones)
}

/// The bit patterns (so that 0.0 and -0.0, or two NaNs, are told apart).
fn bits(values: &[f64]) -> Vec<u64> {
    values.iter().map(|v| v.to_bits()).collect()
}

/// Asserts that the models' trace is bit-identical to the simulator's; returns it.
fn compare(name: &str, mode: CccMode) -> Trace {
    let config = SimConfig::builtin(name).unwrap().with_mode(mode);
    let sim = Simulator::new(config.clone()).unwrap();
    let expected = sim.run().trace;
    let n = expected.len();
    let (got, dones) = run_models(name, &config, n);
    let label = format!("{name} {mode:?}");
    for (k, &done) in dones.iter().enumerate() {
        let check = |what: &str, a: &[f64], b: &[f64]| {
            assert_eq!(bits(a), bits(b), "{label}: {what} at k={k}: {a:?} vs {b:?}");
        };
        check(
            "reference",
            got.reference[k].as_slice(),
            expected.reference[k].as_slice(),
        );
        check(
            "actual",
            got.actual[k].as_slice(),
            expected.actual[k].as_slice(),
        );
        check("u", got.u[k].as_slice(), expected.u[k].as_slice());
        check(
            "contour error",
            &[got.estimated_error[k]],
            &[expected.estimated_error[k]],
        );
        check("gains", &got.gains[k], &expected.gains[k]);
        assert_eq!(done, sim.references()[k].done, "{label}: done at k={k}");
    }
    // The run is the whole path: done only at the last sample, and the tool moved.
    assert!(dones[n - 1] && !dones[n - 2], "{label}");
    let xs = got.actual.iter().map(|p| p[0]);
    let span = xs.clone().fold(f64::MIN, f64::max) - xs.fold(f64::MAX, f64::min);
    assert!(span > 15.0, "{label}: x span {span}");
    println!("{label}: {n} samples bit-identical (x span {span:.1} mm)");
    got
}

fn both_modes(name: &str) {
    let fuzzy = compare(name, CccMode::Fuzzy);
    let fixed = compare(name, CccMode::Fixed);
    let off = compare(name, CccMode::Off);
    // Fixed gains are the base gains at every sample; fuzzy ones move.
    assert!(fixed.gains.iter().all(|g| *g == fixed.gains[0]) && fixed.gains[0][0] > 0.0);
    assert!(fuzzy.gains.iter().any(|g| *g != fixed.gains[0]));
    // The CCC mode reached the model: with it the gains are non-zero and the path differs.
    assert!(fuzzy.gains.iter().any(|g| g[0] > 0.0));
    assert!(off.gains.iter().all(|g| *g == [0.0; 3]));
    let diff = fuzzy
        .actual
        .iter()
        .zip(&off.actual)
        .map(|(a, b)| math::hypot(a[0] - b[0], a[1] - b[1]))
        .fold(0.0, f64::max);
    assert!(diff > 1e-3, "{name}: CCC on/off differ by only {diff} mm");
}

#[test]
fn circle_models_match_the_simulator() {
    both_modes("circle");
}

#[test]
fn infinity_models_match_the_simulator() {
    both_modes("infinity");
}

#[test]
fn trident_models_match_the_simulator() {
    both_modes("trident");
}
