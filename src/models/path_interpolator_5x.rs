//! `PathInterpolator5X`: the five-axis reference. The tool follows a built-in path, a
//! two-curve JSON file or APT CL data, one sample every `Ts`. With `accel` > 0 (the
//! default) the reference is planned at initialization within the machine's limits:
//! the branch and turn of the rotary axes chosen over the whole path, the feed within
//! every joint's velocity and acceleration and the tip's acceleration, a jerk filter
//! (docs/design/five-axis.md §5.3b). With `accel` = 0 the tip moves at the constant feed
//! and the joints come from the inverse kinematics on the A ≥ 0 branch, as before limits
//! (§5.3a, §5.1). `ref.X` … `ref.C` hold the latest sample between samples.

use std::path::Path;

use super::axis_variables::{REFERENCE_ACCELERATION_OUT, REFERENCE_OUT, REFERENCE_VELOCITY_OUT};
use super::{joint_limits_parameters, kinematics_parameters, path_parameter};
use crate::framework::model::{DefaultExperiment, Environment, Model, ModelInfo, ModelResult};
use crate::framework::sample_clock::{check_period, SampleClock};
use crate::framework::saved_state::{RestoredState, StateLayout};
use crate::framework::variable_table::{axis_block, variable_table, XYZAC};
use crate::framework::variables::{Start, Values, Variable};
use contour_core::limits::PathLimits;
use contour_core::part_program::gcode::GcodeOptions;
use contour_core::part_program::{file_kind, FileKind};
use contour_core::path::five_axis::{
    load_program, program_feeds, FeedChange, FiveAxisInputs, FiveAxisReference,
    SavedFiveAxisReference, ToolPath, BUILTIN_TOOL_PATHS,
};

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
        "tilted_helix or figure_eight (built-in), or a file: APT CL data (.cl, .apt, NX .cls, \
         CATIA .aptsource, Creo .ncl: GOTO/x,y,z,i,j,k records), a three-axis G-code program \
         (.ngc, .nc, .gcode, .tap; the tool axis vertical) or a two-curve JSON file (.json); \
         absolute, or relative to the FMU's resources folder, which holds the example CL part \
         blade.cl",
    );
    FEED: Real = Variable::parameter(
        "feed",
        Start::Real(50.0),
        "Tool-tip feed rate along the path (> 0): the greatest, where the plan allows it; \
         a CL file's FEDRAT wins from its first one on",
    )
    .unit("mm/s");
    TS: Real = Variable::parameter(
        "Ts",
        Start::Real(1e-3),
        "Interpolation period (at least 1 us)",
    )
    .unit("s");
    MACHINE: Reals<{ kinematics_parameters::COUNT }> = kinematics_parameters::VARIABLES;
    ACCEL: Real = Variable::parameter(
        "accel",
        Start::Real(2000.0),
        "Greatest tool-tip acceleration, tangential and centripetal (0: no plan, the tip \
         at constant feed)",
    )
    .unit("mm/s2")
    .min(0.0);
    JERK: Real = Variable::parameter(
        "jerk",
        Start::Real(1e5),
        "Greatest tool-tip jerk (0: no jerk limit)",
    )
    .unit("mm/s3")
    .min(0.0);
    TOLERANCE: Real = Variable::parameter(
        "tolerance",
        Start::Real(0.005),
        "How far the planned tool tip may leave the programmed path",
    )
    .unit("mm")
    .min(0.0);
    ORIENTATION_TOLERANCE: Real = Variable::parameter(
        "orientationTolerance",
        Start::Real(2e-3),
        "How far the planned tool axis may leave the programmed one",
    )
    .unit("rad")
    .min(0.0);
    POLE_CONE: Real = Variable::parameter(
        "poleCone",
        Start::Real(2.0 * std::f64::consts::PI / 180.0),
        "Half-angle of the cone about the C axis within which C's turn is planned",
    )
    .unit("rad")
    .min(0.0);
    LIMITS: Reals<{ joint_limits_parameters::COUNT }> = joint_limits_parameters::VARIABLES;
    DURATION: Real = Variable::output(
        "plannedDuration",
        "Duration of the planned reference, from the start to rest at the end (0 without \
         a plan)",
    )
    .unit("s");
    TIP_DEVIATION: Real = Variable::output(
        "deviation.tip",
        "Distance of the reference's tool tip from the programmed path",
    )
    .unit("mm");
    ORIENTATION_DEVIATION: Real = Variable::output(
        "deviation.orientation",
        "Angle between the reference's tool axis and the programmed one",
    )
    .unit("rad");
    VREF: Reals<5> = axis_block(&XYZAC, &[REFERENCE_VELOCITY_OUT]);
    AREF: Reals<5> = axis_block(&XYZAC, &[REFERENCE_ACCELERATION_OUT]);
    // Last, so that the value references of the variables before it stay as they were.
    RAPID: Real = Variable::parameter(
        "rapid",
        Start::Real(100.0),
        "Tool-tip speed of a CL file's RAPID moves with a plan (> 0)",
    )
    .unit("mm/s");
    DIALECT: Int = path_parameter::DIALECT;
    OPTIONAL_STOP: Bool = path_parameter::OPTIONAL_STOP;
    HOME: Reals<3> = path_parameter::HOME;
    TOOL_RADII: Str = path_parameter::TOOL_RADII;
}

