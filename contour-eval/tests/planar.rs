//! `contour-eval` on runs of the XY table (columns time,X,Y): measured points placed at
//! known signed offsets from known places of G-code programs, the expected contour
//! errors from the test's own closed forms; blended corners; a slot whose return pass
//! lies nearer the outgoing one; the columns deciding the kind of run; bad inputs.

use contour_core::math;
use std::f64::consts::{FRAC_PI_2, PI};
use std::fmt::Write as _;
use std::path::Path;

mod common;
use common::{contour_eval, entries, s};

use contour_core::contour::planar::true_error;
use contour_core::path::planar::{planned_geometry, Path as CorePath};

type P2 = [f64; 2];

fn scratch(name: &str) -> std::path::PathBuf {
    common::scratch("contour-eval-xy", name)
}

/// One expected sample: the measured point, the signed contour error (> 0 right of
/// travel) and the programmed moves the foot may be on (two where it is their common
/// vertex).
#[derive(Clone, Debug)]
struct Expected {
    point: P2,
    contour: f64,
    segments: Vec<usize>,
}

/// A row against its expected sample: the contour error to 1e-9 mm, the segment one
/// of those allowed.
fn assert_sample(k: usize, row: &Row, e: &Expected) {
    assert!(
        (row.contour - e.contour).abs() < 1e-9,
        "sample {k} at {:?}: {} vs {}",
        e.point,
        row.contour,
        e.contour
    );
    assert!(
        e.segments.contains(&row.segment),
        "sample {k} at {:?}: segment {} vs {:?}",
        e.point,
        row.segment,
        e.segments
    );
}

/// The right-hand normal of a direction of travel.
fn right(t: P2) -> P2 {
    let n = (t[0] * t[0] + t[1] * t[1]).sqrt();
    [t[1] / n, -t[0] / n]
}

/// `d` to the right of the point at fraction `f` of the line `a` → `b`.
fn off_line(a: P2, b: P2, f: f64, d: f64, segment: usize) -> Expected {
    let n = right([b[0] - a[0], b[1] - a[1]]);
    Expected {
        point: [
            a[0] + f * (b[0] - a[0]) + d * n[0],
            a[1] + f * (b[1] - a[1]) + d * n[1],
        ],
        contour: d,
        segments: vec![segment],
    }
}

/// `d` to the right of the point at angle `phi` of the circle about `c` of radius `r`
/// travelled counter-clockwise (right is outward) or clockwise (right is inward).
fn off_arc(c: P2, r: f64, phi: f64, ccw: bool, d: f64, segment: usize) -> Expected {
    let radius = if ccw { r + d } else { r - d };
    Expected {
        point: [
            c[0] + radius * math::cos(phi),
            c[1] + radius * math::sin(phi),
        ],
        contour: d,
        segments: vec![segment],
    }
}

/// The run's CSV (columns shuffled, one the tool must ignore) and the times.
fn run_csv(points: &[P2]) -> (String, Vec<f64>) {
    let mut text = String::from("Y,time,note,X\n");
    let mut times = Vec::new();
    for (k, p) in points.iter().enumerate() {
        let t = k as f64 * 1e-3;
        writeln!(text, "{},{t},n,{}", p[1], p[0]).unwrap();
        times.push(t);
    }
    (text, times)
}

struct Row {
    time: f64,
    segment: usize,
    contour: f64,
    planned: f64,
}

fn read_rows(file: &Path) -> Vec<Row> {
    let text = std::fs::read_to_string(file).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("time,segment,contour,contour_planned"));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f.len(), 4, "{l}");
            Row {
                time: f[0].parse().unwrap(),
                segment: f[1].parse().unwrap(),
                contour: f[2].parse().unwrap(),
                planned: f[3].parse().unwrap(),
            }
        })
        .collect()
}

