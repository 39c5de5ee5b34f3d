//! `FaultProbe` (feature `test-hooks` only, never packaged): a model that fails or
//! panics on demand, so the ABI tests can drive the FMI layer into its `Error` and
//! `Fatal` modes and check that a panic becomes `fmi2Fatal`, never an abort.

use crate::framework::model::{DefaultExperiment, Environment, Model, ModelInfo, ModelResult};
use crate::framework::saved_state::{decode_state, encode_state, StateLayout};
use crate::framework::variable_table::variable_table;
use crate::framework::variables::Value;
use crate::framework::variables::{Start, Values, Variable};

variable_table! {
    static VARIABLES;
    PANIC: Bool = Variable::discrete_input(
        "panic",
        Start::Boolean(false),
        "Panic in the next fmi2DoStep",
    );
    FAIL: Bool = Variable::discrete_input(
        "fail",
        Start::Boolean(false),
        "Fail the next fmi2DoStep",
    );
    LABEL: Str = Variable::parameter(
        "label",
        Start::String("probe"),
        "A string parameter, echoed",
    );
    STEPS: Int = Variable::discrete_output("steps", Start::Integer(0), "Steps completed");
    ECHO: Str = Variable::discrete_output("echo", Start::String(""), "The label, as computed");
    GAIN: Real = Variable::parameter(
        "gain",
        Start::Real(1.0),
        "A tunable parameter that must stay < 10",
    )
    .tunable()
    .min(0.0);
    LEVEL: Int = Variable::discrete_input(
        "level",
        Start::Integer(0),
        "An Integer input (settable whenever inputs are)",
    );
    NOTE: Str = Variable::discrete_input(
        "note",
        Start::String(""),
        "A String input (settable whenever inputs are)",
    );
}

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
    initial_dependencies: &[(ECHO.vr(), &[LABEL.vr()])],
    initial_dependencies_on_some_paths: &[],
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
        values.set(STEPS.vr(), Value::Integer(0));
        values.set(ECHO.vr(), Value::String(LABEL.get(values).to_owned()));
        Ok(())
    }

    fn parameters_changed(&mut self, values: &mut Values) -> ModelResult {
        let gain = GAIN.get(values);
        if gain >= 10.0 {
            return Err(format!("parameter 'gain' must be < 10 (got {gain})"));
        }
        Ok(())
    }

    fn do_step(&mut self, values: &mut Values, _time: f64, _step: f64) -> ModelResult {
        if PANIC.get(values) {
            panic!("FaultProbe: injected panic");
        }
        if FAIL.get(values) {
            return Err("FaultProbe: injected failure".into());
        }
        self.steps += 1;
        values.set(STEPS.vr(), Value::Integer(self.steps));
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
