//! `PathInterpolator5X`: the five-axis reference. The tool tip follows a built-in path, a
//! two-curve JSON file or APT CL data at a constant feed, one sample every `Ts`, the tool
//! axis the path's at that point; the machine's inverse kinematics give the joints
//! (docs/design/five-axis.md §5.3a, §5.1). `ref.X` … `ref.C` hold the latest sample between
//! samples.

use std::path::Path;

use super::axis_variables::REFERENCE_OUT;
use super::kinematics_parameters;
use crate::framework::model::{DefaultExperiment, Environment, Model, ModelInfo, ModelResult};
use crate::framework::sample_clock::{check_period, SampleClock};
use crate::framework::state_codec::{SavedState, StateLayout};
use crate::framework::variable_table::{axis_block, variable_table, XYZAC};
use crate::framework::variables::{Start, Values, Variable};
use contour_core::kinematics::TableTiltingAc;
use contour_core::path::JointReference;
use contour_core::path::{ToolPath, BUILTIN_TOOL_PATHS};

variable_table! {
    static VARIABLES;
    REF: Reals<5> = axis_block(&XYZAC, &[REFERENCE_OUT]);
    DONE: Bool = Variable::discrete_output(
        "done",
        Start::Boolean(false),
        "The end of the path has been reached",
    );
    PATH: Str = Variable::parameter(
        "path",
        Start::String("tilted_helix"),
        "tilted_helix or figure_eight (built-in), or a file: APT CL data (.cl, .apt: \
         GOTO/x,y,z,i,j,k records) or a two-curve JSON file (.json); absolute, or relative \
         to the FMU's resources folder, which holds the example CL part blade.cl",
    );
    FEED: Real = Variable::parameter(
        "feed",
        Start::Real(50.0),
        "Tool-tip feed rate along the path (> 0)",
    )
    .unit("mm/s");
    TS: Real = Variable::parameter(
        "Ts",
        Start::Real(1e-3),
        "Interpolation period (at least 1 us)",
    )
    .unit("s");
    MACHINE: Reals<{ kinematics_parameters::COUNT }> = kinematics_parameters::VARIABLES;
}

pub static INFO: ModelInfo = ModelInfo {
    identifier: "PathInterpolator5X",
    description: "Five-axis reference trajectory: a tool-tip path with its tool axis \
                  (built-in, JSON or APT CL data) sampled every Ts at a constant tip feed, \
                  mapped to X Y Z A C by the inverse kinematics of an A-C trunnion table",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment {
        start_time: 0.0,
        stop_time: 5.5,
        step_size: 1e-3,
    },
    // The first sample is the path's start pose through the inverse kinematics: it
    // depends on the path and the machine; feed and Ts only matter from the first step on.
    initial_dependencies: &[
        (REF.at(0).vr(), &X_KNOWNS),
        (REF.at(1).vr(), &YZ_KNOWNS),
        (REF.at(2).vr(), &YZ_KNOWNS),
        (REF.at(3).vr(), &[PATH.vr()]),
        (REF.at(4).vr(), &[PATH.vr()]),
    ],
    create: |environment: &Environment| {
        Box::new(PathInterpolator5X {
            environment: environment.clone(),
            state: None,
            warnings: Vec::new(),
        })
    },
};

/// X, Y, Z at the start: the path's start pose turned by the start A and C about the
/// pivots. A turns about an axis along x, so X does not see the A pivot; Y and Z see
/// both.
const X_KNOWNS: [usize; 3] = [PATH.vr(), MACHINE.at(2).vr(), MACHINE.at(3).vr()];
const YZ_KNOWNS: [usize; 5] = [
    PATH.vr(),
    MACHINE.at(0).vr(),
    MACHINE.at(1).vr(),
    MACHINE.at(2).vr(),
    MACHINE.at(3).vr(),
];

/// Version 1: `Option<State>` as below, the path saved twice (with the interpolator's
/// copy of its tip curve) and a built-in's poses in full. Version 2: the path once, a
/// built-in by name (see `JointReference`'s saved form).
const LAYOUT: StateLayout = StateLayout {
    model: "PathInterpolator5X",
    version: 2,
};

