//! What a campaign measures on each run, computed where the run is (`contour-cosim batch
//! --metrics`), so a batch answers a row of numbers rather than its trajectory.
//!
//! The names and their meaning are the campaigns' (docs/campaigns.md, "Metrics"): a
//! quantity and a statistic, `contour_error.max`. Of the two-axis loop:
//! - `contour_error`: the exact distance from the plant's position to the interpolator's
//!   path (a built-in one: circle, line, arc, infinity, trident), by contour-core's
//!   [`TrueErrorIndex`];
//! - `estimated_contour_error`: |the controller's `contourError`|.
//!
//! Of the five-axis loop:
//! - `tip_error`, `orientation_error`: the distance and the angle from the plant's pose to
//!   the interpolator's reference tool path ([`tool_path_truth`]);
//! - `estimated_tip_error`, `estimated_orientation_error`: |the controller's
//!   `contourError.tip` and `.orientation`|.
//!
//! The units are the shipped loops': `interpolator`, `controller`, `plant`. Sample k of
//! n = steps is what the controller answered at t_k (row k + 1 of its columns, it has
//! stepped) and where the rest stood before the step from t_k (row k), as the fmpy engine
//! reads its trace. The geometry (the path's name, its `line.*`/`arc.*`, the machine's
//! pivots) is read from the interpolator once the run is done: the values the run used.

mod statistics;
pub mod tool_path_truth;

use contour_core::contour::planar::TrueErrorIndex;
use contour_core::geometry::{Vector, Vector2};
use contour_core::kinematics::{Joints, TableTiltingAc};
use contour_core::path::planar::{builtin, Path};
use contour_core::path::{CircularArc, Line};

use crate::simulation::Trace;
use crate::ssp::Value;
use crate::system::{Resolved, System};
use crate::{Error, Simulation};
use tool_path_truth::ReferenceToolPath;

/// A per-sample quantity.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Quantity {
    Contour,
    EstimatedContour,
    Tip,
    Orientation,
    EstimatedTip,
    EstimatedOrientation,
}

const QUANTITIES: [(&str, Quantity); 6] = [
    ("contour_error", Quantity::Contour),
    ("estimated_contour_error", Quantity::EstimatedContour),
    ("tip_error", Quantity::Tip),
    ("orientation_error", Quantity::Orientation),
    ("estimated_tip_error", Quantity::EstimatedTip),
    (
        "estimated_orientation_error",
        Quantity::EstimatedOrientation,
    ),
];

const JOINTS: [&str; 5] = ["X", "Y", "Z", "A", "C"];
const PIVOTS: [&str; 4] = ["pivot.A.y", "pivot.A.z", "pivot.C.x", "pivot.C.y"];
const LINE: [&str; 4] = ["line.x0", "line.y0", "line.x1", "line.y1"];
const ARC: [&str; 5] = ["arc.cx", "arc.cy", "arc.r", "arc.start", "arc.sweep"];

impl Quantity {
    /// The recorded columns it reads, as (unit, variable).
    fn columns(self) -> Vec<(&'static str, String)> {
        let joints = |unit, prefix: &str| -> Vec<(&'static str, String)> {
            JOINTS
                .iter()
                .map(|j| (unit, format!("{prefix}.{j}")))
                .collect()
        };
        match self {
            Quantity::Contour => vec![("plant", "pos.x".into()), ("plant", "pos.y".into())],
            Quantity::EstimatedContour => vec![("controller", "contourError".into())],
            Quantity::Tip | Quantity::Orientation => {
                [joints("interpolator", "ref"), joints("plant", "pos")].concat()
            }
            Quantity::EstimatedTip => vec![("controller", "contourError.tip".into())],
            Quantity::EstimatedOrientation => {
                vec![("controller", "contourError.orientation".into())]
            }
        }
    }

