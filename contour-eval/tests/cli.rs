//! Runs the `contour-eval` binary on measured runs made here from a known displacement
//! of the tilted helix, so the expected errors are analytic, and on bad inputs.

use contour_core::math;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

mod common;
use common::{contour_eval, entries, s};

use contour_core::geometry::{self, Vector};
use contour_core::kinematics::{Pose, TableTiltingAc};
use contour_core::path::five_axis::{JointReference, ToolPath};

type V3 = Vector<3>;

/// Radial tip offset, mm, and tool tilt, rad, of the measured run.
const OFFSET: f64 = 0.020;
const TILT: f64 = 50e-6;

/// The machine of the tests, as given on the command line.
fn machine() -> TableTiltingAc {
    TableTiltingAc {
        a_pivot: V3::new(0.0, 0.0, -50.0),
        c_pivot: V3::new(5.0, -3.0, 0.0),
    }
}

const PIVOTS: [&str; 4] = ["--pivot-a", "0,-50", "--pivot-c", "5,-3"];

fn scratch(name: &str) -> PathBuf {
    common::scratch("contour-eval", name)
}

/// Samples of the measured run: 0.4 s, 8 mm of the helix (a debug build evaluates it
/// in seconds).
const SAMPLES: usize = 400;

/// The first SAMPLES of the helix followed at 20 mm/s, 1 kHz, with the tip moved OFFSET outward (normal to
/// the helix) and the tool turned TILT in its vertical plane (normal to the way the axis
/// turns along the path): columns shuffled, plus one the tool must ignore. Returns the
/// CSV text and the helix parameter u (segment + fraction) of each row.
fn displaced_helix_csv() -> (String, Vec<f64>) {
    let machine = machine();
    let mut reference = JointReference::new(ToolPath::tilted_helix(), machine, 20.0, 1e-3).unwrap();
    let mut text = String::from("C,time,note,X,Y,Z,A\n");
    let mut us = Vec::new();
    let mut c = 0.0;
    let mut k = 0;
    loop {
        let s = reference.current();
        let Pose { tip, axis } = s.pose;
        // The tool leans toward the helix's centre line: outward is the other way.
        let outward = geometry::unit(&V3::new(-axis[0], -axis[1], 0.0)).unwrap();
        let about = geometry::unit(&V3::z().cross(&axis)).unwrap();
        let turned = axis * math::cos(TILT) + about.cross(&axis) * math::sin(TILT);
        let moved = Pose {
            tip: tip + outward * OFFSET,
            axis: turned,
        };
        let q = machine.inverse(&moved, c).unwrap();
        c = q[4];
        writeln!(
            text,
            "{},{},x,{},{},{},{}",
            q[4],
            k as f64 * 1e-3,
            q[0],
            q[1],
            q[2],
            q[3]
        )
        .unwrap();
        us.push(s.u);
        if us.len() == SAMPLES {
            break;
        }
        reference.step().unwrap();
        k += 1;
    }
    (text, us)
}

fn rows(file: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(file)
        .unwrap()
        .lines()
        .map(|l| l.split(',').map(String::from).collect())
        .collect()
}

/// ERR.csv holds the displacement at every sample, each mapped where it is.
fn check_errors(file: &Path, us: &[f64]) {
    let rows = rows(file);
    assert_eq!(rows[0], ["time", "segment", "tip", "orientation"]);
    assert_eq!(rows.len() - 1, us.len());
    for (k, (row, u)) in rows[1..].iter().zip(us).enumerate() {
        let time: f64 = row[0].parse().unwrap();
        let segment: f64 = row[1].parse().unwrap();
        let tip: f64 = row[2].parse().unwrap();
        let orientation: f64 = row[3].parse().unwrap();
        assert_eq!(time, k as f64 * 1e-3);
        // Its own segment or a neighbour: on 3 µm segments those differ by nm in cost.
        assert!(
            segment <= u + 1.0 && u - segment <= 2.0,
            "row {k}: segment {segment}, u {u}"
        );
        assert!((tip - OFFSET).abs() < 0.05e-3, "row {k}: tip {tip}");
        assert!(
            (orientation - TILT).abs() < 5e-6,
            "row {k}: orientation {orientation}"
        );
    }
}