/// The G-code reader's parameters.
const READER: path_parameter::ReaderParameters = path_parameter::ReaderParameters {
    dialect: DIALECT,
    optional_stop: OPTIONAL_STOP,
    home: HOME,
    tools: TOOL_RADII,
};

pub static INFO: ModelInfo = ModelInfo {
    identifier: "PathInterpolator5X",
    description: "Five-axis reference trajectory: a tool-tip path with its tool axis \
                  (built-in, JSON or APT CL data) on an A-C trunnion table, planned within \
                  the machine's travel, velocity, acceleration and jerk limits (branch of \
                  A and C chosen over the whole path) and sampled every Ts; accel = 0: at \
                  constant tip feed",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment {
        start_time: 0.0,
        stop_time: 5.5,
        step_size: 1e-3,
    },
    // The first sample is the path's start pose through the inverse kinematics: it
    // depends on the path and the machine; feed and Ts only matter from the first step
    // on. With a plan, a path that starts near the pole or that the A ≥ 0 branch cannot
    // drive starts where the plan's choice of branch and turn puts it (the travel, the
    // rotary speeds that weigh the choice, the pole's cone and tolerance). The planned
    // duration depends on everything, each limit where it binds.
    initial_dependencies: &[
        (REF.at(0).vr(), &X_KNOWNS),
        (REF.at(1).vr(), &YZ_KNOWNS),
        (REF.at(2).vr(), &YZ_KNOWNS),
        (REF.at(3).vr(), &[PATH.vr()]),
        (REF.at(4).vr(), &[PATH.vr()]),
        (DURATION.vr(), &[PATH.vr(), FEED.vr()]),
        (ORIENTATION_DEVIATION.vr(), &[PATH.vr()]),
    ],
    initial_dependencies_on_some_paths: &[
        (REF.at(0).vr(), &ROTARY_KNOWNS),
        (REF.at(1).vr(), &ROTARY_KNOWNS),
        (REF.at(2).vr(), &ROTARY_KNOWNS),
        (REF.at(3).vr(), &ROTARY_KNOWNS),
        (REF.at(4).vr(), &ROTARY_KNOWNS),
        (DURATION.vr(), &ALL_KNOWNS),
        (TIP_DEVIATION.vr(), &ALL_KNOWNS),
        (ORIENTATION_DEVIATION.vr(), &ALL_KNOWNS),
        // The first sample's central differences: the second sample depends on everything.
        (VREF.at(0).vr(), &ALL_KNOWNS),
        (VREF.at(1).vr(), &ALL_KNOWNS),
        (VREF.at(2).vr(), &ALL_KNOWNS),
        (VREF.at(3).vr(), &ALL_KNOWNS),
        (VREF.at(4).vr(), &ALL_KNOWNS),
        (AREF.at(0).vr(), &ALL_KNOWNS),
        (AREF.at(1).vr(), &ALL_KNOWNS),
        (AREF.at(2).vr(), &ALL_KNOWNS),
        (AREF.at(3).vr(), &ALL_KNOWNS),
        (AREF.at(4).vr(), &ALL_KNOWNS),
    ],
    create: |environment: &Environment| {
        Box::new(PathInterpolator5X {
            environment: environment.clone(),
            state: None,
            warnings: Vec::new(),
        })
    },
};

