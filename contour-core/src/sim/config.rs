//! What a closed-loop run depends on, the presets of the built-in paths, and why a
//! configuration can be refused.

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::contour::planar::EstimatorKind;
use crate::control::{CccMode, ConfigError, ControllerConfig};
use crate::path::planar::{builtin, Path};
use crate::path::PathError;
use crate::plant::{AxisParams, ServoAxesParams};

/// The paper's circle feed, mm/s: at 10π the built-in `circle` is x = 10 cos πt − 10,
/// y = 10 sin πt, one turn in 2 s.
pub const PAPER_CIRCLE_FEED: f64 = 10.0 * std::f64::consts::PI;

/// Feed used for the built-in free curves (`infinity`, `trident`, `line`, `arc`), mm/s.
/// 50 mm/s gives a following error of 50/28.5 ≈ 1.75 mm and at the trident's 4.2 mm
/// minimum radius an acceleration of 0.6 m/s² (≈ 4 A of drive current): well inside what
/// the test plant does linearly, yet fast enough that the curvature makes contour error.
pub const FREE_CURVE_FEED: f64 = 50.0;

/// The feed a path is run at unless one is given: [`PAPER_CIRCLE_FEED`] for a full
/// circle (the paper's experiment), [`FREE_CURVE_FEED`] for anything else. Decided on the
/// path itself, not on how it was named, so `circle`, `Circle` and its mirror agree.
pub fn preset_feed(path: &Path) -> f64 {
    if matches!(path, Path::Arc(a) if a.is_full_circle()) {
        PAPER_CIRCLE_FEED
    } else {
        FREE_CURVE_FEED
    }
}

/// Refuses runs longer than this many samples (a feed too small for the path).
pub const MAX_SAMPLES: usize = 50_000_000;

/// Everything a closed-loop run depends on.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SimConfig<const D: usize = 2, P = Path> {
    /// The reference path; the plant starts at rest at its start point.
    pub path: P,
    /// Feed, mm/s (> 0 unless `duration` is set).
    pub feed: f64,
    /// Sample period of interpolator, controller and plant, s. Overrides `controller.ts`
    /// so the two can never disagree.
    pub ts: f64,
    /// Plant parameters, one servo axis per dimension.
    pub plant: ServoAxesParams<D>,
    /// Controller configuration (`ts` ignored, see above).
    pub controller: ControllerConfig<D>,
    /// Contour estimator the controller runs.
    pub estimator: EstimatorKind,
    /// Seconds simulated after the interpolator reaches the path end (≥ 0).
    pub settle: f64,
    /// Fixed run length, s: when set, replaces "path end + settle".
    pub duration: Option<f64>,
    /// Start-up time excluded from the `settled_*` metrics, s. Default 0.2 s: the axis
    /// loops start at rest behind a reference that jumps to full feed, and their lag
    /// builds up with time constant 1/Kpp = 35 ms; after ~6 of them only the path's own
    /// contour error is left.
    pub transient: f64,
    /// |true contour error| (mm) above which the run counts as diverged. Default 10 mm,
    /// far above anything a stable loop produces on the built-in paths.
    pub abort_error: f64,
}

impl<const D: usize, P> SimConfig<D, P> {
    /// `path` at `feed` with the defaults: Ts = 1 ms, the paper's axis on every axis, the
    /// default controller (fuzzy-PID CCC), the free-curve estimator (planar paths), no
    /// settle time.
    pub fn new(path: P, feed: f64) -> Self {
        SimConfig {
            path,
            feed,
            ts: 1e-3,
            plant: ServoAxesParams::uniform(AxisParams::PAPER),
            controller: ControllerConfig::default(),
            estimator: EstimatorKind::FreeCurve,
            settle: 0.0,
            duration: None,
            transient: 0.2,
            abort_error: 10.0,
        }
    }

    /// The same run with another plant (e.g. [`XyTableParams::mismatched`]).
    pub fn with_plant(mut self, plant: ServoAxesParams<D>) -> Self {
        self.plant = plant;
        self
    }

    /// The same run with another CCC mode (the rest of the controller kept).
    pub fn with_mode(mut self, mode: CccMode) -> Self {
        self.controller.ccc.mode = mode;
        self
    }

    /// The controller configuration actually used (`ts` taken from the run).
    pub fn effective_controller(&self) -> ControllerConfig<D> {
        ControllerConfig {
            ts: self.ts,
            ..self.controller
        }
    }
}

impl SimConfig {
    /// The paper's experiment: the circle at 10π mm/s (2 s), paper plant, defaults.
    pub fn paper_circle() -> Self {
        Self::new(Path::Arc(builtin::circle()), PAPER_CIRCLE_FEED)
    }

    /// A built-in path by name at its [`preset_feed`].
    pub fn builtin(name: &str) -> Result<Self, PathError> {
        let path = builtin::by_name(name)?;
        let feed = preset_feed(&path);
        Ok(Self::new(path, feed))
    }
}

/// Why a configuration cannot be simulated.
#[derive(Clone, Debug, PartialEq)]
pub enum SimError {
    /// Feed or sample period rejected by the interpolator.
    Path(PathError),
    /// Controller configuration rejected.
    Controller(ConfigError),
    /// Plant parameters rejected; the message names the field.
    Plant(String),
    /// A run parameter (`settle`, `duration`, `transient`, `abort_error`, `feed`) rejected.
    Invalid(String),
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SimError::Path(e) => write!(f, "{e}"),
            SimError::Controller(e) => write!(f, "{e}"),
            SimError::Plant(m) => write!(f, "invalid plant: {m}"),
            SimError::Invalid(m) => write!(f, "invalid simulation: {m}"),
        }
    }
}

impl std::error::Error for SimError {}

impl From<PathError> for SimError {
    fn from(e: PathError) -> Self {
        SimError::Path(e)
    }
}

impl From<ConfigError> for SimError {
    fn from(e: ConfigError) -> Self {
        SimError::Controller(e)
    }
}