/// REF.csv: the same displacement at every reference point the run passes, none near the
/// first sample (no sample before it to fit) nor after the run's end; the run's samples
/// are at helix parameters `us`.
fn check_reference(file: &Path, points: usize, us: &[f64]) {
    // Points past the last but one sample may be nearest the last (no sample after it).
    let last_u = us[us.len() - 2];
    let rows = rows(file);
    assert_eq!(
        rows[0],
        [
            "index",
            "x",
            "y",
            "z",
            "i",
            "j",
            "k",
            "tip",
            "orientation",
            "t"
        ]
    );
    assert_eq!(rows.len() - 1, points);
    let passed = last_u.floor() as usize;
    let mut estimated = 0;
    for (i, row) in rows[1..].iter().enumerate() {
        assert_eq!(row[0], i.to_string());
        if row[7].is_empty() {
            assert!(row[8].is_empty() && row[9].is_empty());
            assert!(
                i < us[1].ceil() as usize || i >= passed,
                "point {i} has no estimate"
            );
            continue;
        }
        assert!(
            i <= us[us.len() - 1].ceil() as usize,
            "point {i} beyond the run has an estimate"
        );
        let tip: f64 = row[7].parse().unwrap();
        let orientation: f64 = row[8].parse().unwrap();
        let t: f64 = row[9].parse().unwrap();
        assert!((tip - OFFSET).abs() < 0.05e-3, "point {i}: tip {tip}");
        assert!(
            (orientation - TILT).abs() < 5e-6,
            "point {i}: {orientation}"
        );
        assert!((-1.0..=1.0).contains(&t));
        estimated += 1;
    }
    assert!(estimated + 10 >= passed, "{estimated} of {passed}");
}