/// What the start A and C may depend on besides the path: the plan's branch choice.
const ROTARY_KNOWNS: [usize; 10] = [
    ACCEL.vr(),
    ORIENTATION_TOLERANCE.vr(),
    POLE_CONE.vr(),
    LIMITS.at(0).vr(),
    LIMITS.at(1).vr(),
    LIMITS.at(2).vr(),
    LIMITS.at(3).vr(),
    LIMITS.at(7).vr(),
    LIMITS.at(8).vr(),
    PATH.vr(),
];
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
/// Every parameter: the path and those after it, up to the outputs that end the table.
const KNOWN_COUNT: usize = 8 + kinematics_parameters::COUNT + joint_limits_parameters::COUNT;
const _: () =
    assert!(PATH.vr() + KNOWN_COUNT == LIMITS.at(joint_limits_parameters::COUNT - 1).vr() + 1);
/// …and `rapid`, which came later.
const ALL_KNOWNS: [usize; KNOWN_COUNT + 1] = {
    let mut all = [0; KNOWN_COUNT + 1];
    let mut i = 0;
    while i < KNOWN_COUNT {
        all[i] = PATH.vr() + i;
        i += 1;
    }
    all[KNOWN_COUNT] = RAPID.vr();
    all
};

/// Version 1: `Option<State>` as below, the path saved twice (with the interpolator's
/// copy of its tip curve) and a built-in's poses in full. Version 2: the path once, a
/// built-in by name (see `JointReference`'s saved form). Version 3: the reference is
/// constant-feed or planned (a plan saved as its inputs and the place on it). Version 4:
/// the reference keeps the previous sample's joints (`vref.*`'s central difference).
/// Version 5: a plan's inputs carry the program's speeds move by move. Version 6: a plan
/// is saved with its inputs' fingerprint and the plan's summary, checked on restore.
const LAYOUT: StateLayout = StateLayout {
    model: "PathInterpolator5X",
    version: 6,
};

#[derive(Clone, serde::Serialize)]
struct State {
    reference: FiveAxisReference,
    clock: SampleClock,
}

/// A saved [`State`] as read back (the same layout), before its reference is planned
/// again through the instance's planner.
#[derive(serde::Deserialize)]
struct SavedStateData {
    reference: SavedFiveAxisReference,
    clock: SampleClock,
}

impl RestoredState for State {
    type Saved = SavedStateData;

    /// The saved reference on the plan the instance's planner keeps or makes again, its
    /// place checked against it.
    fn restore(
        saved: SavedStateData,
        time: f64,
        environment: &Environment,
    ) -> Result<Self, String> {
        saved.clock.validate_at(time)?;
        let reference = saved
            .reference
            .resume(&environment.planner)
            .map_err(|e| format!("reference: {e}"))?;
        // Not `saved_state::all_finite`: it names every float of the path, megabytes of
        // text for a built-in; the path checked itself when decoded, and `check` covers
        // the rest (a plan checked its place when restored).
        reference
            .check(saved.clock.period())
            .map_err(|e| format!("reference: {e}"))?;
        Ok(State {
            reference,
            clock: saved.clock,
        })
    }
}

pub struct PathInterpolator5X {
    environment: Environment,
    /// `None` until initialized.
    state: Option<State>,
    warnings: Vec<String>,
}

/// The programmed path the `path` parameter names (files relative to the resources
/// folder): the path, a built-in's name, the CL lines of its poses, the reader's
/// warnings; errors name the file and line.
struct Programmed {
    path: ToolPath,
    builtin: Option<String>,
    /// A CL file's speeds move by move.
    feeds: Vec<FeedChange>,
    lines: Option<(String, Vec<usize>)>,
    warnings: Vec<String>,
}