/// Runs contour-eval on `points` against `path`; the rows and stdout.
fn evaluate(dir: &Path, path: &str, points: &[P2], extra: &[&str]) -> (Vec<Row>, String) {
    let (csv, times) = run_csv(points);
    let (run, err) = (dir.join("run.csv"), dir.join("err.csv"));
    std::fs::write(&run, csv).unwrap();
    let mut args = vec!["--path", path, "--measured", s(&run), "--out", s(&err)];
    args.extend(extra);
    let out = contour_eval(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows = read_rows(&err);
    assert_eq!(rows.len(), points.len());
    for (row, t) in rows.iter().zip(&times) {
        assert_eq!(row.time, *t);
    }
    (rows, String::from_utf8_lossy(&out.stdout).into_owned())
}

/// The number after `key` in `text` (the first occurrence after `from`).
fn number_after(text: &str, from: &str, key: &str) -> f64 {
    let rest = &text[text.find(from).unwrap()..];
    let rest = &rest[rest.find(key).unwrap() + key.len()..];
    let end = rest
        .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == '+'))
        .unwrap_or(rest.len());
    rest[..end].parse().unwrap()
}

/// A rectangle of lines (0,0) → (30,0), a tangent counter-clockwise quarter arc about
/// (30,5) to (35,5), then (35,20), (0,20) and back to (0,0) through non-tangent
/// corners. Moves 0 … 4 are on program lines 5 … 9.
const RECTANGLE: &str = "%\n(rectangle with a tangent arc)\nG21 G17 G90\nG0 X0 Y0\n\
                         G1 X30 F1200\nG3 X35 Y5 I0 J5\nG1 Y20\nG1 X0\nG1 Y0\nM30\n%\n";

/// Points round the rectangle in the order of travel, each at a known signed offset.
fn rectangle_points() -> Vec<Expected> {
    let (a, b, c, d, e) = (
        [0.0, 0.0],
        [30.0, 0.0],
        [35.0, 5.0],
        [35.0, 20.0],
        [0.0, 20.0],
    );
    let offset = |k: usize| 0.3 * math::sin(0.7 * k as f64);
    let mut points = Vec::new();
    // Outside the start corner (a vertex of the closed contour): its distance, right.
    points.push(Expected {
        point: [-0.1, -0.1],
        contour: 0.1 * 2f64.sqrt(),
        segments: vec![0],
    });
    for k in 0..=116 {
        let x = 0.5 + 0.25 * k as f64;
        points.push(off_line(a, b, x / 30.0, offset(k), 0));
    }
    // At the tangent join, then round the arc.
    points.push(Expected {
        segments: vec![0, 1],
        ..off_line(a, b, 1.0, 0.1, 0)
    });
    for k in 1..40 {
        let phi = -FRAC_PI_2 + FRAC_PI_2 * k as f64 / 40.0;
        points.push(off_arc([30.0, 5.0], 5.0, phi, true, offset(k), 1));
    }
    for k in 0..=56 {
        let y = 5.5 + 0.25 * k as f64;
        // The largest error of the run, on program line 7.
        let off = if k == 26 { 0.45 } else { offset(k) };
        points.push(off_line(c, d, (y - 5.0) / 15.0, off, 2));
    }
    // Round the outside of the corner at (35, 20): 0.1 mm from the vertex.
    for k in 1..10 {
        let theta = FRAC_PI_2 * k as f64 / 10.0;
        points.push(Expected {
            point: [35.0 + 0.1 * math::cos(theta), 20.0 + 0.1 * math::sin(theta)],
            contour: 0.1,
            segments: vec![2, 3],
        });
    }
    for k in 0..=136 {
        let x = 34.5 - 0.25 * k as f64;
        points.push(off_line(d, e, (35.0 - x) / 35.0, offset(k), 3));
    }
    // Inside the corner at (0, 20): nearer the line y = 20, then nearer x = 0.
    for (x, y, contour, segment) in [(0.3, 19.9, -0.1, 3), (0.15, 19.8, -0.15, 4)] {
        points.push(Expected {
            point: [x, y],
            contour,
            segments: vec![segment],
        });
    }
    for k in 0..=78 {
        let y = 19.5 - 0.25 * k as f64;
        points.push(off_line(e, a, (20.0 - y) / 20.0, offset(k), 4));
    }
    points
}

