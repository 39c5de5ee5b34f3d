//! `PathInterpolator2D`: the reference trajectory. Follows a line, an arc, the paper's
//! circle, the built-in `infinity` and `trident` NURBS, a NURBS file or a G-code program,
//! one sample every `Ts`; `ref.x`, `ref.y` hold the latest sample between samples. With
//! `accel` = 0 at the constant `feed` (the paper's interpolator); with `accel` > 0 a
//! program, a line or an arc is planned at initialization within the speeds, the
//! acceleration and the jerk, corners blended (docs/design/two-axis.md §4.9). For
//! feed-forward it gives the sample's velocity and acceleration and its look-ahead, the
//! mean acceleration over the coming period (§4.12b).

use std::f64::consts::PI;

use super::axis_variables::{
    ACCELERATION_AHEAD_OUT, REFERENCE_ACCELERATION_OUT, REFERENCE_OUT, REFERENCE_VELOCITY_OUT,
};
use super::{line_arc_parameters, path_parameter};
use crate::framework::model::{DefaultExperiment, Environment, Model, ModelInfo, ModelResult};
use crate::framework::sample_clock::{check_period, SampleClock};
use crate::framework::saved_state::{self, RestoredState, StateLayout};
use crate::framework::variable_table::{axis_block, variable_table, Real, XY};
use crate::framework::variables::{Start, Values, Variable};
use contour_core::path::planar::{Path, SavedXyReference, XyLimits, XyReference};
use contour_core::path::{Curve, Interpolator};

variable_table! {
    static VARIABLES;
    REF: Reals<2> = axis_block(&XY, &[REFERENCE_OUT]);
    DONE: Bool = Variable::discrete_output(
        "done",
        Start::Boolean(false),
        "The end of the path has been reached",
    );
    PATH: Str = Variable::parameter(
        "path",
        Start::String(path_parameter::DEFAULT),
        path_parameter::DESCRIPTION,
    );
    FEED: Real = Variable::parameter(
        "feed",
        Start::Real(10.0 * PI),
        "Feed rate along the path (> 0); with a plan, the speed of moves before a \
         program's first F word",
    )
    .unit("mm/s");
    TS: Real = Variable::parameter(
        "Ts",
        Start::Real(1e-3),
        "Interpolation period (at least 1 us)",
    )
    .unit("s");
    GEOMETRY: Reals<{ line_arc_parameters::COUNT }> = line_arc_parameters::VARIABLES;
    ACCEL: Real = Variable::parameter(
        "accel",
        Start::Real(0.0),
        "Greatest acceleration along the path, tangential and centripetal (0: no plan, \
         the constant feed)",
    )
    .unit("mm/s2")
    .min(0.0);
    JERK: Real = Variable::parameter(
        "jerk",
        Start::Real(1e5),
        "Greatest jerk of the planned reference (0: no jerk limit)",
    )
    .unit("mm/s3")
    .min(0.0);
    TOLERANCE: Real = path_parameter::TOLERANCE;
    RAPID: Real = Variable::parameter(
        "rapid",
        Start::Real(100.0),
        "Speed of a program's G0 moves with a plan (> 0)",
    )
    .unit("mm/s");
    FEED_RATE: Real = Variable::output(
        "feedRate",
        "Path speed of the reference (the constant feed without a plan)",
    )
    .unit("mm/s");
    DURATION: Real = Variable::output(
        "plannedDuration",
        "Time from the start to the end of the path (known after initialization)",
    )
    .unit("s");
    VREF: Reals<2> = axis_block(&XY, &[REFERENCE_VELOCITY_OUT]);
    AREF: Reals<2> = axis_block(&XY, &[REFERENCE_ACCELERATION_OUT]);
    DIALECT: Int = path_parameter::DIALECT;
    OPTIONAL_STOP: Bool = path_parameter::OPTIONAL_STOP;
    HOME: Reals<3> = path_parameter::HOME;
    TOOL_RADII: Str = path_parameter::TOOL_RADII;
    AHEAD: Reals<2> = axis_block(&XY, &[ACCELERATION_AHEAD_OUT]);
}

