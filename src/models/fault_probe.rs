//! `FaultProbe` (feature `test-hooks` only, never packaged): a model that fails or
//! panics on demand, so the ABI tests can drive the FMI layer into its `Error` and
//! `Fatal` modes and check that a panic becomes `fmi2Fatal`, never an abort.

use super::variables::{Start, Values, Variable, Vr};
use super::{
    decode_state, encode_state, DefaultExperiment, Environment, Model, ModelInfo, ModelResult,
    StateLayout, Value,
};

pub const PANIC: Vr = 0;
pub const FAIL: Vr = 1;
pub const LABEL: Vr = 2;
pub const STEPS: Vr = 3;
pub const ECHO: Vr = 4;
pub const GAIN: Vr = 5;
pub const LEVEL: Vr = 6;
pub const NOTE: Vr = 7;

static VARIABLES: [Variable; 8] = [
    Variable::discrete_input(
        PANIC,
        "panic",
        Start::Boolean(false),
        "Panic in the next fmi2DoStep",
    ),
    Variable::discrete_input(
        FAIL,
        "fail",
        Start::Boolean(false),
        "Fail the next fmi2DoStep",
    ),
    Variable::parameter(
        LABEL,
        "label",
        Start::String("probe"),
        "A string parameter, echoed",
    ),
    Variable::discrete_output(STEPS, "steps", Start::Integer(0), "Steps completed"),
    Variable::discrete_output(ECHO, "echo", Start::String(""), "The label, as computed"),
    Variable::parameter(
        GAIN,
        "gain",
        Start::Real(1.0),
        "A tunable parameter that must stay < 10",
    )
    .tunable()
    .min(0.0),
    Variable::discrete_input(
        LEVEL,
        "level",
        Start::Integer(0),
        "An Integer input (settable whenever inputs are)",
    ),
    Variable::discrete_input(
        NOTE,
        "note",
        Start::String(""),
        "A String input (settable whenever inputs are)",
    ),
];

pub static INFO: ModelInfo = ModelInfo {
    identifier: "FaultProbe",
    description: "Test-only model that fails or panics on demand",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment {
        start_time: 0.0,
        stop_time: 1.0,
        step_size: 1e-3,
    },
    // `echo` is the label as initialized; `steps` starts at 0.
    initial_dependencies: &[(ECHO, &[LABEL])],
    create: |_: &Environment| Box::new(FaultProbe { steps: 0 }),
};

const LAYOUT: StateLayout = StateLayout {
    model: "FaultProbe",
    version: 1,
};

fn decode(bytes: &[u8]) -> Result<i32, String> {
    let steps: i32 = decode_state(LAYOUT, bytes)?;
    if steps < 0 {
        return Err(format!("FaultProbe step count {steps} must be >= 0"));
    }
    Ok(steps)
}

struct FaultProbe {
    steps: i32,
}

impl Model for FaultProbe {
    fn initialize(&mut self, values: &mut Values, _start_time: f64) -> ModelResult {
        self.parameters_changed(values)?;
        self.steps = 0;
        values.set(STEPS, Value::Integer(0));
        values.set(ECHO, Value::String(values.string(LABEL).to_owned()));
        Ok(())
    }

    fn parameters_changed(&mut self, values: &mut Values) -> ModelResult {
        let gain = values.real(GAIN);
        if gain >= 10.0 {
            return Err(format!("parameter 'gain' must be < 10 (got {gain})"));
        }
        Ok(())
    }

    fn do_step(&mut self, values: &mut Values, _time: f64, _step: f64) -> ModelResult {
        if values.boolean(PANIC) {
            panic!("FaultProbe: injected panic");
        }
        if values.boolean(FAIL) {
            return Err("FaultProbe: injected failure".into());
        }
        self.steps += 1;
        values.set(STEPS, Value::Integer(self.steps));
        Ok(())
    }

    fn save_state(&self) -> Result<Vec<u8>, String> {
        encode_state(LAYOUT, &self.steps)
    }

    fn check_state(&self, bytes: &[u8], _time: f64) -> ModelResult {
        decode(bytes).map(drop)
    }

    fn restore_state(&mut self, bytes: &[u8], _time: f64) -> ModelResult {
        self.steps = decode(bytes)?;
        Ok(())
    }
}
