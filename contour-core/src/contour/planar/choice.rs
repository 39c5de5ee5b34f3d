//! The estimator the controller runs, chosen by name (`free_curve`, `line`, `arc`,
//! `program`), as one
//! serialisable enum so the FMU can save and restore it with the rest of its state.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::{
    ArcEstimator, FreeCurveEstimator, LineEstimator, ProgramEstimator, SavedProgramEstimator,
    TrueErrorIndexes,
};
use crate::contour::{ContourEstimate, ContourEstimator};
use crate::geometry::Vector2;
use crate::path::planar::Path;

/// Which estimator to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum EstimatorKind {
    /// Two-circle free-curve estimator (any path).
    FreeCurve,
    /// Exact line error (Koren).
    Line,
    /// Exact arc/circle error (Koren–Lo).
    Arc,
    /// Exact error along the whole programmed path, tracked (any path).
    Program,
}

impl EstimatorKind {
    /// All kinds, in FMI enumeration order (1, 2, 3, 4).
    pub const ALL: [EstimatorKind; 4] = [
        EstimatorKind::FreeCurve,
        EstimatorKind::Line,
        EstimatorKind::Arc,
        EstimatorKind::Program,
    ];

    /// Canonical name.
    pub fn as_str(self) -> &'static str {
        match self {
            EstimatorKind::FreeCurve => "free_curve",
            EstimatorKind::Line => "line",
            EstimatorKind::Arc => "arc",
            EstimatorKind::Program => "program",
        }
    }
}

impl fmt::Display for EstimatorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for EstimatorKind {
    type Err = String;
    /// Accepts `free_curve`, `free curve`, `freecurve`, `free-curve`, `line`, `arc`,
    /// `program` (case-insensitive).
    fn from_str(s: &str) -> Result<Self, String> {
        let k: String = s
            .trim()
            .to_ascii_lowercase()
            .chars()
            .filter(|c| !matches!(c, '_' | ' ' | '-'))
            .collect();
        match k.as_str() {
            "freecurve" => Ok(EstimatorKind::FreeCurve),
            "line" => Ok(EstimatorKind::Line),
            "arc" | "circle" => Ok(EstimatorKind::Arc),
            "program" => Ok(EstimatorKind::Program),
            _ => Err(format!(
                "unknown contour estimator '{s}': expected free_curve, line, arc or program"
            )),
        }
    }
}

/// A contour-error estimator of any kind.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Estimator {
    /// Two-circle free-curve estimator.
    FreeCurve(FreeCurveEstimator),
    /// Line estimator (fixed line or tracking direction).
    Line(LineEstimator),
    /// Arc estimator (fixed circle or tracking three-point circle).
    Arc(ArcEstimator),
    /// Exact error along the programmed path.
    Program(ProgramEstimator),
}

/// An [`Estimator`] as saved (the same bytes), read without building the `program`
/// estimator's index: [`SavedEstimator::resume`] finds it in a [`TrueErrorIndexes`].
#[derive(Deserialize)]
pub enum SavedEstimator {
    /// As [`Estimator::FreeCurve`].
    FreeCurve(FreeCurveEstimator),
    /// As [`Estimator::Line`].
    Line(LineEstimator),
    /// As [`Estimator::Arc`].
    Arc(ArcEstimator),
    /// As [`Estimator::Program`].
    Program(SavedProgramEstimator),
}

impl SavedEstimator {
    /// The estimator, a `program` one on the index `indexes` keeps or builds; refused
    /// (naming the value) when its track does not fit its path.
    pub fn resume(self, indexes: &TrueErrorIndexes) -> Result<Estimator, String> {
        Ok(match self {
            SavedEstimator::FreeCurve(e) => Estimator::FreeCurve(e),
            SavedEstimator::Line(e) => Estimator::Line(e),
            SavedEstimator::Arc(e) => Estimator::Arc(e),
            SavedEstimator::Program(e) => Estimator::Program(e.resume(indexes)?),
        })
    }
}

impl Estimator {
    /// [`Estimator::for_path`], a `program` estimator on the index `indexes` keeps or
    /// builds for `path` (instances on one path share it).
    pub fn for_path_shared(kind: EstimatorKind, path: &Path, indexes: &TrueErrorIndexes) -> Self {
        match kind {
            EstimatorKind::Program => Estimator::Program(ProgramEstimator::on(indexes.index(path))),
            _ => Estimator::for_path(kind, path),
        }
    }

    /// The estimator of `kind` for following `path`: the exact line/arc estimators use the
    /// path's own geometry when it is a line/arc; on other paths they fall back to the
    /// local line (direction of the last reference move) or the circle through the last
    /// three reference points, which is what those classic estimators do on free curves.
    /// The program estimator measures against the whole of `path`.
    pub fn for_path(kind: EstimatorKind, path: &Path) -> Self {
        match (kind, path) {
            (EstimatorKind::FreeCurve, _) => Estimator::FreeCurve(FreeCurveEstimator::default()),
            (EstimatorKind::Line, Path::Line(l)) => Estimator::Line(LineEstimator::new(l)),
            (EstimatorKind::Line, _) => Estimator::Line(LineEstimator::tracking()),
            (EstimatorKind::Arc, Path::Arc(a)) => Estimator::Arc(ArcEstimator::new(a)),
            (EstimatorKind::Arc, _) => Estimator::Arc(ArcEstimator::tracking()),
            (EstimatorKind::Program, _) => Estimator::Program(ProgramEstimator::new(path)),
        }
    }