pub static INFO: ModelInfo = ModelInfo {
    identifier: "PathInterpolator2D",
    description:
        "Two-axis reference trajectory: a line, arc, circle, NURBS or G-code path sampled \
                  every Ts at a constant feed (second-order Taylor interpolation) or, with \
                  accel > 0, planned within the speeds, acceleration and jerk",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment {
        start_time: 0.0,
        stop_time: 2.0,
        step_size: 1e-3,
    },
    // The first sample is the path's start point: for `line` the line's start, for `arc`
    // the point at arc.start on the circle, otherwise fixed by the path name or file.
    // Feed and Ts only matter from the first step on; `done` starts false.
    initial_dependencies: &[
        (
            REF.at(0).vr(),
            &[
                PATH.vr(),
                GEOMETRY.at(line_arc_parameters::LINE_X0).vr(),
                GEOMETRY.at(line_arc_parameters::ARC_CX).vr(),
                GEOMETRY.at(line_arc_parameters::ARC_R).vr(),
                GEOMETRY.at(line_arc_parameters::ARC_START).vr(),
            ],
        ),
        (
            REF.at(1).vr(),
            &[
                PATH.vr(),
                GEOMETRY.at(line_arc_parameters::LINE_Y0).vr(),
                GEOMETRY.at(line_arc_parameters::ARC_CY).vr(),
                GEOMETRY.at(line_arc_parameters::ARC_R).vr(),
                GEOMETRY.at(line_arc_parameters::ARC_START).vr(),
            ],
        ),
    ],
    initial_dependencies_on_some_paths: &[
        // At rest with a plan, the feed without.
        (FEED_RATE.vr(), &[FEED.vr(), ACCEL.vr()]),
        (DURATION.vr(), &DURATION_KNOWNS),
        // The feed along the start's tangent without a plan, at rest with one.
        (VREF.at(0).vr(), &DURATION_KNOWNS),
        (VREF.at(1).vr(), &DURATION_KNOWNS),
        (AREF.at(0).vr(), &DURATION_KNOWNS),
        (AREF.at(1).vr(), &DURATION_KNOWNS),
        (AHEAD.at(0).vr(), &DURATION_KNOWNS),
        (AHEAD.at(1).vr(), &DURATION_KNOWNS),
    ],
    create: |environment: &Environment| {
        Box::new(PathInterpolator2D {
            environment: environment.clone(),
            state: None,
            warnings: Vec::new(),
        })
    },
};

/// What the planned duration depends on: the path and every limit.
const DURATION_KNOWNS: [usize; 16] = {
    let mut k = [0; 16];
    let head = [
        PATH.vr(),
        FEED.vr(),
        TS.vr(),
        ACCEL.vr(),
        JERK.vr(),
        TOLERANCE.vr(),
        RAPID.vr(),
    ];
    let mut i = 0;
    while i < head.len() {
        k[i] = head[i];
        i += 1;
    }
    while i < 16 {
        k[i] = GEOMETRY.at(i - head.len()).vr();
        i += 1;
    }
    k
};

/// Version 2: `Option<State>` as below (version 1 had the constant-feed interpolator
/// alone). Version 3: a program's moves carry their standstill (dwells, stops, Z alone).
const LAYOUT: StateLayout = StateLayout {
    model: "PathInterpolator2D",
    version: 3,
};

/// The G-code reader's parameters.
const READER: path_parameter::ReaderParameters = path_parameter::ReaderParameters {
    dialect: DIALECT,
    optional_stop: OPTIONAL_STOP,
    home: HOME,
    tools: TOOL_RADII,
};

/// The reference the parameters choose.
#[derive(Clone, serde::Serialize)]
#[allow(clippy::large_enum_variant)] // one per instance
enum Reference {
    /// `accel` = 0: the paper's constant-feed interpolator.
    ConstantFeed(Interpolator),
    /// `accel` > 0: the plan.
    Planned(XyReference),
}

#[derive(Clone, serde::Serialize)]
struct State {
    reference: Reference,
    clock: SampleClock,
}

/// A saved [`Reference`] as read back (the same layout): a plan's inputs, before the
/// instance's plan cache finds or makes the plan.
#[derive(serde::Deserialize)]
enum SavedReference {
    ConstantFeed(Interpolator),
    Planned(SavedXyReference),
}

/// A saved [`State`] as read back (the same layout).
#[derive(serde::Deserialize)]
struct SavedStateData {
    reference: SavedReference,
    clock: SampleClock,
}