/// `speeds`: the `feed` and `rapid` parameters, a part program's speeds before its first
/// feed word and at its rapids; G-code is read with `options`.
fn programmed(
    spec: &str,
    speeds: (f64, f64),
    options: &GcodeOptions,
    environment: &Environment,
) -> Result<Programmed, String> {
    let spec = spec.trim();
    let message = |e: contour_core::path::PathError| format!("parameter 'path': {e}");
    let file = Path::new(spec);
    // A bare name is a built-in (the error lists them); anything else is a file.
    let bare = file.extension().is_none() && !spec.contains(['/', '\\']);
    if BUILTIN_TOOL_PATHS.contains(&spec) || bare {
        return Ok(Programmed {
            path: ToolPath::builtin(spec).map_err(message)?,
            builtin: Some(spec.to_owned()),
            feeds: Vec::new(),
            lines: None,
            warnings: Vec::new(),
        });
    }
    let full = match environment.resource_dir.as_deref() {
        Some(dir) if file.is_relative() && !file.exists() => dir.join(file),
        _ => file.to_path_buf(),
    };
    let hint = |e: String| {
        let h = super::path_parameter::resource_hint(spec, environment, &e);
        e + h
    };
    if matches!(file_kind(file), Some(FileKind::ClData | FileKind::GCode)) {
        // Read here rather than through ToolPath::load: the plan names the program's lines.
        let program = load_program(&full, options).map_err(|e| hint(message(e)))?;
        let path = ToolPath::from_poses(&program.poses()).map_err(message)?;
        return Ok(Programmed {
            path,
            builtin: None,
            feeds: program_feeds(&program, speeds.0, speeds.1),
            lines: Some((spec.to_owned(), program.lines())),
            warnings: program.warning_lines(),
        });
    }
    let (path, warnings) = ToolPath::load(&full.to_string_lossy()).map_err(|e| hint(message(e)))?;
    Ok(Programmed {
        path,
        builtin: None,
        feeds: Vec::new(),
        lines: None,
        warnings,
    })
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
        let joints = joint_limits_parameters::joint_limits(values, LIMITS)?;
        let limits = PathLimits {
            feed,
            accel: ACCEL.get(values),
            jerk: JERK.get(values),
            tolerance: TOLERANCE.get(values),
            orientation_tolerance: ORIENTATION_TOLERANCE.get(values),
            pole_cone: POLE_CONE.get(values),
        };
        limits.check().map_err(|e| format!("plan: {e}"))?;
        let rapid = RAPID.get(values);
        if rapid <= 0.0 {
            return Err(format!("parameter 'rapid' must be > 0 (got {rapid})"));
        }
        let options = READER.options(values)?;
        let programmed = programmed(PATH.get(values), (feed, rapid), &options, &self.environment)?;
        let unplanned_speeds = limits.accel == 0.0 && !programmed.feeds.is_empty();
        let lines = &programmed.lines;
        let name = |i: usize| match lines {
            Some((file, lines)) => match lines.get(i) {
                Some(line) => format!("{file}:{line}"),
                None => format!("{file}: GOTO record {}", i + 1),
            },
            None => format!("pose {i} of the path"),
        };
        let inputs = FiveAxisInputs {
            path: programmed.path,
            builtin: programmed.builtin,
            feeds: programmed.feeds,
            machine,
            joints,
            limits,
            ts,
        };
        let reference = FiveAxisReference::new(inputs, &self.environment.planner, &name)
            // The file read, but its path cannot be followed: say which file.
            .map_err(|e| match e {
                contour_core::path::PathError::Invalid(m) => {
                    format!("parameter 'path': {}: {m}", PATH.get(values).trim())
                }
                other => format!("parameter 'path': {other}"),
            })?;
        self.warnings = programmed
            .warnings
            .into_iter()
            .map(|w| format!("parameter 'path': {w}"))
            .collect();
        if unplanned_speeds {
            self.warnings.push(
                "parameter 'path': with accel = 0 the tip runs at the constant 'feed' (the \
                 file's FEDRAT and RAPID speeds are not planned: set 'accel' > 0)"
                    .to_string(),
            );
        }
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

    crate::framework::saved_state::sampled_state_methods!(State, LAYOUT);
}

impl PathInterpolator5X {
    fn write_outputs(&mut self, values: &mut Values) {
        if let Some(state) = &mut self.state {
            let out = state.reference.current();
            REF.set(values, &out.joints);
            DONE.set(values, out.done);
            DURATION.set(values, state.reference.planned_duration().unwrap_or(0.0));
            let (velocity, acceleration) = state.reference.derivatives();
            VREF.set(values, &velocity);
            AREF.set(values, &acceleration);
            TIP_DEVIATION.set(values, out.tip_deviation);
            ORIENTATION_DEVIATION.set(values, out.orientation_deviation);
        }
    }
}
