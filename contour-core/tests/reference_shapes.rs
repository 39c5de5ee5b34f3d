//! The offline evaluation's two readings of CL data (docs/design/five-axis.md §5.3a),
//! each against its own brute force: a figure-eight CL file at 0.2 mm chords, a measured
//! run offset from the curve by 0.1–0.3 mm with the tool turned by about a milliradian,
//! and per sample the nearest point of the reference (dense sampling of the traced
//! branch, then golden section) with the tool axis at that same point, written here from
//! the definitions (only the library's hypot norm is shared).

use contour_core::contour::five_axis::pose_error::{
    foot_point_error_between, nearest_segment_near,
};
use contour_core::contour::five_axis::reference_shape::ReferenceShape;
use contour_core::contour::five_axis::run_evaluation::{
    evaluate_run, suggested_max_skip, RunSettings,
};
use contour_core::geometry::{norm, Vector};
use contour_core::kinematics::{Joints, Pose, TableTiltingAc};
use contour_core::math;
use contour_core::path::five_axis::load_poses;

type V3 = Vector<3>;

/// The built-in figure eight's shape (docs/design/five-axis.md §5.3a): tip and unit axis at t.
fn eight(t: f64) -> (V3, V3) {
    let lean = 15f64.to_radians() * math::cos(t);
    let tilt = 25f64.to_radians();
    (
        V3::new(20.0 * math::sin(t), 10.0 * math::sin(2.0 * t), 0.0),
        V3::new(
            math::sin(lean) * math::cos(tilt),
            math::sin(tilt),
            math::cos(lean) * math::cos(tilt),
        ),
    )
}

/// Parameters t every `chord` mm of arc along the figure eight (trapezoidal arc length on
/// a fine grid), as a CAM system would post a smooth curve.
fn arc_length_table() -> (Vec<f64>, Vec<f64>) {
    let n = 400_000;
    let speed = |t: f64| (400.0 * math::cos(t).powi(2) + 400.0 * math::cos(2.0 * t).powi(2)).sqrt();
    let (mut ts, mut s) = (vec![0.0], vec![0.0]);
    for i in 1..=n {
        let (a, b) = (
            std::f64::consts::TAU * (i - 1) as f64 / n as f64,
            std::f64::consts::TAU * i as f64 / n as f64,
        );
        ts.push(b);
        s.push(s[i - 1] + 0.5 * (speed(a) + speed(b)) * (b - a));
    }
    (ts, s)
}

fn t_at(table: &(Vec<f64>, Vec<f64>), arc: f64) -> f64 {
    let (ts, s) = table;
    let i = s.partition_point(|&x| x < arc).clamp(1, s.len() - 1);
    let f = (arc - s[i - 1]) / (s[i] - s[i - 1]);
    ts[i - 1] + f * (ts[i] - ts[i - 1])
}

/// Turns `v` by `angle` about the unit `axis` (Rodrigues).
fn rotate(v: &V3, axis: &V3, angle: f64) -> V3 {
    v * math::cos(angle)
        + axis.cross(v) * math::sin(angle)
        + axis * axis.dot(v) * (1.0 - math::cos(angle))
}

/// The unit axis a fraction `f` of the way from `a` to `b` along their great circle.
fn turn_toward(a: &V3, b: &V3, f: f64) -> V3 {
    let cross = a.cross(b);
    let angle = math::atan2(norm(&cross), a.dot(b));
    if norm(&cross) == 0.0 {
        return *a;
    }
    rotate(a, &(cross / norm(&cross)), f * angle)
}

fn angle(a: &V3, b: &V3) -> f64 {
    math::atan2(norm(&a.cross(b)), a.dot(b))
}

/// The reference read as straight moves at global parameter u (segment ⌊u⌋).
fn straight_at(reference: &[Pose], u: f64) -> (V3, V3) {
    let i = (u.floor() as usize).min(reference.len() - 2);
    let f = u - i as f64;
    let (a, b) = (&reference[i], &reference[i + 1]);
    (
        a.tip + (b.tip - a.tip) * f,
        turn_toward(&a.axis, &b.axis, f),
    )
}

/// The smooth reading (its definition in `ReferenceShape::Smooth`): on segment i the
/// cubic Hermite with end derivatives |R_i+1 − R_i| times the unit tangent, the tangent
/// at a point along the chord between its neighbours; the axis turned by the same
/// parameter.
fn smooth_at(reference: &[Pose], u: f64) -> (V3, V3) {
    let n = reference.len();
    let i = (u.floor() as usize).min(n - 2);
    let s = u - i as f64;
    let tangent = |j: usize| {
        let d = reference[(j + 1).min(n - 1)].tip - reference[j.saturating_sub(1)].tip;
        d / norm(&d)
    };
    let (p0, p1) = (reference[i].tip, reference[i + 1].tip);
    let length = norm(&(p1 - p0));
    let (m0, m1) = (tangent(i) * length, tangent(i + 1) * length);
    let (s2, s3) = (s * s, s * s * s);
    let tip = p0 * (2.0 * s3 - 3.0 * s2 + 1.0)
        + m0 * (s3 - 2.0 * s2 + s)
        + p1 * (-2.0 * s3 + 3.0 * s2)
        + m1 * (s3 - s2);
    (
        tip,
        turn_toward(&reference[i].axis, &reference[i + 1].axis, s),
    )
}

