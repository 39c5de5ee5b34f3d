//! Loading a NURBS path from a small JSON file.
//!
//! Format (mm; `weights` optional, all 1 when absent; unknown keys are rejected so a typo
//! such as `"weight"` is not silently ignored):
//!
//! ```json
//! {
//!   "degree": 3,
//!   "knots": [0, 0, 0, 0, 0.5, 1, 1, 1, 1],
//!   "control_points": [[0, 0], [10, 5], [20, 0], [30, 5], [40, 0]],
//!   "weights": [1, 1, 2, 1, 1]
//! }
//! ```
//!
//! Every error names the file; JSON syntax and type errors also give line and column.

use super::nurbs::NurbsData;
use super::{Nurbs, PathError};

/// Reads and validates a NURBS JSON file.
pub fn load_nurbs<const D: usize>(
    file: impl AsRef<std::path::Path>,
) -> Result<Nurbs<D>, PathError> {
    let (name, text) = read_path_file(file.as_ref())?;
    parse_nurbs(&text, &name)
}

/// The name (for messages) and the text of a path file; an unreadable file is an error
/// naming it.
pub(crate) fn read_path_file(file: &std::path::Path) -> Result<(String, String), PathError> {
    let name = file.display().to_string();
    match std::fs::read_to_string(file) {
        Ok(text) => Ok((name, text)),
        Err(e) => Err(PathError::File {
            file: name,
            line: 0,
            column: 0,
            message: format!("cannot read: {e}"),
        }),
    }
}

/// Parses the JSON text of a NURBS file; `name` is used in error messages.
pub fn parse_nurbs<const D: usize>(text: &str, name: &str) -> Result<Nurbs<D>, PathError> {
    let data: NurbsData<D> = serde_json::from_str(text).map_err(|e| PathError::File {
        file: name.to_string(),
        line: e.line(),
        column: e.column(),
        message: match e.classify() {
            serde_json::error::Category::Syntax | serde_json::error::Category::Eof => {
                format!("JSON syntax error: {e}")
            }
            _ => format!("wrong NURBS file content: {e}"),
        },
    })?;
    Nurbs::try_from(data).map_err(|e| e.in_file(name))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::path::Curve;

    #[test]
    fn parses_documented_example() {
        let t = r#"{
          "degree": 3,
          "knots": [0, 0, 0, 0, 0.5, 1, 1, 1, 1],
          "control_points": [[0, 0], [10, 5], [20, 0], [30, 5], [40, 0]],
          "weights": [1, 1, 2, 1, 1]
        }"#;
        let n = parse_nurbs::<2>(t, "ex.json").unwrap();
        assert_eq!(n.weights()[2], 2.0);
        assert_eq!(n.point(1.0), crate::geometry::Vector2::new(40.0, 0.0));
    }

    #[test]
    fn syntax_error_names_file_and_line() {
        let t = "{\n \"degree\": 3,\n \"knots\": [0, 0,, 1]\n}";
        let e = parse_nurbs::<2>(t, "bad.json").unwrap_err();
        match &e {
            PathError::File { file, line, .. } => {
                assert_eq!(file, "bad.json");
                assert_eq!(*line, 3);
            }
            other => panic!("unexpected {other:?}"),
        }
        assert!(e.to_string().starts_with("bad.json:3:"), "{e}");
    }

    #[test]
    fn content_errors_name_file() {
        let t = r#"{"degree": 3, "knots": [0,0,0,1,1,1,1], "control_points": [[0,0],[1,1],[2,0],[3,1]]}"#;
        let e = parse_nurbs::<2>(t, "short.json").unwrap_err().to_string();
        assert!(e.contains("short.json") && e.contains("knot count"), "{e}");
        let t = r#"{"degree": 3, "knot": []}"#;
        let e = parse_nurbs::<2>(t, "typo.json").unwrap_err().to_string();
        assert!(
            e.contains("typo.json:1:") && e.contains("unknown field"),
            "{e}"
        );
        let e = load_nurbs::<2>("/nonexistent/dir/x.json")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("/nonexistent/dir/x.json") && e.contains("cannot read"),
            "{e}"
        );
    }

    #[test]
    fn spec_resolves_builtins_then_files() {
        use crate::path::planar::Path;
        assert!(matches!(Path::from_spec("circle", None), Ok(Path::Arc(_))));
        let dir = std::env::temp_dir().join(format!("contour_fmu_path_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(
            dir.join("s.json"),
            r#"{"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0], [3, 4]]}"#,
        )
        .unwrap();
        let p = Path::from_spec("s.json", Some(&dir)).unwrap();
        assert!((p.length() - 5.0).abs() < 1e-12);
        assert_eq!(p.end_point(), crate::geometry::Vector2::new(3.0, 4.0));
        let e = Path::from_spec("nope.json", Some(&dir)).unwrap_err();
        assert!(e.to_string().contains("nope.json") && e.to_string().contains("cannot read"));
        assert!(matches!(
            Path::from_spec("spiral", Some(&dir)),
            Err(PathError::UnknownName(_))
        ));
        std::fs::remove_dir_all(&dir).ok();
    }
}