#[test]
fn a_displaced_helix_gives_its_displacement() {
    let dir = scratch("helix");
    let (csv, us) = displaced_helix_csv();
    let (run, err, reference, plot) = (
        dir.join("run.csv"),
        dir.join("err.csv"),
        dir.join("ref.csv"),
        dir.join("err.png"),
    );
    std::fs::write(&run, csv).unwrap();
    let evaluate = |err: &Path, reference: &Path, options: &[&str]| {
        let mut args = vec!["--path", "tilted_helix", "--measured", s(&run)];
        args.extend(["--out", s(err), "--out-reference", s(reference)]);
        args.extend(options);
        args.extend(PIVOTS);
        contour_eval(&args)
    };
    let out = evaluate(&err, &reference, &["--plot", s(&plot)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains(&format!("samples: {}", us.len())),
        "{stdout}"
    );
    assert!(stdout.contains("tip error: max 20.0"), "{stdout}");
    check_errors(&err, &us);
    let ToolPath::Poses { tips, .. } = ToolPath::tilted_helix() else {
        unreachable!("the helix is sampled")
    };
    check_reference(&reference, tips.len(), &us);
    // A PNG of the designed size: signature, then IHDR width and height.
    let png = std::fs::read(&plot).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(&png[16..24], &[0, 0, 4, 176, 0, 0, 3, 32]);
    // Nothing else left in the folder.
    let names = entries(&dir);
    assert_eq!(names, ["err.csv", "err.png", "ref.csv", "run.csv"]);
    // On one thread: the same files, byte for byte.
    let (err_1, reference_1) = (dir.join("err_1.csv"), dir.join("ref_1.csv"));
    let out = evaluate(&err_1, &reference_1, &["--threads", "1"]);
    assert!(out.status.success());
    assert!(std::fs::read(&err).unwrap() == std::fs::read(&err_1).unwrap());
    assert!(std::fs::read(&reference).unwrap() == std::fs::read(&reference_1).unwrap());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The helix's poses as CL text in `file` (its extension names the format): `header`,
/// then each GOTO in units of `unit` mm with 10 decimals; contour-eval on the displaced
/// run must give the displacement at every sample.
fn helix_as_cl_gives_the_same_errors(file: &str, header: &str, unit: f64) {
    let dir = scratch(file);
    let ToolPath::Poses { tips, axes } = ToolPath::tilted_helix() else {
        unreachable!("the helix is sampled")
    };
    let mut cl = String::from(header);
    let (csv, us) = displaced_helix_csv();
    let needed = us[us.len() - 1] as usize + 50;
    for (p, o) in tips.iter().zip(axes.iter()).take(needed) {
        let p = p / unit;
        writeln!(
            cl,
            "GOTO/{:.10},{:.10},{:.10},{:.12},{:.12},{:.12}",
            p[0], p[1], p[2], o[0], o[1], o[2]
        )
        .unwrap();
    }
    cl.push_str("END-OF-PATH\nFINI\n");
    let (part, run, err) = (dir.join(file), dir.join("run.csv"), dir.join("e.csv"));
    std::fs::write(&part, cl).unwrap();
    std::fs::write(&run, csv).unwrap();
    let mut args = vec!["--path", s(&part), "--measured", s(&run), "--out", s(&err)];
    args.extend(PIVOTS);
    let out = contour_eval(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    check_errors(&err, &us);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_same_helix_as_cl_data_gives_the_same_errors() {
    helix_as_cl_gives_the_same_errors(
        "helix.cl",
        "PARTNO/HELIX\n$$ the tilted helix\nMULTAX\nFEDRAT/MMPM,1200\n",
        1.0,
    );
}

#[test]
fn the_same_helix_as_nx_writes_it_in_inches_gives_the_same_errors() {
    // NX's CLSF: a listing header, no UNITS record (FEDRAT/IPM: inches),
    // MSYS, TOOL PATH, PAINT; `.cls`. The measured run's columns (X Y Z A C) make it a
    // five-axis evaluation, whatever the reference file's extension.
    helix_as_cl_gives_the_same_errors(
        "helix.cls",
        "Information listing created by\tsomeone\nTOOL PATH/HELIX,TOOL,BALL\n\
         MSYS/0.0000,0.0000,0.0000,1.0000000,0.0000000,0.0000000,0.0000000,1.0000000,0.0000000\n\
         PAINT/PATH\nFEDRAT/IPM,47.2441\n",
        25.4,
    );
}

#[test]
fn bad_inputs_fail_naming_the_cause_and_write_nothing() {
    let dir = scratch("bad");
    let good = "time,X,Y,Z,A,C\n0,20,0,0,0.35,0\n0.001,20,0.01,0,0.35,0\n";
    let write = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let good_run = write("good.csv", good);
    let no_a = write("no_a.csv", "time,X,Y,Z,C\n0,1,2,3,4\n");
    let nan = write(
        "nan.csv",
        "time,X,Y,Z,A,C\n0,20,0,0,0.35,0\n0.001,20,NaN,0,0.35,0\n",
    );
    let word = write(
        "word.csv",
        "time,X,Y,Z,A,C\n0,20,0,0,0.35,0\n0.001,20,0,0,abc,0\n",
    );
    let no_goto = write("empty.cl", "PARTNO/NOTHING\nMULTAX\n$$ no motion\nFINI\n");
    let missing = dir.join("missing.csv");
    let missing_cl = dir.join("missing.cl");
    let cases: Vec<(String, &Path, Vec<&str>)> = vec![
        (
            s(&no_a).to_string(),
            &no_a,
            vec!["no_a.csv:1", "no column 'A'"],
        ),
        (
            s(&nan).to_string(),
            &nan,
            vec!["nan.csv:3", "column 'Y'", "not finite"],
        ),
        (
            s(&word).to_string(),
            &word,
            vec!["word.csv:3", "'abc' is not a number"],
        ),
        ("".to_string(), &missing, vec!["missing.csv", "cannot read"]),
    ];
    let out_file = dir.join("out.csv");
    let ref_file = dir.join("ref.csv");
    std::fs::write(&out_file, "keep me\n").unwrap();
    let check = |args: &[&str], expected: &[&str]| {
        let out = contour_eval(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        for e in expected {
            assert!(stderr.contains(e), "{args:?}: expected '{e}' in {stderr}");
        }
        assert_eq!(std::fs::read_to_string(&out_file).unwrap(), "keep me\n");
        assert!(!ref_file.exists());
    };
    for (_, measured, expected) in &cases {
        check(
            &[
                "--path",
                "tilted_helix",
                "--measured",
                s(measured),
                "--out",
                s(&out_file),
                "--out-reference",
                s(&ref_file),
            ],
            expected,
        );
    }
    let with_path = |path: &str| {
        vec![
            "--path".to_string(),
            path.to_string(),
            "--measured".into(),
            s(&good_run).into(),
            "--out".into(),
            s(&out_file).into(),
            "--out-reference".into(),
            s(&ref_file).into(),
        ]
    };
    for (path, expected) in [
        (s(&no_goto), vec!["empty.cl", "at least two GOTO points"]),
        (
            "spiral",
            vec![
                "unknown five-axis path \"spiral\"",
                "tilted_helix",
                "figure_eight",
            ],
        ),
        (s(&missing_cl), vec!["missing.cl", "cannot read"]),
    ] {
        let args = with_path(path);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        check(&args, &expected);
    }
    // Command-line mistakes: exit 2 too.
    check(
        &["--path", "tilted_helix", "--out", s(&out_file)],
        &["--measured is required"],
    );
    let on_the_good_run = |options: &[&str], expected: &[&str]| {
        let mut args = vec!["--path", "tilted_helix", "--measured", s(&good_run)];
        args.extend(["--out", s(&out_file)]);
        args.extend(options);
        check(&args, expected);
    };
    on_the_good_run(&["--pivot-a", "1"], &["--pivot-a needs two"]);
    on_the_good_run(&["--threads", "0"], &["--threads must be at least 1"]);
    on_the_good_run(&["--threads", "two"], &["--threads 'two'"]);
    // Only the inputs and the untouched output remain: no temporary files.
    let names = entries(&dir);
    assert_eq!(
        names,
        ["empty.cl", "good.csv", "nan.csv", "no_a.csv", "out.csv", "word.csv"]
    );
    // And the good run then replaces the output.
    let args = with_path("tilted_helix");
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = contour_eval(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(std::fs::read_to_string(&out_file)
        .unwrap()
        .starts_with("time,segment,tip,orientation\n"));
    assert!(ref_file.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--reference`: on CL points every 0.05 rad of a circle of radius 5 mm, a run 0.3 mm
/// outside it. Read as straight moves the tip error is the distance to the chord
/// (0.3 mm plus up to the 1.56 µm sagitta) and the axis is slerped at the chord
/// projection; read as a smooth curve the tip error is the 0.3 mm to the circle (the
/// curve keeps to it within 2.4e-7 mm). Straight is the default.
#[test]
fn the_reference_is_read_as_straight_moves_unless_smooth_is_asked_for() {
    let dir = scratch("shape");
    let (radius, step, outside) = (5.0, 0.05, 5.3);
    // The tool leans in the x–z plane by 0.3 + 0.5·φ: a great circle, so slerping
    // between two points turns it linearly in φ.
    let lean = |phi: f64| 0.3 + 0.5 * phi;
    let axis = |phi: f64| V3::new(math::sin(lean(phi)), 0.0, math::cos(lean(phi)));
    let mut cl = String::from("PARTNO/ARC\n");
    for i in 0..=16 {
        let phi = step * i as f64;
        let o = axis(phi);
        writeln!(
            cl,
            "GOTO/{},{},0,{},{},{}",
            radius * math::cos(phi),
            radius * math::sin(phi),
            o[0],
            o[1],
            o[2]
        )
        .unwrap();
    }
    // 240 samples from φ = 0.2 to 0.6 (chords 4 … 11), the tool leaning as the curve's.
    let machine = TableTiltingAc::default();
    let mut csv = String::from("time,X,Y,Z,A,C\n");
    let mut expected = Vec::new();
    let mut c = 0.0;
    for k in 0..240 {
        let phi = 0.2 + 0.4 * k as f64 / 239.0;
        let tip = V3::new(math::cos(phi), math::sin(phi), 0.0) * outside;
        let q = machine
            .inverse(
                &Pose {
                    tip,
                    axis: axis(phi),
                },
                c,
            )
            .unwrap();
        c = q[4];
        writeln!(
            csv,
            "{},{},{},{},{},{}",
            k as f64 * 1e-3,
            q[0],
            q[1],
            q[2],
            q[3],
            q[4]
        )
        .unwrap();
        // The straight reading by hand: the nearest point over all chords (projections
        // clamped to them; outside a vertex that is the vertex).
        let (distance, orientation) = (0..16)
            .map(|i| {
                let (a, b) = (step * i as f64, step * (i + 1) as f64);
                let (pa, pb) = (
                    V3::new(math::cos(a), math::sin(a), 0.0) * radius,
                    V3::new(math::cos(b), math::sin(b), 0.0) * radius,
                );
                let f = ((tip - pa).dot(&(pb - pa)) / (pb - pa).norm_squared()).clamp(0.0, 1.0);
                let distance = geometry::norm(&(pa + (pb - pa) * f - tip));
                (distance, 0.5 * (phi - (a + f * step)).abs())
            })
            .min_by(|x, y| x.0.total_cmp(&y.0))
            .unwrap();
        expected.push((distance, orientation));
    }
    let (part, run) = (dir.join("arc.cl"), dir.join("run.csv"));
    std::fs::write(&part, cl).unwrap();
    std::fs::write(&run, csv).unwrap();
    let evaluate = |name: &str, extra: &[&str]| {
        let out = dir.join(name);
        let mut args = vec!["--path", s(&part), "--measured", s(&run), "--out", s(&out)];
        args.extend(extra);
        let done = contour_eval(&args);
        let stdout = String::from_utf8_lossy(&done.stdout).into_owned();
        assert!(
            done.status.success(),
            "{}",
            String::from_utf8_lossy(&done.stderr)
        );
        let values: Vec<(f64, f64)> = rows(&out)[1..]
            .iter()
            .map(|r| (r[2].parse().unwrap(), r[3].parse().unwrap()))
            .collect();
        (std::fs::read_to_string(&out).unwrap(), values, stdout)
    };
    let (default_text, _, stdout) = evaluate("default.csv", &[]);
    assert!(
        stdout.contains("reference read as: straight moves between the points"),
        "{stdout}"
    );
    let (straight_text, straight, _) = evaluate("straight.csv", &["--reference", "straight"]);
    assert_eq!(default_text, straight_text);
    let (_, smooth, stdout) = evaluate("smooth.csv", &["--reference", "smooth"]);
    assert!(
        stdout.contains("reference read as: a smooth curve through the points"),
        "{stdout}"
    );
    let mut apart: f64 = 0.0;
    for (k, ((st, so), (&(tip, orientation), (mt, mo)))) in straight
        .iter()
        .zip(expected.iter().zip(&smooth))
        .enumerate()
    {
        assert!(
            (st - tip).abs() < 1e-12,
            "sample {k}: straight tip {st} vs {tip}"
        );
        assert!(
            (so - orientation).abs() < 1e-12,
            "sample {k}: straight orientation {so} vs {orientation}"
        );
        assert!((mt - 0.3).abs() < 3e-7, "sample {k}: smooth tip {mt}");
        // The smooth curve's parameter runs within 0.1 % of the angle: the axis is
        // within 0.5·0.05·1e-3 rad of the tool's.
        assert!(*mo < 2.5e-5, "sample {k}: smooth orientation {mo}");
        apart = apart.max(st - mt);
    }
    // Near the chords' middles the readings are a sagitta (1.56 µm) apart.
    let sagitta = radius * (1.0 - math::cos(step / 2.0));
    assert!(
        apart > 0.99 * sagitta && apart < sagitta + 3e-7,
        "{apart} vs {sagitta}"
    );
    // An unknown reading is a command-line mistake.
    let done = contour_eval(&[
        "--path",
        s(&part),
        "--measured",
        s(&run),
        "--out",
        s(&dir.join("x.csv")),
        "--reference",
        "curved",
    ]);
    let stderr = String::from_utf8_lossy(&done.stderr);
    assert_eq!(done.status.code(), Some(2), "{stderr}");
    assert!(
        stderr
            .contains("--reference: unknown reference shape 'curved': expected straight or smooth"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
