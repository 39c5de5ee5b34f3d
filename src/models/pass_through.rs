//! `PassThrough` (feature `test-hooks` only, never packaged): the baseline of
//! benches/fmu_abi.rs. Ten Real inputs `in1`…`in10`, copied on `fmi2DoStep` to the ten
//! Real outputs `out1`…`out10`, no parameters and no internal state: an instance step
//! costs the FMI layer's bookkeeping and nothing else. Ten inputs and ten outputs cover the
//! call shapes of both controllers, so the bench makes the same calls with the same
//! number of values as for each of them: `fmi2SetReal` of 4 inputs / `fmi2GetReal` of 3
//! outputs for `ContourCCC2D`, 10 / 7 for `ContourCCC5X`.

use crate::framework::model::{DefaultExperiment, Environment, Model, ModelInfo, ModelResult};
use crate::framework::saved_state::{decode_state, encode_state, StateLayout};
use crate::framework::variable_table::variable_table;
use crate::framework::variables::Values;
use crate::framework::variables::Variable;

variable_table! {
    static VARIABLES;
    IN: Reals<10> = [
        Variable::input("in1", 0.0, "Copied to out1"),
        Variable::input("in2", 0.0, "Copied to out2"),
        Variable::input("in3", 0.0, "Copied to out3"),
        Variable::input("in4", 0.0, "Copied to out4"),
        Variable::input("in5", 0.0, "Copied to out5"),
        Variable::input("in6", 0.0, "Copied to out6"),
        Variable::input("in7", 0.0, "Copied to out7"),
        Variable::input("in8", 0.0, "Copied to out8"),
        Variable::input("in9", 0.0, "Copied to out9"),
        Variable::input("in10", 0.0, "Copied to out10"),
    ];
    OUT: Reals<10> = [
        Variable::output("out1", "in1 held over the last step"),
        Variable::output("out2", "in2 held over the last step"),
        Variable::output("out3", "in3 held over the last step"),
        Variable::output("out4", "in4 held over the last step"),
        Variable::output("out5", "in5 held over the last step"),
        Variable::output("out6", "in6 held over the last step"),
        Variable::output("out7", "in7 held over the last step"),
        Variable::output("out8", "in8 held over the last step"),
        Variable::output("out9", "in9 held over the last step"),
        Variable::output("out10", "in10 held over the last step"),
    ];
}

pub static INFO: ModelInfo = ModelInfo {
    identifier: "PassThrough",
    description: "Test-only model that copies its inputs to its outputs on each step",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment {
        start_time: 0.0,
        stop_time: 1.0,
        step_size: 1e-3,
    },
    // The outputs change only in fmi2DoStep: they start at 0 whatever the inputs.
    initial_dependencies: &[],
    initial_dependencies_on_some_paths: &[],
    create: |_: &Environment| Box::new(PassThrough),
};

const LAYOUT: StateLayout = StateLayout {
    model: "PassThrough",
    version: 1,
};

struct PassThrough;

impl Model for PassThrough {
    fn initialize(&mut self, _values: &mut Values, _start_time: f64) -> ModelResult {
        Ok(())
    }

    fn do_step(&mut self, values: &mut Values, _time: f64, _step: f64) -> ModelResult {
        OUT.set(values, &IN.vector(values));
        Ok(())
    }

    // No internal state: the saved state is the layout version alone.
    fn save_state(&self) -> Result<Vec<u8>, String> {
        encode_state(LAYOUT, &())
    }

    fn check_state(&self, bytes: &[u8], _time: f64) -> ModelResult {
        decode_state::<()>(LAYOUT, bytes)
    }

    fn restore_state(&mut self, bytes: &[u8], time: f64) -> ModelResult {
        self.check_state(bytes, time)
    }
}
