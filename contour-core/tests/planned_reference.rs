//! Planned five-axis references on CL data shaped like a CAM system's: tool axes through
//! and beside vertical, a hemisphere raster over its apex, a path the A range cannot
//! reach. Every check is on the samples the FMU would send.

use contour_core::geometry::{self, Vector};
use contour_core::kinematics::{Pose, TableTiltingAc};
use contour_core::limits::{JointLimits, PathLimits};
use contour_core::math;
use contour_core::path::five_axis::{FiveAxisPlan, PlannedSample};

type V3 = Vector<3>;

const TS: f64 = 1e-3;

/// A straight pass along x, 60 mm in 0.5 mm CL steps, the tool axis tilting from +30°
/// to −30° about y, `beside` rad to the side of vertical (0: through it).
fn tilting_pass(beside: f64) -> Vec<Pose> {
    (0..=120)
        .map(|i| {
            let f = i as f64 / 120.0;
            let theta = (30.0 - 60.0 * f).to_radians();
            Pose {
                tip: V3::new(-30.0 + 60.0 * f, 0.0, 0.0),
                axis: V3::new(
                    math::sin(theta) * math::cos(beside),
                    math::sin(beside),
                    math::cos(theta) * math::cos(beside),
                ),
            }
        })
        .collect()
}

/// A finishing raster over a hemisphere of radius 40 mm, the tool normal to the surface:
/// passes along x at step-over 2 mm (the middle one over the apex), zigzag, 0.5 mm steps,
/// within 45° of the apex.
fn dome_raster(passes: i32) -> Vec<Pose> {
    let r = 40.0;
    let mut poses = Vec::new();
    for (k, j) in (-passes..=passes).enumerate() {
        let y = 2.0 * j as f64;
        let half = ((r * math::sin(45f64.to_radians())).powi(2) - y * y).sqrt();
        let steps = (2.0 * half / 0.5).ceil() as usize;
        for i in 0..=steps {
            let f = i as f64 / steps as f64;
            let f = if k % 2 == 0 { f } else { 1.0 - f };
            let x = -half + 2.0 * half * f;
            let p = V3::new(x, y, (r * r - x * x - y * y).sqrt());
            poses.push(Pose {
                tip: p,
                axis: p / r,
            });
        }
    }
    poses
}

fn name(i: usize) -> String {
    format!("pose {i}")
}

/// Every sample of `plan` from its start to rest at the end.
fn samples(plan: FiveAxisPlan) -> (Vec<PlannedSample>, std::sync::Arc<FiveAxisPlan>) {
    let mut cursor = plan.start();
    let mut out = vec![plan.sample(&mut cursor)];
    while !out[out.len() - 1].done {
        plan.advance(&mut cursor);
        out.push(plan.sample(&mut cursor));
    }
    (out, std::sync::Arc::new(plan))
}

/// Every joint within travel, velocity and acceleration, by differences of the samples;
/// the tip within feed, accel and jerk, and within the tolerances of the CL path. The
/// differences are of the samples themselves, so the only slack is the filter's
/// quantum (2⁻³⁰ per joint) over Ts² or Ts³.
fn assert_within(samples: &[PlannedSample], joints: &JointLimits, limits: &PathLimits, what: &str) {
    let q = |k: usize| samples[k].joints;
    let p = |k: usize| samples[k].pose.tip;
    let quantum = 2f64.powi(-30);
    for k in 0..samples.len() {
        for i in 0..5 {
            assert!(
                q(k)[i] >= joints.min[i] - quantum && q(k)[i] <= joints.max[i] + quantum,
                "{what}: joint {i} at {} outside its travel at sample {k}",
                q(k)[i]
            );
        }
        if k >= 1 {
            let v = (q(k) - q(k - 1)) / TS;
            for i in 0..5 {
                assert!(
                    v[i].abs() <= joints.velocity[i] * (1.0 + 1e-9) + 2.0 * quantum / TS,
                    "{what}: joint {i} at {} /s at sample {k}",
                    v[i]
                );
            }
            let speed = geometry::dist(&p(k), &p(k - 1)) / TS;
            assert!(
                speed <= limits.feed * (1.0 + 1e-6),
                "{what}: tip at {speed} mm/s, sample {k}"
            );
        }
        if k >= 2 {
            let a = (q(k) - q(k - 1) * 2.0 + q(k - 2)) / (TS * TS);
            for i in 0..5 {
                assert!(
                    a[i].abs() <= joints.acceleration[i] * (1.0 + 1e-9) + 4.0 * quantum / TS / TS,
                    "{what}: joint {i} at {} /s² at sample {k}",
                    a[i]
                );
            }
            let accel = geometry::norm(&(p(k) - p(k - 1) * 2.0 + p(k - 2))) / (TS * TS);
            assert!(
                accel <= limits.accel * (1.0 + 1e-6) + 1e-3,
                "{what}: tip at {accel} mm/s², sample {k}"
            );
        }
        if k >= 3 && limits.jerk > 0.0 {
            let jerk =
                geometry::norm(&(p(k) - p(k - 1) * 3.0 + p(k - 2) * 3.0 - p(k - 3))) / TS.powi(3);
            assert!(
                jerk <= limits.jerk * (1.0 + 1e-6) + 1.0,
                "{what}: tip at {jerk} mm/s³, sample {k}"
            );
        }
    }
}