    /// Which kind this is.
    pub fn kind(&self) -> EstimatorKind {
        match self {
            Estimator::FreeCurve(_) => EstimatorKind::FreeCurve,
            Estimator::Line(_) => EstimatorKind::Line,
            Estimator::Arc(_) => EstimatorKind::Arc,
            Estimator::Program(_) => EstimatorKind::Program,
        }
    }

    /// How far off the path a reference was, the first time one was off it by more than
    /// [`ON_PATH`](super::ON_PATH) (the program estimator only; then `None`).
    pub fn take_off_path(&mut self) -> Option<f64> {
        match self {
            Estimator::Program(e) => e.take_off_path(),
            _ => None,
        }
    }
}

impl ContourEstimator for Estimator {
    fn estimate(&mut self, reference: Vector2, actual: Vector2) -> ContourEstimate {
        match self {
            Estimator::FreeCurve(e) => e.estimate(reference, actual),
            Estimator::Line(e) => e.estimate(reference, actual),
            Estimator::Arc(e) => e.estimate(reference, actual),
            Estimator::Program(e) => e.estimate(reference, actual),
        }
    }
    fn reset(&mut self) {
        match self {
            Estimator::FreeCurve(e) => e.reset(),
            Estimator::Line(e) => e.reset(),
            Estimator::Arc(e) => e.reset(),
            Estimator::Program(e) => e.reset(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::path::planar::builtin;

    /// Every kind's saved bytes read as a [`SavedEstimator`] resume to the estimator that
    /// wrote them, on the infinity and on the line; a `program` estimator's index is
    /// built once for the instances and the restores on one path.
    #[test]
    fn saved_estimators_resume_as_they_were_with_shared_indexes() {
        let indexes = TrueErrorIndexes::new();
        for name in ["infinity", "line"] {
            let path = builtin::by_name(name).unwrap();
            for kind in EstimatorKind::ALL {
                let mut estimator = Estimator::for_path_shared(kind, &path, &indexes);
                for k in 0..50 {
                    let r = Vector2::new(k as f64 * 0.05, k as f64 * 0.0375);
                    estimator.estimate(r, r + Vector2::new(0.001, -0.002));
                }
                let bytes = postcard::to_stdvec(&estimator).unwrap();
                let saved: SavedEstimator = postcard::from_bytes(&bytes).unwrap();
                let resumed = saved.resume(&indexes).unwrap();
                assert_eq!(resumed, estimator, "{name} {kind}");
                assert_eq!(postcard::to_stdvec(&resumed).unwrap(), bytes);
            }
        }
        assert_eq!(indexes.indexes_made(), 2, "one index per path");
    }

    #[test]
    fn names_parse() {
        for k in EstimatorKind::ALL {
            assert_eq!(k.as_str().parse::<EstimatorKind>().unwrap(), k);
        }
        assert_eq!(
            "Free Curve".parse::<EstimatorKind>().unwrap(),
            EstimatorKind::FreeCurve
        );
        assert!("spline".parse::<EstimatorKind>().is_err());
    }

    #[test]
    fn dispatch_uses_path_geometry() {
        let circle = builtin::by_name("circle").unwrap();
        let mut e = Estimator::for_path(EstimatorKind::Arc, &circle);
        // The paper's circle: centre (−10, 0), r = 10, CCW; P 0.25 mm outside at (0.25, 0).
        let r = e.estimate(Vector2::new(0.0, 0.0), Vector2::new(0.25, 0.0));
        assert!((r.error - 0.25).abs() < 1e-15 && r.normal == Vector2::new(-1.0, 0.0));
        let blob = postcard::to_stdvec(&e).unwrap();
        assert_eq!(postcard::from_bytes::<Estimator>(&blob).unwrap(), e);
        let line = builtin::by_name("line").unwrap();
        let mut e = Estimator::for_path(EstimatorKind::Line, &line);
        // Line (0,0)→(40,30): P = (3, −4) lies 5 mm right of the start, perpendicular to (4, 3).
        let r = e.estimate(Vector2::new(0.0, 0.0), Vector2::new(3.0, -4.0));
        assert!((r.error - 5.0).abs() < 1e-14);
        assert_eq!(e.kind(), EstimatorKind::Line);
        let mut f = Estimator::for_path(EstimatorKind::FreeCurve, &line);
        assert_eq!(
            f.estimate(Vector2::new(0.0, 0.0), Vector2::new(3.0, -4.0))
                .error,
            0.0
        );
    }
}
