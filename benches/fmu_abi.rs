//! One sample of `ContourCCC5X` as an importer pays for it: `fmi2SetReal` of the ten
//! inputs (reference and measured joints), `fmi2DoStep` of 1 ms (one control period),
//! `fmi2GetReal` of the five velocity commands and the two contour errors, through the
//! exported C functions (linked statically, as tests/no_alloc.rs calls them; an importer
//! adds only the dlopen'ed call's indirection). The target: at most 5 µs median
//! per sample, flat in the path length, no allocation (the last is tests/no_alloc.rs).
//!
//! `fmu_abi/contour_ccc_5x_sample`: replays the reference and measured joints of the
//! recorded five-axis closed loop on the figure-eight (as benches/five_axis.rs does in
//! process), from the freshly initialized instance each time.
//!
//! `fmu_abi/path_1k` and `fmu_abi/path_100k`: the last 500 samples of a helix reference of
//! 1 000 and of 100 000 distinct points, the tool trailing by 35 samples (the paths of
//! benches/five_axis.rs); the instance has stepped through all the points before them,
//! once, and is put back there with `fmi2SetFMUstate` before each timed run.
//!
//! `fmu_abi/five_axis_plant_round`: the same round on `FiveAxisPlant`, the lightest
//! five-axis model (five velocity commands in, five positions and velocities out): what
//! the ABI and the instance bookkeeping cost with next to no model behind them.
//!
//! Criterion's throughput gives the time per sample. At the end the bench prints the
//! median per sample of each group, taken from the same timed runs criterion analyses,
//! and the two ratios: path_100k / path_1k and contour_ccc_5x_sample / five_axis_plant_round.

use std::ffi::CString;
use std::hint::black_box;
use std::time::{Duration, Instant};

use contour_fmu::fmi2::bindings::{fmi2CallbackFunctions, fmi2Component, fmi2FMUstate};
use contour_fmu::sim::{simulate_five_axis, FiveAxisSimConfig};
use criterion::{BenchmarkGroup, Criterion, SamplingMode, Throughput};

#[path = "../tests/common/linked.rs"]
mod linked;

use linked::{
    fmi2DoStep, fmi2FreeFMUstate, fmi2FreeInstance, fmi2GetFMUstate, fmi2GetReal, fmi2SetFMUstate,
    fmi2SetReal,
};

/// Communication step = the controller's period.
const H: f64 = 1e-3;
/// Criterion samples per benchmark (set on every group, so the summary knows how many of
/// the recorded runs are criterion's samples rather than its warm-up).
const SAMPLES: usize = 100;

const CCC_INPUTS: [&str; 10] = [
    "ref.X", "ref.Y", "ref.Z", "ref.A", "ref.C", "pos.X", "pos.Y", "pos.Z", "pos.A", "pos.C",
];
const CCC_OUTPUTS: [&str; 7] = [
    "u.X",
    "u.Y",
    "u.Z",
    "u.A",
    "u.C",
    "contourError.tip",
    "contourError.orientation",
];
const PLANT_INPUTS: [&str; 5] = ["u.X", "u.Y", "u.Z", "u.A", "u.C"];
const PLANT_OUTPUTS: [&str; 10] = [
    "pos.X", "pos.Y", "pos.Z", "pos.A", "pos.C", "vel.X", "vel.Y", "vel.Z", "vel.A", "vel.C",
];

/// An initialized instance (logging off) with the value references of one round.
struct Fmu {
    c: fmi2Component,
    inputs: Vec<u32>,
    outputs: Vec<u32>,
    read: Vec<f64>,
    /// FMU states taken with [`Fmu::save`], freed with the instance.
    states: Vec<fmi2FMUstate>,
    /// The instance was given their address: they live as long as it.
    _functions: Box<fmi2CallbackFunctions>,
}

impl Fmu {
    fn new(identifier: &str, inputs: &[&str], outputs: &[&str]) -> Fmu {
        let model = linked::model(identifier);
        let functions = Box::new(linked::quiet_callbacks());
        let name = CString::new("fmu-abi-bench").unwrap();
        // SAFETY: the callbacks are boxed in the returned value, which frees the instance
        // (Drop) before they are dropped.
        let c = unsafe { linked::instantiate_started(model, &name, &*functions) };
        Fmu {
            c,
            inputs: linked::vrs(model, inputs),
            outputs: linked::vrs(model, outputs),
            read: vec![0.0; outputs.len()],
            states: Vec::new(),
            _functions: functions,
        }
    }