    /// The loop it is measured on.
    fn machine(self) -> &'static str {
        match self {
            Quantity::Contour | Quantity::EstimatedContour => "two-axis",
            _ => "five-axis",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Statistic {
    Max,
    Mean,
}

/// The metrics a batch computes on each run, with what they read resolved once.
pub struct Metrics {
    names: Vec<String>,
    wanted: Vec<(Quantity, Statistic)>,
    columns: Vec<(String, String)>,
    /// The interpolator's path and line/arc geometry, for `contour_error`.
    path: Option<PathVariables>,
    /// The interpolator's pivots, for the five-axis errors.
    pivots: Option<[Resolved; 4]>,
    /// The exact-distance index of the last two-axis path, kept for the next run.
    index: Option<(Path, TrueErrorIndex)>,
}

struct PathVariables {
    name: Resolved,
    line: [Resolved; 4],
    arc: [Resolved; 5],
}

impl Metrics {
    /// The metrics `names` of the loop `system`; refused when one is unknown or the loop
    /// lacks a unit or variable it reads.
    pub fn new(system: &System, names: &[String]) -> Result<Metrics, Error> {
        let known = || {
            QUANTITIES
                .iter()
                .flat_map(|(q, _)| [format!("{q}.max"), format!("{q}.mean")])
                .collect::<Vec<_>>()
                .join(", ")
        };
        let mut wanted = Vec::new();
        for name in names {
            let parsed = name.rsplit_once('.').and_then(|(quantity, statistic)| {
                let quantity = QUANTITIES.iter().find(|(q, _)| *q == quantity)?.1;
                let statistic = match statistic {
                    "max" => Statistic::Max,
                    "mean" => Statistic::Mean,
                    _ => return None,
                };
                Some((quantity, statistic))
            });
            let metric = parsed.ok_or_else(|| {
                Error::Refused(format!(
                    "--metrics: unknown metric {name:?} (known: {})",
                    known()
                ))
            })?;
            if wanted.contains(&metric) {
                return Err(Error::Refused(format!("--metrics: {name:?} named twice")));
            }
            wanted.push(metric);
        }
        if wanted.is_empty() {
            return Err(Error::Refused(format!(
                "--metrics: name at least one of {}",
                known()
            )));
        }
        let mut columns: Vec<(String, String)> = Vec::new();
        for (name, (quantity, _)) in names.iter().zip(&wanted) {
            let reads = quantity
                .columns()
                .into_iter()
                .map(|(u, v)| (u, v.to_string()));
            let geometry: &[&str] = match quantity {
                Quantity::Contour => &["path"],
                Quantity::Tip | Quantity::Orientation => &PIVOTS,
                _ => &[],
            };
            for (unit, variable) in
                reads.chain(geometry.iter().map(|v| ("interpolator", v.to_string())))
            {
                let refused = |why: String| {
                    Error::Refused(format!(
                        "--metrics {name}, a metric of the {} loop: {why}",
                        quantity.machine()
                    ))
                };
                let resolved = system
                    .resolve(unit, &variable)
                    .map_err(|e| refused(e.to_string()))?;
                // Lengths are measured in mm: the SI build's FMUs speak m.
                let declared = system.units[resolved.unit]
                    .fmu
                    .description
                    .variable(&variable)
                    .and_then(|v| v.unit.as_deref());
                if declared == Some("m") {
                    return Err(refused(format!(
                        "{unit}.{variable} is in m; the metrics are in mm and rad: run the \
                         loop of the mm build (target/fmu, not the SI build's target/fmu-si)"
                    )));
                }
            }
            for (unit, name) in quantity.columns() {
                let column = (unit.to_string(), name);
                if !columns.contains(&column) {
                    columns.push(column);
                }
            }
        }
        let needs = |quantities: &[Quantity]| wanted.iter().any(|(q, _)| quantities.contains(q));
        let path = if needs(&[Quantity::Contour]) {
            Some(PathVariables {
                name: system.resolve("interpolator", "path")?,
                line: interpolator_variables(system, LINE)?,
                arc: interpolator_variables(system, ARC)?,
            })
        } else {
            None
        };
        let pivots = if needs(&[Quantity::Tip, Quantity::Orientation]) {
            Some(interpolator_variables(system, PIVOTS)?)
        } else {
            None
        };
        Ok(Metrics {
            names: names.to_vec(),
            wanted,
            columns,
            path,
            pivots,
            index: None,
        })
    }

    /// The metrics' names, in the order of [`Metrics::compute`]'s values.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The columns a run must record for them, (unit, variable).
    pub fn columns(&self) -> &[(String, String)] {
        &self.columns
    }

    /// The metrics of the run just done by `simulation`, whose `trace` recorded
    /// [`Metrics::columns`] (among others). An error names what cannot be measured.
    pub fn compute(
        &mut self,
        trace: &Trace,
        simulation: &mut Simulation,
    ) -> Result<Vec<f64>, Error> {
        let n = trace.steps;
        if n == 0 {
            return Err(Error::Failed(
                "the run took no step: nothing to measure".into(),
            ));
        }
        let column = |unit: &str, name: &str| -> Vec<f64> {
            let all = trace
                .column(&format!("{unit}.{name}"))
                .expect("the metrics' columns are recorded");
            // The controller's answer to sample k is on the row after it.
            let first = usize::from(unit == "controller");
            all[first..first + n].to_vec()
        };
        let mut errors: Vec<(Quantity, Vec<f64>)> = Vec::new();
        let wanted: Vec<Quantity> = self.wanted.iter().map(|(q, _)| *q).collect();
        for quantity in wanted {
            if errors.iter().any(|(q, _)| *q == quantity) {
                continue;
            }
            match quantity {
                Quantity::Contour => {
                    let (x, y) = (column("plant", "pos.x"), column("plant", "pos.y"));
                    let distances = self.contour_errors(&x, &y, simulation)?;
                    errors.push((quantity, distances));
                }
                Quantity::Tip | Quantity::Orientation => {
                    let joints = |unit: &str, prefix: &str| -> Vec<Joints> {
                        let axes: Vec<Vec<f64>> = JOINTS
                            .iter()
                            .map(|j| column(unit, &format!("{prefix}.{j}")))
                            .collect();
                        (0..n)
                            .map(|k| Joints::from(std::array::from_fn(|j| axes[j][k])))
                            .collect()
                    };
                    let pivots = self.pivots.as_ref().expect("resolved with the metric");
                    let machine = machine(pivots, simulation)?;
                    let (tip, orientation) = tool_errors(
                        &machine,
                        &joints("interpolator", "ref"),
                        &joints("plant", "pos"),
                    )?;
                    errors.push((Quantity::Tip, tip));
                    errors.push((Quantity::Orientation, orientation));
                }
                estimated => {
                    let (unit, name) = estimated.columns().remove(0);
                    let values = column(unit, &name).iter().map(|v| v.abs()).collect();
                    errors.push((estimated, values));
                }
            }
        }
        Ok(self
            .wanted
            .iter()
            .map(|(quantity, statistic)| {
                let samples = &errors
                    .iter()
                    .find(|(q, _)| q == quantity)
                    .expect("computed above")
                    .1;
                match statistic {
                    Statistic::Max => statistics::max(samples),
                    Statistic::Mean => statistics::mean(samples),
                }
            })
            .collect())
    }

    /// The exact distances of the plant's positions to the interpolator's path.
    fn contour_errors(
        &mut self,
        x: &[f64],
        y: &[f64],
        simulation: &mut Simulation,
    ) -> Result<Vec<f64>, Error> {
        let variables = self.path.as_ref().expect("resolved with the metric");
        let path = interpolator_path(variables, simulation)?;
        if self.index.as_ref().map(|(p, _)| p) != Some(&path) {
            let index = TrueErrorIndex::new(&path);
            self.index = Some((path, index));
        }
        let (_, index) = self.index.as_ref().expect("just made");
        let mut hint = 0.0;
        Ok(x.iter()
            .zip(y)
            .map(|(&x, &y)| {
                let found = index.error(Vector2::new(x, y), hint);
                hint = found.u;
                found.error.abs()
            })
            .collect())
    }
}

/// The interpolator's variables `names`.
fn interpolator_variables<const N: usize>(
    system: &System,
    names: [&str; N],
) -> Result<[Resolved; N], Error> {
    let resolved: Vec<Resolved> = names
        .iter()
        .map(|name| system.resolve("interpolator", name))
        .collect::<Result<_, _>>()?;
    Ok(resolved.try_into().expect("one per name"))
}

/// The values of Real `variables` now.
fn reals<const N: usize>(
    simulation: &mut Simulation,
    variables: &[Resolved; N],
) -> Result<[f64; N], Error> {
    let mut values = [0.0; N];
    for (value, &variable) in values.iter_mut().zip(variables) {
        *value = match simulation.value(variable)? {
            Value::Real(v) => v,
            other => return Err(Error::Failed(format!("expected a Real, read {other:?}"))),
        };
    }
    Ok(values)
}

/// The interpolator's path, when it is a built-in one.
fn interpolator_path(
    variables: &PathVariables,
    simulation: &mut Simulation,
) -> Result<Path, Error> {
    let name = match simulation.value(variables.name)? {
        Value::String(name) => name,
        other => return Err(Error::Failed(format!("interpolator.path: read {other:?}"))),
    };
    let geometry = |e: contour_core::path::PathError| {
        Error::Failed(format!("contour_error: the interpolator's path: {e}"))
    };
    match name.trim().to_ascii_lowercase().as_str() {
        "line" => {
            let v = reals(simulation, &variables.line)?;
            Ok(Path::Line(
                Line::new([v[0], v[1]], [v[2], v[3]]).map_err(geometry)?,
            ))
        }
        "arc" => {
            let v = reals(simulation, &variables.arc)?;
            Ok(Path::Arc(
                CircularArc::new([v[0], v[1]], v[2], v[3], v[4]).map_err(geometry)?,
            ))
        }
        _ => builtin::by_name(&name).map_err(|_| {
            Error::Failed(format!(
                "contour_error.* needs a built-in path ({}), not {name:?}; use \
                 estimated_contour_error.* there",
                builtin::NAMES.join(", ")
            ))
        }),
    }
}

/// The machine of the interpolator's pivots.
fn machine(pivots: &[Resolved; 4], simulation: &mut Simulation) -> Result<TableTiltingAc, Error> {
    let v = reals(simulation, pivots)?;
    Ok(TableTiltingAc {
        a_pivot: Vector::<3>::new(0.0, v[0], v[1]),
        c_pivot: Vector::<3>::new(v[2], v[3], 0.0),
    })
}

/// Per sample: the tip's distance and the axis' angle to the reference tool path.
fn tool_errors(
    machine: &TableTiltingAc,
    reference: &[Joints],
    measured: &[Joints],
) -> Result<(Vec<f64>, Vec<f64>), Error> {
    let path = ReferenceToolPath::new(machine, reference);
    let mut tip = Vec::with_capacity(measured.len());
    let mut orientation = Vec::with_capacity(measured.len());
    for (k, q) in measured.iter().enumerate() {
        let error = path.error(machine, q, k, 0).ok_or_else(|| {
            Error::Failed(
                "tip_error: the reference never moved, so there is no tool path to measure \
                 against"
                    .into(),
            )
        })?;
        tip.push(error.tip);
        orientation.push(error.orientation);
    }
    Ok((tip, orientation))
}
