//! One sample of the five-axis controller (axis loops + online HMM mapping + foot-point
//! errors + tip and orientation laws + damped least squares), docs/design/five-axis.md §5.
//!
//! `five_axis/sample_*`: replays the reference and measured joints of the recorded
//! closed loop on the figure-eight (2 540 samples, through its crossing) in each CCC mode;
//! criterion's throughput gives the time per sample.
//!
//! `five_axis/path_1k` and `five_axis/path_100k`: the last 500 samples of a reference of
//! 1 000 and of 100 000 distinct points (a helix, the tool trailing by 35 samples), the
//! controller having run through all the points before them — the ratio of the two shows
//! whether the cost per sample grows with the path.
//!
//! `five_axis/plan_1k` and `five_axis/plan_100k`: planning the reference of a hemisphere
//! raster of 1 000 and of 100 000 CL points (docs/design/five-axis.md §5.3b).
//! `five_axis/plan_nx_15_operations`: reading and planning the fifteen-operation NX-style
//! CL file of `cam_examples::nx_multi_operation_cls` with its own speeds (§5.3c), as the
//! interpolator FMU does at initialization (target: under 10 s).

use contour_core::math;
use std::hint::black_box;

use contour_core::control::{CccMode, FiveAxisConfig, FiveAxisController};
use contour_core::kinematics::Joints;
use contour_core::sim::{simulate_five_axis, FiveAxisSimConfig};
use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};

fn replay(controller: &mut FiveAxisController, samples: &[(Joints, Joints)]) -> f64 {
    let mut sum = 0.0;
    for (reference, actual) in samples {
        let out = controller
            .sample(black_box(reference), black_box(actual))
            .expect("finite samples");
        sum += out.u[0];
    }
    sum
}

fn bench_modes(c: &mut Criterion) {
    let mut group = c.benchmark_group("five_axis");
    for (name, mode) in [
        ("sample_off", CccMode::Off),
        ("sample_fixed", CccMode::Fixed),
        ("sample_fuzzy", CccMode::Fuzzy),
    ] {
        let config = FiveAxisSimConfig::builtin("figure_eight")
            .unwrap()
            .with_mode(mode);
        let (_, records) = simulate_five_axis(&config, true).unwrap();
        let samples: Vec<(Joints, Joints)> =
            records.iter().map(|r| (r.reference, r.actual)).collect();
        let fresh = FiveAxisController::new(config.controller).unwrap();
        group.throughput(Throughput::Elements(samples.len() as u64));
        group.bench_function(name, |b| {
            b.iter_batched_ref(
                || fresh.clone(),
                |controller| replay(controller, &samples),
                BatchSize::SmallInput,
            )
        });
    }
    group.finish();
}

/// A helix in joint space: `n` distinct reference samples, the measured joints trailing
/// by 35 samples and displaced slightly.
fn helix(n: usize) -> Vec<(Joints, Joints)> {
    let q = |k: usize| {
        let t = k as f64 * 2.5e-3;
        Joints::new(
            30.0 + 20.0 * math::cos(t),
            10.0 + 20.0 * math::sin(t),
            0.8 * t,
            0.35 + 0.1 * math::sin(0.3 * t),
            t,
        )
    };
    (0..n)
        .map(|k| (q(k), q(k.saturating_sub(35)) + Joints::repeat(2e-3)))
        .collect()
}

fn bench_path_length(c: &mut Criterion) {
    let mut group = c.benchmark_group("five_axis");
    let config = FiveAxisConfig::DEFAULT.with_mode(CccMode::Fuzzy);
    for (name, n) in [("path_1k", 1_000), ("path_100k", 100_000)] {
        let samples = helix(n);
        let (before, timed) = samples.split_at(n - 500);
        let mut warmed = FiveAxisController::new(config).unwrap();
        replay(&mut warmed, before);
        group.throughput(Throughput::Elements(timed.len() as u64));
        group.bench_function(name, |b| {
            b.iter_batched_ref(
                || warmed.clone(),
                |controller| replay(controller, timed),
                BatchSize::SmallInput,
            )
        });
    }
    group.finish();
}

/// Planning a reference from a 100 000-point CL file: a hemisphere raster at 0.25 mm CL
/// steps and 0.1 mm step-over (25 m of path, tool normal to the surface, over the apex),
/// within the default limits; and, for the ratio, the same raster at 1 000 points.
fn bench_planning(c: &mut Criterion) {
    use contour_core::kinematics::TableTiltingAc;
    use contour_core::limits::{JointLimits, PathLimits};
    use contour_core::path::five_axis::cam_examples::dome_raster;
    use contour_core::path::five_axis::FiveAxisPlan;
    let mut group = c.benchmark_group("five_axis");
    group.sample_size(10);
    for (name, stepover, passes) in [("plan_1k", 5.0, 2), ("plan_100k", 0.1, 282)] {
        let poses = dome_raster(40.0, stepover, passes, 0.25, 45f64.to_radians(), 0.0);
        eprintln!("{name}: {} CL points", poses.len());
        group.throughput(Throughput::Elements(poses.len() as u64));
        group.bench_function(name, |b| {
            b.iter(|| {
                FiveAxisPlan::new(
                    black_box(&poses),
                    TableTiltingAc::default(),
                    &JointLimits::default(),
                    &PathLimits::at_feed(50.0),
                    1e-3,
                    &|i| format!("pose {i}"),
                )
                .unwrap()
                .report()
                .duration
            })
        });
    }
    let text = contour_core::path::five_axis::cam_examples::nx_multi_operation_cls();
    group.bench_function("plan_nx_15_operations", |b| {
        b.iter(|| {
            use contour_core::part_program::cl_data::parse_cl;
            use contour_core::path::five_axis::{program_feeds, SAMPLE_BUDGET};
            let program = parse_cl(black_box(&text), "nx.cls").unwrap();
            let poses = program.poses();
            let feeds = program_feeds(&program, 50.0, 100.0);
            FiveAxisPlan::within_budget(
                (&poses, &feeds),
                TableTiltingAc::default(),
                &JointLimits::default(),
                &PathLimits::at_feed(50.0),
                1e-3,
                &|i| format!("pose {i}"),
                SAMPLE_BUDGET,
            )
            .unwrap()
            .report()
            .duration
        })
    });
    group.finish();
}

criterion_group!(benches, bench_modes, bench_path_length, bench_planning);
criterion_main!(benches);