/// The nearest point of `at` to `p` over u in [lo, hi]: a scan every 1/40 segment, then
/// 60 golden-section steps on the two cells around the best (0.05 · 0.618⁶⁰ = 1e-14 of a
/// segment, below the spacing of floats near u = 600). Tip distance and the orientation
/// error at that point.
fn brute_force(at: impl Fn(f64) -> (V3, V3), lo: f64, hi: f64, p: &V3, axis: &V3) -> (f64, f64) {
    let d = |u: f64| norm(&(at(u).0 - p));
    let steps = ((hi - lo) * 40.0).ceil() as usize;
    let best = (0..=steps)
        .map(|k| lo + (hi - lo) * k as f64 / steps as f64)
        .min_by(|a, b| d(*a).total_cmp(&d(*b)))
        .unwrap();
    let cell = (hi - lo) / steps as f64;
    let (mut a, mut b) = ((best - cell).max(lo), (best + cell).min(hi));
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut x1, mut x2) = (b - g * (b - a), a + g * (b - a));
    let (mut f1, mut f2) = (d(x1), d(x2));
    for _ in 0..60 {
        if f1 <= f2 {
            (b, x2, f2) = (x2, x1, f1);
            x1 = b - g * (b - a);
            f1 = d(x1);
        } else {
            (a, x1, f1) = (x1, x2, f2);
            x2 = a + g * (b - a);
            f2 = d(x2);
        }
    }
    let u = 0.5 * (a + b);
    let (tip, reference_axis) = at(u);
    (norm(&(tip - p)), angle(axis, &reference_axis))
}

struct Case {
    reference: Vec<Pose>,
    machine: TableTiltingAc,
    measured: Vec<Joints>,
    /// The measured poses and the reference index each sample traces (from its t).
    poses: Vec<Pose>,
    traced: Vec<f64>,
}