    /// One round per row of `rows`, the first at communication point `first · H`; returns
    /// the sum of the first output (for `black_box`).
    fn replay<const N: usize>(&mut self, first: usize, rows: &[[f64; N]]) -> f64 {
        assert_eq!(N, self.inputs.len());
        let (c, n_out) = (self.c, self.outputs.len());
        let mut sum = 0.0;
        for (k, row) in rows.iter().enumerate() {
            let t = (first + k) as f64 * H;
            // SAFETY: a live instance (freed only by Drop); value references, values and
            // the output buffer are arrays of the lengths passed. (OK is 0: the OR of the
            // three statuses is 0 only if all three calls succeeded.)
            let status = unsafe {
                fmi2SetReal(c, self.inputs.as_ptr(), N, black_box(row).as_ptr())
                    | fmi2DoStep(c, t, H, 1)
                    | fmi2GetReal(c, self.outputs.as_ptr(), n_out, self.read.as_mut_ptr())
            };
            assert_eq!(status, 0, "round at t = {t}");
            sum += self.read[0];
        }
        sum
    }

    /// The instance's current state, kept until the instance is freed.
    fn save(&mut self) -> fmi2FMUstate {
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        // SAFETY: a live instance; `state` is a variable holding NULL, as FMI asks.
        assert_eq!(unsafe { fmi2GetFMUstate(self.c, &mut state) }, 0);
        self.states.push(state);
        state
    }

    fn restore(&self, state: fmi2FMUstate) {
        // SAFETY: a live instance and a state it returned (freed only by Drop).
        assert_eq!(unsafe { fmi2SetFMUstate(self.c, state) }, 0);
    }
}

impl Drop for Fmu {
    fn drop(&mut self) {
        for state in &mut self.states {
            // SAFETY: the address of a variable holding a state of this live instance,
            // freed once.
            unsafe { fmi2FreeFMUstate(self.c, state) };
        }
        // SAFETY: a live instance, freed once; nothing uses `c` after this.
        unsafe { fmi2FreeInstance(self.c) };
    }
}

/// Per-sample times of every timed call, by benchmark, for the summary at the end.
#[derive(Default)]
struct Summary {
    runs: Vec<(&'static str, Vec<f64>)>,
}

impl Summary {
    fn record(&mut self, name: &'static str, per_sample: f64) {
        match self.runs.iter_mut().find(|(n, _)| *n == name) {
            Some((_, times)) => times.push(per_sample),
            None => self.runs.push((name, vec![per_sample])),
        }
    }

    /// The median per-sample time (s) over criterion's samples of `name`: the last
    /// [`SAMPLES`] calls (the warm-up calls come first); `None` if it did not run (filtered).
    fn median(&self, name: &str) -> Option<f64> {
        let (_, times) = self.runs.iter().find(|(n, _)| *n == name)?;
        let mut last = times[times.len().saturating_sub(SAMPLES)..].to_vec();
        last.sort_by(f64::total_cmp);
        let m = last.len() / 2;
        Some(if last.len() % 2 == 1 {
            last[m]
        } else {
            0.5 * (last[m - 1] + last[m])
        })
    }

    fn print(&self) {
        println!("\nfmu_abi: median time per sample (median over criterion's samples)");
        for (name, _) in &self.runs {
            let m = self.median(name).unwrap();
            println!("  {name:<26} {:>8.3} µs", m * 1e6);
        }
        let ratio = |a: &str, b: &str| match (self.median(a), self.median(b)) {
            (Some(a), Some(b)) => format!("{:.3}", a / b),
            _ => "(not run)".to_string(),
        };
        println!(
            "  path_100k / path_1k        {}",
            ratio("path_100k", "path_1k")
        );
        println!(
            "  sample / plant round       {}",
            ratio("contour_ccc_5x_sample", "five_axis_plant_round")
        );
    }
}

/// Benchmarks `name`: each timed run puts `fmu` back to `state` (untimed), then steps it
/// through `rows` from communication point `first · H`.
fn bench_replay<const N: usize>(
    group: &mut BenchmarkGroup<'_, criterion::measurement::WallTime>,
    summary: &mut Summary,
    name: &'static str,
    (fmu, state, first): (&mut Fmu, fmi2FMUstate, usize),
    rows: &[[f64; N]],
) {
    group.throughput(Throughput::Elements(rows.len() as u64));
    group.bench_function(name, |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                fmu.restore(state);
                let start = Instant::now();
                black_box(fmu.replay(first, rows));
                total += start.elapsed();
            }
            summary.record(
                name,
                total.as_secs_f64() / (iters as f64 * rows.len() as f64),
            );
            total
        })
    });
}