#[derive(Clone, serde::Serialize, serde::Deserialize)]
struct State {
    reference: JointReference,
    clock: SampleClock,
}

impl SavedState for State {
    fn validate(&self, time: f64) -> Result<(), String> {
        self.clock.validate_at(time)?;
        // Not `state_check::all_finite`: it names every float of the path, megabytes of
        // text for a built-in; the path checked itself when decoded, and `check` covers
        // the rest.
        self.reference
            .check(self.clock.period())
            .map_err(|e| format!("reference: {e}"))
    }
}

pub struct PathInterpolator5X {
    environment: Environment,
    /// `None` until initialized.
    state: Option<State>,
    warnings: Vec<String>,
}

/// The reference on the path the `path` parameter names (files relative to the resources
/// folder), with the CL reader's warnings; errors name the file and line.
fn joint_reference(
    spec: &str,
    environment: &Environment,
    machine: TableTiltingAc,
    feed: f64,
    ts: f64,
) -> Result<(JointReference, Vec<String>), String> {
    let spec = spec.trim();
    let message = |e: contour_core::path::PathError| format!("parameter 'path': {e}");
    let file = Path::new(spec);
    // A bare name is a built-in (the error lists them); anything else is a file.
    let bare = file.extension().is_none() && !spec.contains(['/', '\\']);
    if BUILTIN_TOOL_PATHS.contains(&spec) || bare {
        return JointReference::builtin(spec, machine, feed, ts)
            .map(|r| (r, Vec::new()))
            .map_err(message);
    }
    let full = match environment.resource_dir.as_deref() {
        Some(dir) if file.is_relative() && !file.exists() => dir.join(file),
        _ => file.to_path_buf(),
    };
    let (path, warnings) = ToolPath::load(&full.to_string_lossy()).map_err(|e| {
        let e = message(e);
        let hint = super::path_interpolator_2d::resource_hint(spec, environment, &e);
        e + hint
    })?;
    // The file read, but its path cannot be followed: say which file.
    let reference = JointReference::new(path, machine, feed, ts).map_err(|e| match e {
        contour_core::path::PathError::Invalid(m) => format!("parameter 'path': {spec}: {m}"),
        other => message(other),
    })?;
    Ok((reference, warnings))
}

impl Model for PathInterpolator5X {
    fn initialize(&mut self, values: &mut Values, start_time: f64) -> ModelResult {
        let feed = FEED.get(values);
        // Finite by the variable's check; NaN never reaches here.
        if feed <= 0.0 {
            return Err(format!("parameter 'feed' must be > 0 (got {feed})"));
        }
        let ts = check_period("Ts", TS.get(values))?;
        let machine = kinematics_parameters::machine(values, MACHINE);
        let (reference, warnings) =
            joint_reference(PATH.get(values), &self.environment, machine, feed, ts)?;
        self.warnings = warnings
            .into_iter()
            .map(|w| format!("parameter 'path': {w}"))
            .collect();
        self.state = Some(State {
            reference,
            clock: SampleClock::new(start_time, ts),
        });
        self.write_outputs(values);
        Ok(())
    }

    fn take_warnings(&mut self) -> Vec<String> {
        std::mem::take(&mut self.warnings)
    }

    fn do_step(&mut self, values: &mut Values, time: f64, step: f64) -> ModelResult {
        let state = self.state.as_mut().ok_or("not initialized")?;
        // Every pose of a checked path has a unit axis, which the inverse kinematics always
        // solve; were one refused, the outputs would keep the last joints reached.
        while state.clock.take_until(time + step) {
            state
                .reference
                .step()
                .map_err(|e| format!("reference at t = {time}: {e}"))?;
        }
        self.write_outputs(values);
        Ok(())
    }

    crate::framework::state_codec::sampled_state_methods!(State, LAYOUT);
}

impl PathInterpolator5X {
    fn write_outputs(&self, values: &mut Values) {
        if let Some(state) = &self.state {
            let sample = state.reference.current();
            REF.set(values, &sample.joints);
            DONE.set(values, sample.done);
        }
    }
}