fn figure_eight_case() -> Case {
    let table = arc_length_table();
    let total = *table.1.last().unwrap();
    let points = (total / 0.2).round() as usize;
    let mut cl = String::from("PARTNO/FIGURE EIGHT AT 0.2 MM\nMULTAX\n");
    for k in 0..=points {
        let (tip, axis) = eight(t_at(&table, total * k as f64 / points as f64));
        cl += &format!(
            "GOTO/{},{},{},{},{},{}\n",
            tip[0], tip[1], tip[2], axis[0], axis[1], axis[2]
        );
    }
    let dir = std::env::temp_dir().join(format!("reference-shapes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("eight.cl");
    std::fs::write(&file, cl).unwrap();
    let (reference, warnings) = load_poses(file.to_str().unwrap(), 0.01).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    let chords: Vec<f64> = reference
        .windows(2)
        .map(|w| norm(&(w[1].tip - w[0].tip)))
        .collect();
    assert!(chords.iter().all(|&c| c > 0.199 && c <= 0.2 + 1e-9));

    // The run: 5000 samples along the curve, off it in the plane by 0.1 … 0.3 mm and by
    // up to 0.03 mm in z, the tool turned 0.5 … 1.5 mrad about a direction that wanders.
    let machine = TableTiltingAc {
        a_pivot: V3::new(0.0, 0.0, -40.0),
        c_pivot: V3::new(2.0, -1.0, 0.0),
    };
    let n = 5000;
    let (mut measured, mut poses, mut traced) = (Vec::new(), Vec::new(), Vec::new());
    let mut c = 0.0;
    for k in 0..n {
        let arc = total * (0.002 + 0.996 * k as f64 / (n - 1) as f64);
        let t = t_at(&table, arc);
        let (tip, axis) = eight(t);
        let along = V3::new(20.0 * math::cos(t), 20.0 * math::cos(2.0 * t), 0.0);
        let along = along / norm(&along);
        let normal = V3::new(-along[1], along[0], 0.0);
        let tip =
            tip + normal * (0.2 + 0.1 * math::sin(5.0 * t)) + V3::z() * 0.03 * math::sin(3.0 * t);
        let across = axis.cross(&V3::new(math::cos(7.0 * t), math::sin(7.0 * t), 0.3));
        let across = across / norm(&across);
        let pose = Pose {
            tip,
            axis: rotate(&axis, &across, 1e-3 * (1.0 + 0.5 * math::cos(11.0 * t))),
        };
        let q = machine.inverse(&pose, c).unwrap();
        c = q[4];
        measured.push(q);
        // The pose the evaluation sees is the forward kinematics of the joints.
        poses.push(machine.forward(&q));
        traced.push(arc / total * points as f64);
    }
    Case {
        reference,
        machine,
        measured,
        poses,
        traced,
    }
}

/// Largest, median, and how many beyond 1 % of `peak` of the absolute differences.
fn spread(differences: &mut [f64], peak: f64) -> (f64, f64, usize) {
    let beyond = differences.iter().filter(|&&d| d > 0.01 * peak).count();
    differences.sort_by(f64::total_cmp);
    (
        *differences.last().unwrap(),
        differences[differences.len() / 2],
        beyond,
    )
}

#[test]
fn each_reading_of_a_figure_eight_cl_file_matches_its_brute_force() {
    let case = figure_eight_case();
    let reference = &case.reference;
    let last = (reference.len() - 1) as f64;
    let mut settings = RunSettings::default();
    settings.params.max_skip = suggested_max_skip(&case.machine, reference, &case.measured, 2);
    settings.window = settings.window.max(8 * settings.params.max_skip);

    // The reading the evaluation used before: the foot on the chord at the fraction
    // of the swept normal planes, kept here to show the brute force tells them apart.
    let mut old_orientation = Vec::new();
    let mut old_errors = Vec::new();
    let mut straight_orientation = Vec::new();
    let mut shapes_apart: f64 = 0.0;
    let mut results = Vec::new();
    for shape in [ReferenceShape::Straight, ReferenceShape::Smooth] {
        settings.reference = shape;
        let result = evaluate_run(
            &case.machine,
            reference,
            &case.measured,
            &settings,
            |_, _| {},
        )
        .unwrap();
        let (mut tip_worst, mut orientation_worst): (f64, f64) = (0.0, 0.0);
        for (k, sample) in result.samples.iter().enumerate() {
            let pose = &case.poses[k];
            // The traced branch: 3 mm either side of where the sample was made (the other
            // loop passes within 0.3 mm of it at the crossing).
            let (lo, hi) = (
                (case.traced[k] - 15.0).max(0.0),
                (case.traced[k] + 15.0).min(last),
            );
            assert!(
                (sample.segment as f64 - case.traced[k]).abs() < 3.0,
                "sample {k} mapped to {} tracing {}",
                sample.segment,
                case.traced[k]
            );
            let (tip, orientation) = match shape {
                ReferenceShape::Straight => {
                    brute_force(|u| straight_at(reference, u), lo, hi, &pose.tip, &pose.axis)
                }
                ReferenceShape::Smooth => {
                    brute_force(|u| smooth_at(reference, u), lo, hi, &pose.tip, &pose.axis)
                }
            };
            tip_worst = tip_worst.max((sample.tip - tip).abs());
            orientation_worst = orientation_worst.max((sample.orientation - orientation).abs());
            if shape == ReferenceShape::Straight {
                straight_orientation.push(orientation);
                let segment =
                    |i: usize| (i + 1 < reference.len()).then(|| (reference[i], reference[i + 1]));
                let f = nearest_segment_near(segment, sample.segment, &pose.tip);
                let old = foot_point_error_between(
                    f.checked_sub(1).map(|i| &reference[i]),
                    &reference[f],
                    &reference[f + 1],
                    reference.get(f + 2),
                    pose,
                )
                .unwrap();
                old_orientation.push((old.orientation - orientation).abs());
                old_errors.push(old.orientation);
            }
        }
        results.push(result);
        // Tolerances: the golden section stops at 1e-13 of a segment; the distance is
        // flat at its minimum, so the point found is good to ~1e-8 of a segment there,
        // which moves the axis by < 1e-10 rad (it turns < 3 mrad a segment).
        assert!(
            tip_worst < 1e-10,
            "{shape}: tip off its brute force by {tip_worst} mm"
        );
        assert!(
            orientation_worst < 1e-9,
            "{shape}: orientation off its brute force by {orientation_worst} rad"
        );
        println!(
            "{shape}: worst against the brute force: tip {tip_worst:.2e} mm, orientation \
             {orientation_worst:.2e} rad"
        );
    }
    let mut old_from_smooth: f64 = 0.0;
    for ((a, b), old) in results[0]
        .samples
        .iter()
        .zip(&results[1].samples)
        .zip(&old_errors)
    {
        shapes_apart = shapes_apart.max((a.orientation - b.orientation).abs());
        old_from_smooth = old_from_smooth.max((old - b.orientation).abs());
    }
    let peak = straight_orientation.iter().cloned().fold(0.0, f64::max);
    let (worst, median, beyond) = spread(&mut old_orientation, peak);
    println!(
        "old swept-plane reading against straight moves: orientation off by up to {:.2} \
         urad (median {:.3} urad, {beyond} of {} samples beyond 1 % of the {:.1} urad \
         peak); smooth against straight up to {:.2} urad; old against smooth up to {:.2} \
         urad",
        worst * 1e6,
        median * 1e6,
        old_orientation.len(),
        peak * 1e6,
        shapes_apart * 1e6,
        old_from_smooth * 1e6
    );
    // The old reading is tens of µrad off the straight moves: the brute force sees it.
    assert!(worst > 1e-5, "{worst}");
    // The two readings differ by about as much: the old one sat nearer the smooth curve.
    assert!(shapes_apart > 1e-5, "{shapes_apart}");
    assert!(old_from_smooth < worst, "{old_from_smooth} {worst}");
}