#[test]
fn a_program_of_lines_and_arcs_gives_the_signed_distances_of_its_points() {
    let dir = scratch("rectangle");
    let part = dir.join("part.ngc");
    std::fs::write(&part, RECTANGLE).unwrap();
    let expected = rectangle_points();
    let points: Vec<P2> = expected.iter().map(|e| e.point).collect();
    let plot = dir.join("err.png");
    let (rows, stdout) = evaluate(&dir, s(&part), &points, &["--plot", s(&plot)]);
    for (k, (row, e)) in rows.iter().zip(&expected).enumerate() {
        assert_sample(k, row, e);
        // No blend asked for and none programmed: the planned contour is the programmed.
        assert_eq!(row.planned, row.contour, "sample {k}");
    }
    // The summary: the largest error, where it is, the mean and the RMS.
    let n = expected.len() as f64;
    let (at, largest) = expected
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.contour.abs().total_cmp(&b.1.contour.abs()))
        .unwrap();
    assert_eq!(largest.contour, 0.45);
    let mean = expected.iter().map(|e| e.contour.abs()).sum::<f64>() / n;
    let rms = (expected.iter().map(|e| e.contour.powi(2)).sum::<f64>() / n).sqrt();
    assert!(
        stdout.contains(&format!("samples: {}", expected.len())),
        "{stdout}"
    );
    let line = "contour error (programmed):";
    assert!(
        stdout.contains(&format!(
            "{line} max 450.000 um (signed +450.000 um at t = {} s, segment 2 (line 7))",
            at as f64 * 1e-3
        )),
        "{stdout}"
    );
    assert!((number_after(&stdout, line, "mean ") - mean * 1e3).abs() < 1.5e-3);
    assert!((number_after(&stdout, line, "rms ") - rms * 1e3).abs() < 1.5e-3);
    assert!(
        stdout.contains("contour error (planned): max 450.000 um"),
        "{stdout}"
    );
    // A PNG of the designed size: signature, then IHDR width and height.
    let png = std::fs::read(&plot).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(&png[16..24], &[0, 0, 4, 176, 0, 0, 3, 32]);

    // The mirror image (y → −y, G2 for G3) negates every error.
    let mirrored = RECTANGLE
        .replace("G3 X35 Y5 I0 J5", "G2 X35 Y-5 I0 J-5")
        .replace("Y20", "Y-20");
    let part = dir.join("mirror.ngc");
    std::fs::write(&part, mirrored).unwrap();
    let points: Vec<P2> = points.iter().map(|p| [p[0], -p[1]]).collect();
    let (rows, _) = evaluate(&dir, s(&part), &points, &[]);
    for (k, (row, e)) in rows.iter().zip(&expected).enumerate() {
        assert!((row.contour + e.contour).abs() < 1e-9, "mirror {k}");
        assert!(e.segments.contains(&row.segment), "mirror {k}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The distance from `p` to the square (0,0) (20,0) (20,20) (0,20), signed > 0 outside
/// (it is travelled counter-clockwise), by the test's own closed form.
fn square_distance(p: P2) -> f64 {
    let (dx, dy) = ((p[0] - 10.0).abs() - 10.0, (p[1] - 10.0).abs() - 10.0);
    if dx > 0.0 || dy > 0.0 {
        (dx.max(0.0).powi(2) + dy.max(0.0).powi(2)).sqrt()
    } else {
        dx.max(dy)
    }
}

#[test]
fn blended_corners_change_the_planned_contour_near_them_only() {
    let dir = scratch("blend");
    // Bare G64 from the start: every corner but the closing one is blended within
    // --tolerance.
    let part = dir.join("square.ngc");
    std::fs::write(&part, "G1 X20 F1200\nY20\nX0\nY0\n").unwrap();
    let tolerance = 0.05;
    let corners = [[20.0, 0.0], [20.0, 20.0], [0.0, 20.0]];
    let mut points: Vec<P2> = Vec::new();
    let mut near_vertex = Vec::new();
    let offset = |k: usize| 0.03 * math::sin(0.9 * k as f64);
    let sides = [
        ([0.0, 0.0], [20.0, 0.0]),
        ([20.0, 0.0], [20.0, 20.0]),
        ([20.0, 20.0], [0.0, 20.0]),
        ([0.0, 20.0], [0.0, 0.0]),
    ];
    for (i, (a, b)) in sides.iter().enumerate() {
        for k in 0..=190 {
            let f = (0.5 + 0.1 * k as f64) / 20.0;
            points.push(off_line(*a, *b, f, offset(k), i).point);
        }
        if i < 3 {
            // Past the corner: outside round its vertex (0.03 mm), then inside it along
            // the bisector, 0 … 0.1 mm from either side, between the vertex and the
            // blend (it passes P·√2 = 0.071 mm inside the vertex) and beyond.
            let v: P2 = corners[i];
            let out = right([b[0] - a[0], b[1] - a[1]]);
            let turn = |t: P2| [-t[1], t[0]];
            let next = turn([b[0] - a[0], b[1] - a[1]]);
            let start = math::atan2(out[1], out[0]);
            for k in 0..=10 {
                let theta = start + FRAC_PI_2 * k as f64 / 10.0;
                near_vertex.push(points.len());
                points.push([
                    v[0] + 0.03 * math::cos(theta),
                    v[1] + 0.03 * math::sin(theta),
                ]);
            }
            let inward = [-(out[0] + right(next)[0]), -(out[1] + right(next)[1])];
            for k in 0..=10 {
                let depth = 0.01 * k as f64;
                near_vertex.push(points.len());
                points.push([v[0] + depth * inward[0], v[1] + depth * inward[1]]);
            }
        }
    }
    let tol = tolerance.to_string();
    let (rows, stdout) = evaluate(&dir, s(&part), &points, &["--tolerance", &tol]);
    assert!(
        stdout.contains("3 corners blended (tolerance 0.05 mm)"),
        "{stdout}"
    );
    let planned =
        planned_geometry(&CorePath::from_spec(s(&part), None).unwrap(), tolerance).unwrap();
    // A 90° corner's blend passes P·√2 inside its vertex (its middle is P from either
    // line): outside the corner, where the programmed foot is the vertex, and between
    // the vertex and the blend, the two differ by up to that; elsewhere by up to P.
    let vertex_bound = tolerance * 2f64.sqrt();
    let (mut differ, mut largest_outside) = (0, 0.0f64);
    for (k, (row, p)) in rows.iter().zip(&points).enumerate() {
        assert!(
            (row.contour - square_distance(*p)).abs() < 1e-9,
            "sample {k} at {p:?}: {} vs {}",
            row.contour,
            square_distance(*p)
        );
        let near_a_corner = corners
            .iter()
            .any(|v| (p[0] - v[0]).abs().max((p[1] - v[1]).abs()) < 1.0);
        let apart = (row.contour - row.planned).abs();
        if near_a_corner {
            if apart > 1e-4 {
                differ += 1;
            }
            // The planned distance as the library measures it against the whole
            // planned path (nothing else is near on this square).
            let whole = true_error(&planned, (*p).into()).error;
            assert!(
                (row.planned - whole).abs() < 1e-9,
                "sample {k}: {} vs {whole}",
                row.planned
            );
        } else {
            assert!(
                apart < 1e-12,
                "sample {k} at {p:?}: {} vs {}",
                row.contour,
                row.planned
            );
        }
        if near_vertex.contains(&k) {
            largest_outside = largest_outside.max(apart);
            assert!(apart <= vertex_bound + 1e-12, "sample {k}: {apart}");
        } else {
            assert!(apart <= tolerance + 1e-12, "sample {k} at {p:?}: {apart}");
        }
    }
    assert!(differ > 60, "{differ}");
    // At the vertex they differ by more than the tolerance: by P·√2.
    assert!(
        (largest_outside - vertex_bound).abs() < 1e-6,
        "{largest_outside} vs {vertex_bound}"
    );

    // Without --tolerance nothing is blended; the program's own G64 P is.
    let (rows, stdout) = evaluate(&dir, s(&part), &points, &[]);
    assert!(stdout.contains("no corner blended"), "{stdout}");
    assert!(rows.iter().all(|r| r.planned == r.contour));
    std::fs::write(&part, "G64 P0.05\nG1 X20 F1200\nY20\nX0\nY0\n").unwrap();
    let (own, stdout) = evaluate(&dir, s(&part), &points, &[]);
    assert!(stdout.contains("3 corners blended"), "{stdout}");
    let (asked, _) = evaluate(&dir, s(&part), &points, &["--tolerance", "0.2"]);
    for ((a, b), r) in own.iter().zip(&asked).zip(&rows) {
        // G64 P wins over --tolerance.
        assert_eq!((a.contour, a.planned), (b.contour, b.planned));
        assert_eq!(a.contour, r.contour);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_point_nearer_the_outgoing_pass_of_a_slot_is_measured_against_its_own_pass() {
    // A slot: 30 mm out along y = 0, a half circle of radius 0.05 mm, 30 mm back along
    // y = 0.1. The tool is 0.02 mm right of travel on the way out and round the end,
    // then moves over to 0.07 mm left of the return pass (y = 0.03): 0.03 mm from the
    // outgoing pass, which a nearest-point search would take.
    let dir = scratch("slot");
    let part = dir.join("slot.ngc");
    std::fs::write(&part, "G1 X30 F600\nG3 X30 Y0.1 I0 J0.05\nG1 X0\n").unwrap();
    let mut expected = Vec::new();
    for k in 0..=600 {
        let x = 0.05 * k as f64;
        expected.push(off_line([0.0, 0.0], [30.0, 0.0], x / 30.0, 0.02, 0));
    }
    for k in 1..20 {
        let phi = -FRAC_PI_2 + PI * k as f64 / 20.0;
        expected.push(off_arc([30.0, 0.05], 0.05, phi, true, 0.02, 1));
    }
    for k in 0..=600 {
        let x = 30.0 - 0.05 * k as f64;
        // From +0.02 to −0.07 over the first 2 mm back.
        let d = 0.02 - 0.09 * ((30.0 - x) / 2.0).min(1.0);
        let mut e = off_line([30.0, 0.1], [0.0, 0.1], (30.0 - x) / 30.0, d, 2);
        if k == 0 {
            // The end of the half circle.
            e.segments = vec![1, 2];
        }
        expected.push(e);
    }
    let points: Vec<P2> = expected.iter().map(|e| e.point).collect();
    let (rows, _) = evaluate(&dir, s(&part), &points, &[]);
    let mut trapped = 0;
    for (k, (row, e)) in rows.iter().zip(&expected).enumerate() {
        assert_sample(k, row, e);
        // Where the outgoing pass is the nearer one.
        if e.segments == [2] && e.point[1].abs() < e.contour.abs() - 1e-9 {
            trapped += 1;
        }
    }
    assert!(trapped > 500, "{trapped}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn built_in_paths_and_nurbs_files_are_measured_on_the_xy_table() {
    let dir = scratch("builtin");
    // The paper's circle: centre (−10, 0), r = 10, counter-clockwise: outside is right.
    let points: Vec<P2> = (0..200)
        .map(|k| {
            let phi = 2.0 * PI * k as f64 / 200.0;
            let r = 10.0 + 0.01 * math::cos(k as f64 * 0.3);
            [-10.0 + r * math::cos(phi), r * math::sin(phi)]
        })
        .collect();
    let (rows, stdout) = evaluate(&dir, "circle", &points, &[]);
    for (k, row) in rows.iter().enumerate() {
        assert!(
            (row.contour - 0.01 * math::cos(k as f64 * 0.3)).abs() < 1e-12,
            "{k}"
        );
        assert_eq!((row.segment, row.planned), (0, row.contour));
    }
    assert!(
        stdout.contains("path: an arc; planned on itself"),
        "{stdout}"
    );
    // A NURBS file: the degree-1 curve (0,0) → (10,0) → (10,10), one segment 0, the
    // sign by the side; --tolerance does not change it (with a warning).
    let json = dir.join("l.json");
    std::fs::write(
        &json,
        r#"{"degree": 1, "knots": [0, 0, 0.5, 1, 1], "control_points": [[0, 0], [10, 0], [10, 10]]}"#,
    )
    .unwrap();
    let points: Vec<P2> = (0..100).map(|k| [0.09 * k as f64, 0.2]).collect();
    let (csv, _) = run_csv(&points);
    let (run, err) = (dir.join("run.csv"), dir.join("err.csv"));
    std::fs::write(&run, csv).unwrap();
    let out = contour_eval(&[
        "--path",
        s(&json),
        "--measured",
        s(&run),
        "--out",
        s(&err),
        "--tolerance",
        "0.1",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("--tolerance does not change it"),
        "{stderr}"
    );
    for (k, row) in read_rows(&err).iter().enumerate() {
        assert!((row.contour + 0.2).abs() < 1e-9, "{k}: {}", row.contour);
        assert_eq!((row.segment, row.planned), (0, row.contour));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Runs with `args` expecting exit 2 and every one of `expected` in stderr.
fn refused(args: &[&str], expected: &[&str]) {
    let out = contour_eval(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    for e in expected {
        assert!(stderr.contains(e), "{args:?}: expected '{e}' in {stderr}");
    }
}

#[test]
fn the_columns_decide_the_kind_of_run_and_a_path_of_the_other_kind_is_refused() {
    let dir = scratch("kinds");
    let write = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let xy = write("xy.csv", "time,X,Y\n0,0,0\n0.001,0.01,0\n");
    let five = write(
        "five.csv",
        "time,X,Y,Z,A,C\n0,20,0,0,0.35,0\n0.001,20,0.01,0,0.35,0\n",
    );
    let part = write("part.ngc", "G1 X10 F600\n");
    let nurbs = write(
        "curve.json",
        r#"{"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0], [10, 0]]}"#,
    );
    let pair = write(
        "pair.json",
        r#"{"tip": {"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0, 0], [1, 0, 0]]},
            "second": {"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0, 100], [1, 0, 100]]},
            "length": 100}"#,
    );
    let out = dir.join("out.csv");
    std::fs::write(&out, "keep me\n").unwrap();
    let args = |path: &str, run: &Path, extra: &[&str]| -> Vec<String> {
        let mut a: Vec<String> = ["--path", path, "--measured", s(run), "--out", s(&out)]
            .iter()
            .map(|x| x.to_string())
            .collect();
        a.extend(extra.iter().map(|x| x.to_string()));
        a
    };
    let check = |path: &str, run: &Path, extra: &[&str], expected: &[&str]| {
        let a = args(path, run, extra);
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        refused(&a, expected);
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "keep me\n");
    };
    let xy_cols = "has the XY table's columns time,X,Y (no Z, A, C)";
    let five_cols = "has five-axis columns time,X,Y,Z,A,C";
    // XY columns with a five-axis reference: a built-in, a CL file (refused by its
    // name, before it is read), a two-curve JSON file.
    check(
        "tilted_helix",
        &xy,
        &[],
        &["--path tilted_helix is a five-axis reference", xy_cols],
    );
    check("figure_eight", &xy, &[], &["five-axis reference", "xy.csv"]);
    check(
        "blade.cl",
        &xy,
        &[],
        &["--path blade.cl is a five-axis reference", xy_cols],
    );
    check(
        s(&pair),
        &xy,
        &[],
        &["pair.json is a five-axis reference", xy_cols],
    );
    // Five-axis columns with a path of the XY table.
    for name in ["circle", "line", "arc", "infinity", "trident"] {
        check(
            name,
            &five,
            &[],
            &[
                &format!("--path {name} is a path of the XY table"),
                five_cols,
            ],
        );
    }
    // The part's edge is measured on the XY table only.
    check(
        s(&part),
        &five,
        &["--against", "programmed"],
        &["--against programmed applies to a G-code program and a run of the XY table"],
    );
    check(
        s(&nurbs),
        &five,
        &[],
        &["curve.json is a path of the XY table", five_cols],
    );
    // Options of the other kind.
    check(
        "circle",
        &xy,
        &["--pivot-a", "0,0"],
        &["--pivot-a does not apply", xy_cols],
    );
    check(
        "circle",
        &xy,
        &["--out-reference", "r.csv"],
        &["--out-reference does not apply"],
    );
    check(
        "tilted_helix",
        &five,
        &["--tolerance", "0.1"],
        &["--tolerance does not apply", five_cols],
    );
    // Unknown names, in the world of the columns.
    check(
        "spiral",
        &xy,
        &[],
        &["unknown path 'spiral'", "G-code program"],
    );
    check("spiral", &five, &[], &["unknown five-axis path \"spiral\""]);
    // One of Z, A, C makes a five-axis run, which needs them all.
    let z_only = write("z.csv", "time,X,Y,Z\n0,0,0,0\n");
    check(
        "circle",
        &z_only,
        &[],
        &["z.csv:1", "no column 'A'", "time,X,Y,Z,A,C"],
    );
    let no_y = write("no_y.csv", "time,X\n0,0\n");
    check(
        "circle",
        &no_y,
        &[],
        &["no_y.csv:1", "no column 'Y'", "time,X,Y for the XY table"],
    );
    // The right kinds run.
    for (path, run) in [
        ("circle", &xy),
        (s(&part), &xy),
        (s(&part), &five),
        (s(&nurbs), &xy),
        ("tilted_helix", &five),
    ] {
        let a = args(path, run, &[]);
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        let done = contour_eval(&a);
        assert!(
            done.status.success(),
            "{path}: {}",
            String::from_utf8_lossy(&done.stderr)
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_xy_inputs_fail_naming_file_and_line_and_write_nothing() {
    let dir = scratch("bad");
    let write = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let good = write("good.csv", "time,X,Y\n0,0,0\n0.001,0.01,0\n");
    let part = write("part.ngc", "G1 X10 F600\n");
    let nan = write("nan.csv", "time,X,Y\n0,0,0\n0.001,NaN,0\n");
    let word = write("word.csv", "time,X,Y\n0,0,0\n0.001,0,abc\n");
    let short = write("short.csv", "time,X,Y\n0,0,0\n0.001,0\n");
    let empty = write("empty.csv", "");
    let header = write("header.csv", "time,X,Y\n");
    let g18 = write("g18.ngc", "G1 X10 F600\nG18 G2 X20 Z0 I5 K0\n");
    let arc = write("arc.ngc", "G1 X10 F600\nG2 X20 Y0 I1 J0\n");
    let out = dir.join("out.csv");
    let plot = dir.join("out.png");
    std::fs::write(&out, "keep me\n").unwrap();
    let run = |path: &Path, measured: &Path, extra: &[&str], expected: &[&str]| {
        let mut a = vec![
            "--path",
            s(path),
            "--measured",
            s(measured),
            "--out",
            s(&out),
        ];
        a.extend(["--plot", s(&plot)]);
        a.extend(extra);
        refused(&a, expected);
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "keep me\n");
        assert!(!plot.exists());
    };
    run(&part, &nan, &[], &["nan.csv:3", "column 'X'", "not finite"]);
    run(
        &part,
        &word,
        &[],
        &["word.csv:3", "column 'Y'", "'abc' is not a number"],
    );
    run(&part, &short, &[], &["short.csv:3", "2 fields"]);
    run(&part, &empty, &[], &["empty.csv", "empty file"]);
    run(&part, &header, &[], &["header.csv", "no measured samples"]);
    run(
        &part,
        &dir.join("missing.csv"),
        &[],
        &["missing.csv", "cannot read"],
    );
    run(&g18, &good, &[], &["g18.ngc:2"]);
    run(&arc, &good, &[], &["arc.ngc:2"]);
    run(
        &dir.join("missing.ngc"),
        &good,
        &[],
        &["missing.ngc", "cannot read"],
    );
    run(
        &part,
        &good,
        &["--tolerance", "-0.1"],
        &["--tolerance '-0.1' must be a finite number >= 0"],
    );
    run(
        &part,
        &good,
        &["--tolerance", "NaN"],
        &["--tolerance 'NaN'"],
    );
    run(&part, &good, &["--tolerance", "x"], &["--tolerance 'x'"]);
    run(
        &part,
        &good,
        &["--tolerance"],
        &["--tolerance needs a value"],
    );
    run(
        &part,
        &good,
        &["--speed", "3"],
        &["unknown option '--speed'"],
    );
    // Nothing but the inputs and the untouched output.
    let names = entries(&dir);
    assert_eq!(
        names,
        [
            "arc.ngc",
            "empty.csv",
            "g18.ngc",
            "good.csv",
            "header.csv",
            "nan.csv",
            "out.csv",
            "part.ngc",
            "short.csv",
            "word.csv"
        ]
    );
    // The good run replaces the outputs.
    let done = contour_eval(&[
        "--path",
        s(&part),
        "--measured",
        s(&good),
        "--out",
        s(&out),
        "--plot",
        s(&plot),
    ]);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    assert!(std::fs::read_to_string(&out)
        .unwrap()
        .starts_with("time,segment,contour,contour_planned\n"));
    assert!(plot.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_home_return_is_measured_against_the_home_that_is_given() {
    // X0 → X10, then G28 back at rapid to home, the tool on the way there: with --home
    // −5,−3,0 on the path throughout; without it the program returns to its origin, and
    // the tool at home is |(−5, −3)| from the program's end.
    let dir = scratch("home");
    let part = dir.join("home.ngc");
    std::fs::write(&part, "G1 X10 F600\nG28\n").unwrap();
    let mut points: Vec<P2> = (0..=100).map(|k| [0.1 * k as f64, 0.0]).collect();
    for k in 1..=150 {
        let t = k as f64 / 150.0;
        points.push([10.0 - 15.0 * t, -3.0 * t]);
    }
    let (home, _) = evaluate(&dir, s(&part), &points, &["--home", "-5,-3,0"]);
    for (k, row) in home.iter().enumerate() {
        assert!(row.contour.abs() < 1e-9, "sample {k}: {}", row.contour);
    }
    let (origin, _) = evaluate(&dir, s(&part), &points, &[]);
    let last = origin.last().unwrap();
    assert!(
        (last.contour.abs() - 34f64.sqrt()).abs() < 1e-9,
        "{}",
        last.contour
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_compensated_program_is_measured_against_the_tool_centre_or_the_part_edge() {
    // Under G41 D1 (r 2) the tool centre runs 2 mm left of X0→X20 (y = 2, from the
    // convex corner's arc about (0, 0)) and of X20→Y10 (x = 18, the concave corner cut at
    // (18, 2)). The measured tool runs 0.01 mm further left: against the tool centre's
    // path and against the programmed contour less the offset, −0.01 mm either way.
    let dir = scratch("compensation");
    let part = dir.join("comp.ngc");
    std::fs::write(
        &part,
        "G0 X0 Y-10\nG41 D1 G1 X0 Y0 F600\nG1 X20\nG1 Y10\nG40 G1 X30 Y10\n",
    )
    .unwrap();
    let mut points: Vec<P2> = (10..=170).map(|k| [0.1 * k as f64, 2.01]).collect();
    points.extend((30..=90).map(|k| [17.99, 0.1 * k as f64]));
    for against in ["compensated", "programmed"] {
        let (rows, stdout) = evaluate(
            &dir,
            s(&part),
            &points,
            &["--tool-radii", "1:2", "--against", against],
        );
        for (k, row) in rows.iter().enumerate() {
            assert!(
                (row.contour + 0.01).abs() < 1e-9,
                "{against} {k}: {}",
                row.contour
            );
        }
        assert_eq!(
            stdout.contains("part edge error"),
            against == "programmed",
            "{stdout}"
        );
    }
    // Against the programmed contour without the offsets the tool is 2.01 mm off.
    let (plain, _) = evaluate(&dir, s(&part), &points, &["--tool-radii", "1:0"]);
    assert!(plain.iter().all(|r| (r.contour + 0.01 - 0.0).abs() > 1.9));
    // D1 must be in the table; --against takes one of two words.
    let out = dir.join("out.csv");
    let run = dir.join("run.csv");
    for (extra, expected) in [
        (vec![], ["comp.ngc:2", "D1 is not in the tool table"]),
        (
            vec!["--against", "edge"],
            ["--against must be compensated", "or programmed"],
        ),
    ] {
        let mut args = vec!["--path", s(&part), "--measured", s(&run), "--out", s(&out)];
        args.extend(extra);
        refused(&args, &expected);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