/// The distance of `tip` from the CL polyline and the angle of `axis` from the CL axis at
/// that point, by brute force over every CL segment; where the tool turns on the spot
/// within `tolerance` of the tip, every axis of the turn (sampled) counts as programmed.
fn cl_deviation(cl: &[Pose], pose: &Pose, tolerance: f64) -> (f64, f64) {
    let mut best = (f64::INFINITY, 0.0);
    let mut on_a_turn = f64::INFINITY;
    for w in cl.windows(2) {
        let d = w[1].tip - w[0].tip;
        if d.norm_squared() == 0.0 {
            let distance = geometry::dist(&w[0].tip, &pose.tip);
            let angles = (0..=10_000)
                .map(|k| geometry::slerp(&w[0].axis, &w[1].axis, k as f64 / 1e4).unwrap())
                .map(|axis| geometry::angle_between(&axis, &pose.axis));
            let nearest_axis = angles.fold(f64::INFINITY, f64::min);
            if distance <= tolerance {
                on_a_turn = on_a_turn.min(nearest_axis);
            }
            if distance < best.0 {
                best = (distance, geometry::angle_between(&w[0].axis, &pose.axis));
            }
            continue;
        }
        let t = ((pose.tip - w[0].tip).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
        let distance = geometry::dist(&(w[0].tip + d * t), &pose.tip);
        if distance < best.0 {
            let axis = geometry::slerp(&w[0].axis, &w[1].axis, t).unwrap();
            best = (distance, geometry::angle_between(&axis, &pose.axis));
        }
    }
    (best.0, best.1.min(on_a_turn))
}

fn plan(
    cl: &[Pose],
    joints: &JointLimits,
    limits: &PathLimits,
) -> (Vec<PlannedSample>, std::sync::Arc<FiveAxisPlan>) {
    samples(FiveAxisPlan::new(cl, TableTiltingAc::default(), joints, limits, TS, &name).unwrap())
}

fn check_all(
    cl: &[Pose],
    joints: &JointLimits,
    limits: &PathLimits,
    what: &str,
) -> Vec<PlannedSample> {
    let (s, plan) = plan(cl, joints, limits);
    assert_within(&s, joints, limits, what);
    let (mut tip, mut axis) = (0.0f64, 0.0f64);
    for sample in &s {
        let (d, a) = cl_deviation(cl, &sample.pose, limits.tolerance);
        tip = tip.max(d);
        axis = axis.max(a);
    }
    assert!(
        tip <= limits.tolerance * (1.0 + 1e-6),
        "{what}: tip {tip} mm off the CL path"
    );
    assert!(
        axis <= limits.orientation_tolerance * (1.0 + 1e-6),
        "{what}: axis {axis} rad off"
    );
    // It rests exactly on the path's end: the last node's joints, to the last bit.
    let end = plan.joint_path().joints.last().copied().unwrap();
    assert_eq!(s[s.len() - 1].joints, end, "{what}");
    assert!((s[s.len() - 1].pose.tip - cl[cl.len() - 1].tip).amax() < 1e-12);
    let report = plan.report();
    eprintln!("{what}: {report:?}, brute force tip {tip:.3e} axis {axis:.3e}");
    // Within 10 % of the velocity-and-acceleration optimum, and even of its lower bound
    // that judges accelerations over the filter's T1 and ignores the tolerances.
    assert!(
        report.relaxed_optimum <= report.optimum * (1.0 + 1e-9),
        "{what}"
    );
    assert!(
        report.duration <= 1.1 * report.relaxed_optimum,
        "{what}: {} s against {} s",
        report.duration,
        report.relaxed_optimum
    );
    // The mapping of the limits onto s foresees what the samples do: a round or two
    // of slowing down, not a search.
    assert!(report.rounds <= 3, "{what}: {} rounds", report.rounds);
    // The plan's own measure of its deviation is the brute force's.
    assert!(
        (report.tip_deviation - tip).abs() <= 1e-9 + 1e-6 * tip,
        "{what}"
    );
    s
}

fn c_travel(samples: &[PlannedSample]) -> f64 {
    let c: Vec<f64> = samples.iter().map(|s| s.joints[4]).collect();
    c.iter().cloned().fold(f64::MIN, f64::max) - c.iter().cloned().fold(f64::MAX, f64::min)
}

#[test]
fn through_vertical_the_branch_switches_and_c_stays() {
    let joints = JointLimits::default();
    let limits = PathLimits::at_feed(50.0);
    let s = check_all(&tilting_pass(0.0), &joints, &limits, "through vertical");
    assert!(c_travel(&s) < 1e-6, "C turned by {}", c_travel(&s));
    let a_first = s[0].joints[3];
    let a_last = s[s.len() - 1].joints[3];
    assert!((a_first.abs() - 30f64.to_radians()).abs() < 1e-9);
    assert!((a_first + a_last).abs() < 1e-9, "{a_first} -> {a_last}");
}

#[test]
fn through_vertical_with_a_positive_only_c_turns_through_the_cone() {
    let mut joints = JointLimits::default();
    joints.min[3] = 0.0;
    let limits = PathLimits::at_feed(50.0);
    let s = check_all(&tilting_pass(0.0), &joints, &limits, "A >= 0");
    let turn = c_travel(&s);
    assert!(
        (turn - std::f64::consts::PI).abs() < 1e-6,
        "C turned by {turn}"
    );
    assert!(s.iter().all(|x| x.joints[3] >= 0.0));
}

#[test]
fn beside_vertical_c_swings_within_its_limits() {
    let joints = JointLimits::default();
    let limits = PathLimits::at_feed(50.0);
    let s = check_all(
        &tilting_pass(0.5f64.to_radians()),
        &joints,
        &limits,
        "beside vertical",
    );
    eprintln!("C travel {}", c_travel(&s));
}

#[test]
fn a_tool_turning_on_the_spot_tilts_where_its_tip_stands() {
    // Along x, a stop at x = 10 where the tool tilts 36.87° about x (A), then on.
    let axis = V3::new(0.0, 0.6, 0.8);
    let vertical = V3::new(0.0, 0.0, 1.0);
    let cl = [
        Pose {
            tip: V3::new(0.0, 0.0, 0.0),
            axis: vertical,
        },
        Pose {
            tip: V3::new(10.0, 0.0, 0.0),
            axis: vertical,
        },
        Pose {
            tip: V3::new(10.0, 0.0, 0.0),
            axis,
        },
        Pose {
            tip: V3::new(20.0, 0.0, 0.0),
            axis,
        },
    ];
    let joints = JointLimits::default();
    let s = check_all(&cl, &joints, &PathLimits::at_feed(20.0), "turn on the spot");
    let turning: Vec<&PlannedSample> = s
        .iter()
        .filter(|x| x.joints[3].abs() > 1e-3 && x.joints[3].abs() < 0.6435 - 1e-3)
        .collect();
    // The turn takes at least what A's speed limit allows, and the tip stands meanwhile.
    assert!(turning.len() as f64 * TS >= 0.6435 / joints.velocity[3] * 0.99);
    for x in turning {
        assert!(
            (x.pose.tip - V3::new(10.0, 0.0, 0.0)).amax() < 5e-3,
            "{:?}",
            x.pose.tip
        );
    }
}

#[test]
fn a_dome_raster_over_its_apex() {
    let joints = JointLimits::default();
    let limits = PathLimits::at_feed(50.0);
    check_all(&dome_raster(2), &joints, &limits, "dome");
}

/// Why a plan of `poses` at 50 mm/s within `joints` is refused.
fn refusal(poses: &[Pose], joints: &JointLimits) -> String {
    FiveAxisPlan::new(
        poses,
        TableTiltingAc::default(),
        joints,
        &PathLimits::at_feed(50.0),
        TS,
        &name,
    )
    .unwrap_err()
    .to_string()
}

#[test]
fn a_path_beyond_the_a_travel_is_refused_naming_the_pose() {
    let mut joints = JointLimits::default();
    joints.max[3] = 20f64.to_radians();
    joints.min[3] = -20f64.to_radians();
    let e = refusal(&tilting_pass(0.0), &joints);
    // 30° → −30° in 0.5° steps: pose 20 is the first beyond 20°... from the start, pose 0 is.
    assert!(e.contains("pose 0"), "{e}");
    // The joint, the value it needs and its travel.
    assert!(
        e.contains("A would have to be 30.000° (or -30.000° on the other branch), outside its travel -20.000° … 20.000°"),
        "{e}"
    );
}

#[test]
fn a_path_beyond_a_limited_c_travel_is_refused_naming_c_and_its_travel() {
    // A pass round the part at 30° tilt, the axis leaning outward: C follows the
    // azimuth through a whole turn, and a C limited to ±90° cannot.
    let mut joints = JointLimits::default();
    joints.min[4] = -90f64.to_radians();
    joints.max[4] = 90f64.to_radians();
    let round: Vec<Pose> = (0..=360)
        .map(|i| {
            let angle = (i as f64).to_radians();
            let (s, c) = (math::sin(angle), math::cos(angle));
            let tilt = 30f64.to_radians();
            Pose {
                tip: V3::new(40.0 * c, 40.0 * s, 0.0),
                axis: V3::new(math::sin(tilt) * c, math::sin(tilt) * s, math::cos(tilt)),
            }
        })
        .collect();
    let e = refusal(&round, &joints);
    assert!(
        e.contains("no turn of it keeps C within its travel -90.000° … 90.000°"),
        "{e}"
    );
    assert!(e.contains("tool axis 30.000° from the C axis"), "{e}");
}

#[test]
fn a_straight_tilting_pass_takes_the_trapezoid_time_plus_the_filter() {
    // 60 mm at 50 mm/s with 2000 mm/s²: L/v + v/a = 1.225 s, the velocity-and-acceleration
    // optimum of the tip alone (the joints' limits do not bind on this pass). The jerk
    // filter adds its own length, 25 ms.
    let (s, plan) = plan(
        &tilting_pass(0.0),
        &JointLimits::default(),
        &PathLimits::at_feed(50.0),
    );
    let optimum = 60.0 / 50.0 + 50.0 / 2000.0;
    let duration = (s.len() - 1) as f64 * TS;
    assert!((plan.report().duration - duration).abs() < 1e-12);
    assert!(
        duration <= 1.1 * optimum,
        "{duration} s against {optimum} s"
    );
    assert!(
        duration >= optimum,
        "{duration} s is faster than the optimum {optimum} s"
    );
    // The plan's own optimum agrees with the trapezoid to its grid.
    let own = plan.report().relaxed_optimum;
    assert!((own / optimum - 1.0).abs() < 0.02, "{own}");
}

#[test]
fn a_path_too_long_for_the_sample_budget_is_refused_before_any_planning() {
    // 10 km at 50 mm/s: 2·10⁸ samples at 1 ms, beyond the 2²⁶ a plan may have: refused
    // from the length before any node is made (they alone would be 1.3 GB).
    let far = [
        Pose {
            tip: V3::zeros(),
            axis: V3::z(),
        },
        Pose {
            tip: V3::new(1e7, 0.0, 0.0),
            axis: V3::z(),
        },
    ];
    let e = FiveAxisPlan::new(
        &far,
        TableTiltingAc::default(),
        &JointLimits::default(),
        &PathLimits::at_feed(50.0),
        TS,
        &name,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("more than the 67108864 samples a plan may have"),
        "{e}"
    );
}