impl RestoredState for State {
    type Saved = SavedStateData;

    /// The saved reference (a plan found in or made by the instance's cache), checked
    /// like the parameters it was built from.
    fn restore(
        saved: SavedStateData,
        time: f64,
        environment: &Environment,
    ) -> Result<Self, String> {
        let reference = match saved.reference {
            SavedReference::ConstantFeed(it) => Reference::ConstantFeed(it),
            SavedReference::Planned(planned) => Reference::Planned(
                planned
                    .resume(&environment.xy_plans)
                    .map_err(|e| format!("planned reference: {e}"))?,
            ),
        };
        let state = State {
            reference,
            clock: saved.clock,
        };
        state.validate(time)?;
        Ok(state)
    }
}

impl State {
    /// Checks a restored state like the parameters it was built from; the error names
    /// the offending value. (A NURBS path is validated by its own decoder.)
    fn validate(&self, time: f64) -> Result<(), String> {
        self.clock.validate_at(time)?;
        let it = match &self.reference {
            Reference::ConstantFeed(it) => it,
            // Planned again from its inputs when it was read: within its limits.
            Reference::Planned(planned) => {
                if planned.limits().ts != self.clock.period() {
                    return Err(format!(
                        "planned reference period {} s differs from the sample clock period {} s",
                        planned.limits().ts,
                        self.clock.period()
                    ));
                }
                return saved_state::all_finite(self);
            }
        };
        if !(it.feed().is_finite() && it.feed() >= 0.0) {
            return Err(format!(
                "interpolator feed {} mm/s must be finite and >= 0",
                it.feed()
            ));
        }
        if it.ts() != self.clock.period() {
            return Err(format!(
                "interpolator period {} s differs from the sample clock period {} s",
                it.ts(),
                self.clock.period()
            ));
        }
        it.path()
            .check()
            .map_err(|e| format!("interpolator path: {e}"))?;
        saved_state::all_finite(self)?;
        let (u0, u1) = it.path().param_range();
        if !(u0..=u1).contains(&it.parameter()) {
            return Err(format!(
                "interpolator parameter {} lies outside the path's [{u0}, {u1}]",
                it.parameter()
            ));
        }
        Ok(())
    }
}

pub struct PathInterpolator2D {
    environment: Environment,
    /// `None` until initialized.
    state: Option<State>,
    /// The path reader's warnings of the last initialization.
    warnings: Vec<String>,
}

fn positive(values: &Values, variable: Real) -> Result<f64, String> {
    let v = variable.get(values);
    if v > 0.0 {
        Ok(v)
    } else {
        let name = VARIABLES[variable.vr()].name;
        Err(format!("parameter '{name}' must be > 0 (got {v})"))
    }
}

/// The path the parameters describe; file errors name the file and line.
fn path(values: &Values, environment: &Environment) -> Result<Path, String> {
    path_parameter::path(PATH.get(values), values, GEOMETRY, READER, environment)
}

impl PathInterpolator2D {
    /// The outputs of the current sample. The planned duration is written once, at
    /// initialization: a path's length costs its whole length to measure, which a step
    /// must not.
    fn write_outputs(&self, values: &mut Values) {
        let Some(state) = &self.state else { return };
        let (point, done, speed, velocity, acceleration, next_velocity) = match &state.reference {
            Reference::ConstantFeed(it) => {
                let sample = it.current();
                let speed = if sample.done { 0.0 } else { it.feed() };
                (
                    sample.point,
                    sample.done,
                    speed,
                    it.velocity(),
                    it.acceleration(),
                    it.next_velocity(),
                )
            }
            Reference::Planned(planned) => {
                let (sample, next) = (planned.current(), planned.peek());
                (
                    sample.point,
                    planned.done(),
                    sample.speed,
                    sample.direction * sample.speed,
                    sample.acceleration,
                    next.direction * next.speed,
                )
            }
        };
        AHEAD.set(values, &((next_velocity - velocity) / state.clock.period()));
        REF.set(values, &point);
        VREF.set(values, &velocity);
        AREF.set(values, &acceleration);
        DONE.set(values, done);
        FEED_RATE.set(values, speed);
    }
}