fn group<'a>(c: &'a mut Criterion) -> BenchmarkGroup<'a, criterion::measurement::WallTime> {
    let mut group = c.benchmark_group("fmu_abi");
    // Each run is milliseconds long: the same number of runs per sample (criterion's
    // advice for long routines).
    group.sampling_mode(SamplingMode::Flat).sample_size(SAMPLES);
    group
}

/// The recorded closed loop on the figure-eight, replayed on ContourCCC5X and, with its
/// velocity commands, on FiveAxisPlant.
fn bench_replays(c: &mut Criterion, summary: &mut Summary) {
    let config = FiveAxisSimConfig::builtin("figure_eight").unwrap();
    let (_, records) = simulate_five_axis(&config, true).unwrap();
    let ccc_rows: Vec<[f64; 10]> = records
        .iter()
        .map(|r| {
            let (reference, actual) = (r.reference, r.actual);
            std::array::from_fn(|i| if i < 5 { reference[i] } else { actual[i - 5] })
        })
        .collect();
    let plant_rows: Vec<[f64; 5]> = records.iter().map(|r| r.u.into()).collect();

    let mut ccc = Fmu::new("ContourCCC5X", &CCC_INPUTS, &CCC_OUTPUTS);
    let fresh = ccc.save();
    // The FMU's start values are the simulation's controller (FiveAxisConfig::DEFAULT):
    // fed the same joints, it gives the same commands, so the replay is the closed loop's
    // work sample for sample.
    let mut deviation = 0.0f64;
    for (k, (row, record)) in ccc_rows.iter().zip(&records).enumerate() {
        ccc.replay(k, std::slice::from_ref(row));
        for (u, expected) in ccc.read[..5].iter().zip(record.u.iter()) {
            deviation = deviation.max((u - expected).abs() / expected.abs().max(1.0));
        }
    }
    assert!(
        deviation < 1e-9,
        "ContourCCC5X does not reproduce the recorded commands (relative deviation {deviation:e})"
    );

    let mut plant = Fmu::new("FiveAxisPlant", &PLANT_INPUTS, &PLANT_OUTPUTS);
    let plant_fresh = plant.save();

    let mut group = group(c);
    bench_replay(
        &mut group,
        summary,
        "contour_ccc_5x_sample",
        (&mut ccc, fresh, 0),
        &ccc_rows,
    );
    bench_replay(
        &mut group,
        summary,
        "five_axis_plant_round",
        (&mut plant, plant_fresh, 0),
        &plant_rows,
    );
    group.finish();
}

/// The helix of benches/five_axis.rs as ContourCCC5X inputs: `n` distinct reference
/// samples, the measured joints trailing by 35 samples and displaced slightly.
fn helix(n: usize) -> Vec<[f64; 10]> {
    let q = |k: usize| {
        let t = k as f64 * 2.5e-3;
        [
            30.0 + 20.0 * t.cos(),
            10.0 + 20.0 * t.sin(),
            0.8 * t,
            0.35 + 0.1 * (0.3 * t).sin(),
            t,
        ]
    };
    (0..n)
        .map(|k| {
            let (reference, actual) = (q(k), q(k.saturating_sub(35)));
            std::array::from_fn(|i| {
                if i < 5 {
                    reference[i]
                } else {
                    actual[i - 5] + 2e-3
                }
            })
        })
        .collect()
}

fn bench_path_length(c: &mut Criterion, summary: &mut Summary) {
    let mut group = group(c);
    for (name, n) in [("path_1k", 1_000), ("path_100k", 100_000)] {
        let rows = helix(n);
        let (before, timed) = rows.split_at(n - 500);
        let mut ccc = Fmu::new("ContourCCC5X", &CCC_INPUTS, &CCC_OUTPUTS);
        ccc.replay(0, before);
        let warmed = ccc.save();
        bench_replay(
            &mut group,
            summary,
            name,
            (&mut ccc, warmed, before.len()),
            timed,
        );
    }
    group.finish();
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    let mut summary = Summary::default();
    bench_replays(&mut c, &mut summary);
    bench_path_length(&mut c, &mut summary);
    c.final_summary();
    summary.print();
}
