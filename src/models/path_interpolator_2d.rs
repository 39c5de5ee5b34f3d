//! `PathInterpolator2D`: the reference trajectory. Follows a line, an arc, the paper's
//! circle, the built-in `infinity` and `trident` NURBS or a NURBS file at a constant
//! feed, one sample every `Ts`; `ref.x`, `ref.y` hold the latest sample between samples.

use std::f64::consts::PI;

use super::axis_variables::REFERENCE_OUT;
use super::line_arc_parameters;
use super::path_parameter;
use crate::framework::model::{DefaultExperiment, Environment, Model, ModelInfo, ModelResult};
use crate::framework::sample_clock::{check_period, SampleClock};
use crate::framework::state_check;
use crate::framework::state_codec::{SavedState, StateLayout};
use crate::framework::variable_table::{axis_block, variable_table, Real, XY};
use crate::framework::variables::{Start, Values, Variable};
use contour_core::path::{CircularArc, Curve, Interpolator, Line, Path};

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
        "Feed rate along the path (> 0)",
    )
    .unit("mm/s");
    TS: Real = Variable::parameter(
        "Ts",
        Start::Real(1e-3),
        "Interpolation period (at least 1 us)",
    )
    .unit("s");
    GEOMETRY: Reals<{ line_arc_parameters::COUNT }> = line_arc_parameters::VARIABLES;
}

pub static INFO: ModelInfo = ModelInfo {
    identifier: "PathInterpolator2D",
    description:
        "Two-axis reference trajectory: a line, arc, circle or NURBS path sampled every Ts \
                  at a constant feed (second-order Taylor interpolation)",
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
    initial_dependencies_on_some_paths: &[],
    create: |environment: &Environment| {
        Box::new(PathInterpolator2D {
            environment: environment.clone(),
            state: None,
            warnings: Vec::new(),
        })
    },
};

/// Version 1: `Option<State>` as below.
const LAYOUT: StateLayout = StateLayout {
    model: "PathInterpolator2D",
    version: 1,
};

#[derive(Clone, serde::Serialize, serde::Deserialize)]
struct State {
    interpolator: Interpolator,
    clock: SampleClock,
}

impl SavedState for State {
    /// Checks a restored state like the parameters it was built from; the error names
    /// the offending value. (A NURBS path is validated by its own decoder.)
    fn validate(&self, time: f64) -> Result<(), String> {
        self.clock.validate_at(time)?;
        let it = &self.interpolator;
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
        match it.path() {
            Path::Line(l) => Line::new(l.start(), l.end())
                .map(drop)
                .map_err(|e| format!("interpolator path: {e}"))?,
            Path::Arc(a) => CircularArc::new(a.center(), a.radius(), a.start_angle(), a.sweep())
                .map(drop)
                .map_err(|e| format!("interpolator path: {e}"))?,
            // Both decoders check their paths as their constructors do.
            Path::Nurbs(_) | Path::Program(_) => {}
        }
        state_check::all_finite(self)?;
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
    path_parameter::path(PATH.get(values), values, GEOMETRY, environment)
}

impl PathInterpolator2D {
    fn write_outputs(&self, values: &mut Values) {
        if let Some(state) = &self.state {
            let sample = state.interpolator.current();
            REF.set(values, &sample.point);
            DONE.set(values, sample.done);
        }
    }
}

impl Model for PathInterpolator2D {
    fn initialize(&mut self, values: &mut Values, start_time: f64) -> ModelResult {
        let feed = positive(values, FEED)?;
        let ts = check_period("Ts", TS.get(values))?;
        let mut path = path(values, &self.environment)?;
        self.warnings = path_parameter::reader_warnings(&mut path);
        if let Path::Program(_) = path {
            self.warnings.push(
                "parameter 'path': the program runs at the constant 'feed': its F words, \
                 rapids and corner modes are read but not yet planned"
                    .to_string(),
            );
        }
        let interpolator = Interpolator::new(path, feed, ts).map_err(|e| e.to_string())?;
        self.state = Some(State {
            interpolator,
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
            state.interpolator.step();
        }
        self.write_outputs(values);
        Ok(())
    }

    crate::framework::state_codec::sampled_state_methods!(State, LAYOUT);
}

#[cfg(test)]
mod tests {
    use super::*;
    use contour_core::path::builtin;

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
}