impl Model for PathInterpolator2D {
    fn initialize(&mut self, values: &mut Values, start_time: f64) -> ModelResult {
        let feed = positive(values, FEED)?;
        let ts = check_period("Ts", TS.get(values))?;
        let mut path = path(values, &self.environment)?;
        self.warnings = path_parameter::reader_warnings(&mut path);
        let tolerance = TOLERANCE.get(values);
        let accel = ACCEL.get(values);
        let reference = if accel > 0.0 {
            let limits = XyLimits {
                feed,
                rapid: positive(values, RAPID)?,
                accel,
                jerk: JERK.get(values),
                tolerance,
                ts,
            };
            limits.validate().map_err(|e| format!("parameter {e}"))?;
            Reference::Planned(
                XyReference::planned_by(path, limits, &self.environment.xy_plans)
                    .map_err(|e| format!("parameter 'path': {e}"))?,
            )
        } else {
            if let Path::Program(_) = path {
                self.warnings.push(
                    "parameter 'path': with accel = 0 the program runs at the constant 'feed' \
                     (its F words, rapids and exact stops are not planned: set 'accel' > 0; its \
                     blended corners are rounded all the same)"
                        .to_string(),
                );
            }
            let path = path.blended(tolerance);
            Reference::ConstantFeed(Interpolator::new(path, feed, ts).map_err(|e| e.to_string())?)
        };
        let duration = match &reference {
            Reference::ConstantFeed(it) => it.path().length() / it.feed(),
            Reference::Planned(planned) => planned.duration(),
        };
        DURATION.set(values, duration);
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
        while state.clock.take_until(time + step) {
            match &mut state.reference {
                Reference::ConstantFeed(it) => {
                    it.step();
                }
                Reference::Planned(planned) => {
                    planned.step();
                }
            }
        }
        self.write_outputs(values);
        Ok(())
    }

    crate::framework::saved_state::sampled_state_methods!(State, LAYOUT);
}

#[cfg(test)]
mod tests {
    use super::*;
    use contour_core::path::planar::builtin;

    #[test]
    fn start_values_give_the_papers_circle_and_geometry_defaults_the_built_ins() {
        let mut values = Values::from_table(&VARIABLES);
        let env = Environment::default();
        assert_eq!(
            path(&values, &env).unwrap(),
            builtin::by_name("circle").unwrap()
        );
        for name in ["line", "arc"] {
            values.set(
                PATH.vr(),
                crate::framework::variables::Value::String(name.into()),
            );
            assert_eq!(
                path(&values, &env).unwrap(),
                builtin::by_name(name).unwrap()
            );
        }
    }

    /// A planned NURBS reference restored into a fresh instance of the same process
    /// finds the plan (none made again) and goes on bit for bit; the same state into an
    /// instance with a cache of its own plans once, alike.
    #[test]
    fn a_restored_plan_is_found_not_made_again() {
        use crate::framework::variables::Value;
        let env = Environment::default();
        let mut values = Values::from_table(&VARIABLES);
        values.set(PATH.vr(), Value::String("infinity".into()));
        values.set(ACCEL.vr(), Value::Real(2000.0));
        let mut a = (INFO.create)(&env);
        a.initialize(&mut values, 0.0).unwrap();
        for k in 0..100 {
            a.do_step(&mut values, k as f64 * 1e-3, 1e-3).unwrap();
        }
        assert_eq!(env.xy_plans.plans_made(), 1);
        let saved = a.save_state().unwrap();
        let mut b = (INFO.create)(&env);
        b.restore_state(&saved, 0.1).unwrap();
        assert_eq!(env.xy_plans.plans_made(), 1, "planned again");
        let elsewhere = Environment::default();
        let mut c = (INFO.create)(&elsewhere);
        c.restore_state(&saved, 0.1).unwrap();
        assert_eq!(elsewhere.xy_plans.plans_made(), 1);
        let (mut vb, mut vc) = (values.clone(), values.clone());
        for k in 100..200 {
            let t = k as f64 * 1e-3;
            a.do_step(&mut values, t, 1e-3).unwrap();
            b.do_step(&mut vb, t, 1e-3).unwrap();
            c.do_step(&mut vc, t, 1e-3).unwrap();
            assert!(values == vb && values == vc, "sample {k}");
        }
    }
}
