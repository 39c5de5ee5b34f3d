//! One controller sample as an importer pays for it, through the exported C functions
//! (linked statically, as tests/abi/no_alloc.rs calls them; an importer adds only the
//! dlopen'ed call's indirection): `fmi2SetReal` of the inputs, `fmi2DoStep` of 1 ms (one
//! control period), `fmi2GetReal` of the outputs an importer reads. Each is set against
//! the same calls with the same number of values on `PassThrough` (a test-only model that
//! copies inputs to outputs, hence the `test-hooks` feature): the ratio is the
//! controller's own cost over the ABI and instance bookkeeping. The target for
//! ContourCCC5X: at most 5 µs median per sample, flat in the path length, no allocation
//! (the last is tests/abi/no_alloc.rs).
//!
//! `fmu_abi/contour_ccc_2d_sample`: the reference and measured points of the recorded
//! two-axis closed loop on the paper's circle (4 inputs, u.x, u.y and contourError read);
//! `fmu_abi/pass_through_2d_round`: the same rows and value counts on `PassThrough`.
//!
//! `fmu_abi/contour_ccc_5x_sample`: replays the reference and measured joints of the
//! recorded five-axis closed loop on the figure-eight (as benches/five_axis.rs does in
//! process), from the freshly initialized instance each time (10 inputs, 7 outputs);
//! `fmu_abi/pass_through_5x_round`: the same rows and value counts on `PassThrough`.
//! `fmu_abi/contour_ccc_5x_dome`: the same on the recorded closed loop over a hemisphere
//! raster's apex (CL data, the reference planned within the machine's limits; 11 062
//! samples).
//!
//! `fmu_abi/path_1k` and `fmu_abi/path_100k`: the last 500 samples of a helix reference of
//! 1 000 and of 100 000 distinct points, the tool trailing by 35 samples (the paths of
//! benches/five_axis.rs); the instance has stepped through all the points before them,
//! once, and is put back there with `fmi2SetFMUstate` before each timed run.
//!
//! `fmu_abi/five_axis_plant_round`: the same round on `FiveAxisPlant`, the lightest
//! packaged five-axis model (five velocity commands in, five positions and velocities out).
//!
//! `fmu_abi/interpolator_circle`: `PathInterpolator2D` as the paper runs it (the circle at
//! constant feed; ref.x, ref.y read); `fmu_abi/interpolator_program_1k` and `_100k`: the
//! first 4 000 samples of a planned G-code spiral of 1 000 and of 100 000 short lines
//! (accel 2000 mm/s², jerk 10⁵ mm/s³, G64 P0.005: every corner a blend).
//! `fmu_abi/contour_ccc_2d_program_1k` and `_100k`: `ContourCCC2D` with
//! `estimator = program` on those spirals, the reference their planned samples and the
//! tool 35 samples behind and 10 µm off in y (against `contour_ccc_2d_sample`, the
//! free-curve estimator on the paper's circle).
//!
//! Criterion's throughput gives the time per sample. At the end the bench prints the
//! median per sample of each benchmark, taken from the same timed runs criterion
//! analyses, and the ratios controller / pass-through, path_100k / path_1k and
//! contour_ccc_5x_sample / five_axis_plant_round, measured in alternated passes timed
//! in short chunks (see [`PASSES`]: robust to other processes on a shared machine), and
//! writes them to `<target>/bench-report/fmu_abi.json` for benches/report.py.

use contour_core::math;
use std::ffi::CString;
use std::hint::black_box;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use contour_core::sim::{simulate_five_axis, FiveAxisSimConfig, SimConfig, Simulator};
use contour_fmu::framework::model::ModelInfo;
use contour_fmu::models;
use criterion::{BenchmarkGroup, Criterion, SamplingMode, Throughput};
use fmi2_bindings::{fmi2CallbackFunctions, fmi2Component, fmi2FMUstate};

#[path = "../tests/abi/common/linked.rs"]
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

const CCC_2D_INPUTS: [&str; 4] = ["ref.x", "ref.y", "pos.x", "pos.y"];
const CCC_2D_OUTPUTS: [&str; 3] = ["u.x", "u.y", "contourError"];
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
const PASS_INPUTS: [&str; 10] = [
    "in1", "in2", "in3", "in4", "in5", "in6", "in7", "in8", "in9", "in10",
];
const PASS_OUTPUTS: [&str; 10] = [
    "out1", "out2", "out3", "out4", "out5", "out6", "out7", "out8", "out9", "out10",
];

/// The model served under `identifier`, the test-only ones included (`linked::model`
/// knows the packaged models only).
fn model(identifier: &str) -> &'static ModelInfo {
    models::instantiable()
        .into_iter()
        .find(|m| m.identifier == identifier)
        .unwrap_or_else(|| panic!("no model {identifier} (PassThrough needs test-hooks)"))
}

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
        let model = model(identifier);
        let functions = Box::new(linked::quiet_callbacks());
        let name = CString::new("fmu-abi-bench").unwrap();
        // SAFETY: the callbacks are boxed in the returned value, which frees the instance
        // (Drop) before they are dropped.
        let c = unsafe { linked::instantiate_started(model, &name, &*functions) };
        Fmu::from_instance(c, model, inputs, outputs, functions)
    }

    /// The instance `c` of `model`, made with `functions`, for a round of `inputs` and
    /// `outputs`.
    fn from_instance(
        c: fmi2Component,
        model: &ModelInfo,
        inputs: &[&str],
        outputs: &[&str],
        functions: Box<fmi2CallbackFunctions>,
    ) -> Fmu {
        Fmu {
            c,
            inputs: linked::vrs(model, inputs),
            outputs: linked::vrs(model, outputs),
            read: vec![0.0; outputs.len()],
            states: Vec::new(),
            _functions: functions,
        }
    }

    /// A `PassThrough` instance called with as many values as `Fmu::new(_, inputs,
    /// outputs)`: the baseline of that round.
    fn pass_through(inputs: &[&str], outputs: &[&str]) -> Fmu {
        Fmu::new(
            "PassThrough",
            &PASS_INPUTS[..inputs.len()],
            &PASS_OUTPUTS[..outputs.len()],
        )
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

/// The ratios the summary prints and writes: (name, numerator, denominator).
const RATIOS: [(&str, &str, &str); 8] = [
    (
        "planned_over_circle_interpolator",
        "interpolator_program_1k",
        "interpolator_circle",
    ),
    (
        "interpolator_100k_over_1k",
        "interpolator_program_100k",
        "interpolator_program_1k",
    ),
    (
        "program_estimator_over_circle",
        "contour_ccc_2d_program_1k",
        "contour_ccc_2d_sample",
    ),
    (
        "program_estimator_100k_over_1k",
        "contour_ccc_2d_program_100k",
        "contour_ccc_2d_program_1k",
    ),
    (
        "ccc_2d_over_pass_through",
        "contour_ccc_2d_sample",
        "pass_through_2d_round",
    ),
    (
        "ccc_5x_over_pass_through",
        "contour_ccc_5x_sample",
        "pass_through_5x_round",
    ),
    ("path_100k_over_1k", "path_100k", "path_1k"),
    (
        "ccc_5x_over_plant_round",
        "contour_ccc_5x_sample",
        "five_axis_plant_round",
    ),
];

/// The ratios are measured after criterion, the two rounds of each alternated, in
/// [`PASSES`] timed passes; each pass times every [`CHUNK`] consecutive samples on their
/// own, and a round's time is the sum over its chunks of the chunk's median over the
/// passes. On a shared machine this leaves out the time other processes take: a chunk
/// (well under a scheduler time slice) is rarely preempted, so its median is undisturbed,
/// whereas a whole run of milliseconds is preempted in proportion to its length (medians
/// of whole runs would inflate the longer round's time, and so the ratio, with the load).
const PASSES: usize = 30;
const CHUNK: usize = 16;

/// One benchmarked round: `run(chunk, times)` puts the instance back to its starting
/// state (untimed), then steps it through all its rows, pushing the time (s) of each
/// `chunk` consecutive rows onto `times`.
struct Round {
    name: &'static str,
    samples: usize,
    run: Box<Replay>,
}

/// See [`Round`]'s `run`.
type Replay = dyn FnMut(usize, &mut Vec<f64>);

impl Round {
    /// `fmu` stepped through `rows` from `state`, the first row at communication point
    /// `first · H`.
    fn new<const N: usize>(
        name: &'static str,
        mut fmu: Fmu,
        state: fmi2FMUstate,
        first: usize,
        rows: Vec<[f64; N]>,
    ) -> Round {
        Round {
            name,
            samples: rows.len(),
            run: Box::new(move |chunk, times| {
                fmu.restore(state);
                for (j, part) in rows.chunks(chunk).enumerate() {
                    let start = Instant::now();
                    black_box(fmu.replay(first + j * chunk, part));
                    times.push(start.elapsed().as_secs_f64());
                }
            }),
        }
    }

    /// From the instance's state as it is now (freshly initialized).
    fn fresh<const N: usize>(name: &'static str, mut fmu: Fmu, rows: Vec<[f64; N]>) -> Round {
        let state = fmu.save();
        Round::new(name, fmu, state, 0, rows)
    }

    /// One timed run of all the rows (s).
    fn whole(&mut self, times: &mut Vec<f64>) -> f64 {
        times.clear();
        (self.run)(self.samples, times);
        times[0]
    }

    /// One pass in chunks of [`CHUNK`] rows: their times (s).
    fn chunked(&mut self) -> Vec<f64> {
        let mut times = Vec::with_capacity(self.samples.div_ceil(CHUNK));
        (self.run)(CHUNK, &mut times);
        times
    }
}

/// A round's time per sample (s) from its passes (see [`PASSES`]).
fn per_sample(passes: &[Vec<f64>], samples: usize) -> f64 {
    let chunks = passes[0].len();
    let total: f64 = (0..chunks)
        .map(|j| median(passes.iter().map(|p| p[j]).collect()).expect("PASSES > 0"))
        .sum();
    total / samples as f64
}

fn median(mut values: Vec<f64>) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let m = values.len() / 2;
    Some(if values.len() % 2 == 1 {
        values[m]
    } else {
        0.5 * (values[m - 1] + values[m])
    })
}

/// One of [`RATIOS`] as measured in passes: (label, ratio, numerator's and denominator's
/// time per sample in s).
type Paired = (&'static str, f64, f64, f64);

/// Per-sample times of every timed call, by benchmark, and the paired ratios, for the
/// summary at the end.
#[derive(Default)]
struct Summary {
    runs: Vec<(&'static str, Vec<f64>)>,
    paired: Vec<Paired>,
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
        median(times[times.len().saturating_sub(SAMPLES)..].to_vec())
    }

    /// Each of [`RATIOS`] whose two rounds ran, measured in alternated passes.
    fn measure_pairs(&mut self, rounds: &mut [Round]) {
        for (label, a, b) in RATIOS {
            let (Some(ia), Some(ib)) = (
                rounds.iter().position(|r| r.name == a),
                rounds.iter().position(|r| r.name == b),
            ) else {
                continue;
            };
            let (mut pa, mut pb) = (Vec::new(), Vec::new());
            for _ in 0..PASSES {
                pa.push(rounds[ia].chunked());
                pb.push(rounds[ib].chunked());
            }
            let ta = per_sample(&pa, rounds[ia].samples);
            let tb = per_sample(&pb, rounds[ib].samples);
            self.paired.push((label, ta / tb, ta, tb));
        }
    }

    fn print(&self) {
        println!("\nfmu_abi: median time per sample (median over criterion's samples)");
        for (name, _) in &self.runs {
            let m = self.median(name).unwrap();
            println!("  {name:<26} {:>8.3} µs", m * 1e6);
        }
        println!("ratios ({PASSES} alternated passes, median per {CHUNK}-sample chunk)");
        for (label, ratio, a, b) in &self.paired {
            println!(
                "  {label:<26} {ratio:>8.3}  ({:.3} µs / {:.3} µs)",
                a * 1e6,
                b * 1e6
            );
        }
    }

    /// The medians and ratios as JSON for benches/report.py; what did not run is left out.
    fn json(&self) -> serde_json::Value {
        let medians: serde_json::Map<String, serde_json::Value> = self
            .runs
            .iter()
            .filter_map(|(name, _)| Some((name.to_string(), self.median(name)?.into())))
            .collect();
        let ratios: serde_json::Map<String, serde_json::Value> = self
            .paired
            .iter()
            .map(|(label, ratio, a, b)| {
                let figures =
                    serde_json::json!({"ratio": ratio, "a_s_per_sample": a, "b_s_per_sample": b});
                (label.to_string(), figures)
            })
            .collect();
        serde_json::json!({
            "criterion_samples": SAMPLES,
            "median_s_per_sample": medians,
            "passes": PASSES,
            "chunk": CHUNK,
            "paired": ratios,
        })
    }
}

/// `<target>/bench-report`, where every part of `make bench` leaves its figures.
fn report_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map_or_else(
            || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target"),
            PathBuf::from,
        )
        .join("bench-report")
}

/// Benchmarks `round`; criterion's throughput gives the time per sample.
fn bench(
    group: &mut BenchmarkGroup<'_, criterion::measurement::WallTime>,
    summary: &mut Summary,
    round: &mut Round,
) {
    let name = round.name;
    let samples = round.samples;
    group.throughput(Throughput::Elements(samples as u64));
    group.bench_function(name, |b| {
        let mut times = Vec::with_capacity(1);
        b.iter_custom(|iters| {
            let total: f64 = (0..iters).map(|_| round.whole(&mut times)).sum();
            summary.record(name, total / (iters as f64 * samples as f64));
            Duration::from_secs_f64(total)
        })
    });
}

/// The largest relative deviation of the commands `fmu` computes from `rows` (stepped
/// from the state it is in) from the recorded ones.
fn deviation<const N: usize, const D: usize>(
    fmu: &mut Fmu,
    rows: &[[f64; N]],
    recorded: impl Iterator<Item = [f64; D]>,
) -> f64 {
    let mut deviation = 0.0f64;
    for (k, (row, expected)) in rows.iter().zip(recorded).enumerate() {
        fmu.replay(k, std::slice::from_ref(row));
        for (u, expected) in fmu.read[..D].iter().zip(expected) {
            deviation = deviation.max((u - expected).abs() / expected.abs().max(1.0));
        }
    }
    deviation
}

/// The recorded closed loop on the paper's circle, replayed on ContourCCC2D and, with the
/// same values, on PassThrough.
fn two_axis() -> Vec<Round> {
    let sim = Simulator::new(SimConfig::paper_circle()).unwrap();
    let trace = sim.run().trace;
    let rows: Vec<[f64; 4]> = trace
        .reference
        .iter()
        .zip(&trace.actual)
        .map(|(r, p)| [r[0], r[1], p[0], p[1]])
        .collect();

    let mut ccc = Fmu::new("ContourCCC2D", &CCC_2D_INPUTS, &CCC_2D_OUTPUTS);
    let fresh = ccc.save();
    // The FMU's start values are the simulation's controller (ControllerConfig::DEFAULT),
    // so the replay is the closed loop's work sample for sample.
    let recorded = trace.u.iter().map(|u| [u[0], u[1]]);
    let deviation = deviation(&mut ccc, &rows, recorded);
    assert!(
        deviation < 1e-9,
        "ContourCCC2D does not reproduce the recorded commands (relative deviation {deviation:e})"
    );
    let pass = Fmu::pass_through(&CCC_2D_INPUTS, &CCC_2D_OUTPUTS);
    vec![
        Round::new("contour_ccc_2d_sample", ccc, fresh, 0, rows.clone()),
        Round::fresh("pass_through_2d_round", pass, rows),
    ]
}

/// A spiral of `n` short lines (0.2 mm each, turning by 0.04 rad at first), every corner
/// blended within 5 µm, at 50 mm/s: written to the temporary folder, its name returned.
fn spiral_program(n: usize) -> String {
    use std::fmt::Write;
    let mut text = String::from("G21 G90 G64 P0.005\nG1 X5 Y0 F3000\n");
    for k in 1..=n {
        let phi = (k as f64 * 0.4).sqrt();
        let r = 5.0 + 0.5 * phi;
        writeln!(
            text,
            "X{:.4} Y{:.4}",
            r * math::cos(phi),
            r * math::sin(phi)
        )
        .expect("a String");
    }
    let file = std::env::temp_dir().join(format!("fmu_abi_spiral_{n}.ngc"));
    std::fs::write(&file, text).expect("the temporary folder is writable");
    file.to_string_lossy().into_owned()
}

/// The interpolator on the paper's circle, then planned on the 1k and 100k spirals; the
/// controller's program estimator on the spirals' planned samples.
fn two_axis_programs() -> Vec<Round> {
    use contour_core::path::planar::{XyLimits, XyReference};
    use linked::Start;
    const TIMED: usize = 4_000;
    let interpolator = |parameters: &[(&str, Start)]| {
        let model = model("PathInterpolator2D");
        let functions = Box::new(linked::quiet_callbacks());
        let name = CString::new("fmu-abi-bench").unwrap();
        // SAFETY: the callbacks are boxed in the returned value, which frees the instance
        // first.
        let c = unsafe { linked::instantiate_configured(model, &name, &*functions, parameters) };
        Fmu::from_instance(c, model, &[], &["ref.x", "ref.y"], functions)
    };
    let mut rounds = vec![Round::fresh(
        "interpolator_circle",
        interpolator(&[]),
        vec![[0.0f64; 0]; TIMED],
    )];
    for (n, planned, estimated) in [
        (
            1_000,
            "interpolator_program_1k",
            "contour_ccc_2d_program_1k",
        ),
        (
            100_000,
            "interpolator_program_100k",
            "contour_ccc_2d_program_100k",
        ),
    ] {
        let file = spiral_program(n);
        let limits = [
            ("path", Start::String(&file)),
            ("feed", Start::Real(50.0)),
            ("accel", Start::Real(2000.0)),
            ("jerk", Start::Real(1e5)),
        ];
        rounds.push(Round::fresh(
            planned,
            interpolator(&limits),
            vec![[0.0f64; 0]; TIMED],
        ));
        // The same plan in process: the reference rows, the tool trailing it.
        let program = contour_core::path::planar::Program::load(std::path::Path::new(&file))
            .expect("the spiral reads");
        let mut reference = XyReference::new(
            contour_core::path::planar::Path::Program(program),
            XyLimits {
                feed: 50.0,
                rapid: 100.0,
                accel: 2000.0,
                jerk: 1e5,
                tolerance: 0.0,
                ts: 1e-3,
            },
        )
        .expect("the spiral plans");
        let mut samples = vec![reference.current().point];
        while samples.len() < TIMED + 35 {
            samples.push(reference.step().point);
        }
        let rows: Vec<[f64; 4]> = (35..TIMED + 35)
            .map(|k| {
                let (r, p) = (samples[k], samples[k - 35]);
                [r[0], r[1], p[0], p[1] - 0.01]
            })
            .collect();
        let model_2d = model("ContourCCC2D");
        let functions = Box::new(linked::quiet_callbacks());
        let name = CString::new("fmu-abi-bench").unwrap();
        let parameters = [
            ("estimator", Start::Integer(4)),
            ("path", Start::String(&file)),
        ];
        // SAFETY: as above.
        let c =
            unsafe { linked::instantiate_configured(model_2d, &name, &*functions, &parameters) };
        let ccc = Fmu::from_instance(c, model_2d, &CCC_2D_INPUTS, &CCC_2D_OUTPUTS, functions);
        rounds.push(Round::fresh(estimated, ccc, rows));
    }
    rounds
}

/// The recorded closed loops replayed on ContourCCC5X on CL data: the dome raster (over a
/// hemisphere's apex, the reference planned within the machine's limits), and the pass
/// through vertical at constant feed (C flips by π at the pole: the correction stands
/// aside and the mapping restarts every sample while the machine catches up).
fn cam_paths() -> Vec<Round> {
    use contour_core::path::five_axis::cam_examples::{dome_raster, tilting_pass};
    use contour_core::path::five_axis::ToolPath;
    let replay = |name: &'static str, poses: Vec<contour_core::kinematics::Pose>, planned: bool| {
        let mut config = FiveAxisSimConfig::new(ToolPath::from_poses(&poses).unwrap(), 50.0);
        if !planned {
            config = config.unplanned();
            config.abort_tip_error = f64::INFINITY;
        }
        let (_, records) = simulate_five_axis(&config, true).unwrap();
        let rows: Vec<[f64; 10]> = records
            .iter()
            .map(|r| {
                std::array::from_fn(|i| {
                    if i < 5 {
                        r.reference[i]
                    } else {
                        r.actual[i - 5]
                    }
                })
            })
            .collect();
        let mut ccc = Fmu::new("ContourCCC5X", &CCC_INPUTS, &CCC_OUTPUTS);
        let fresh = ccc.save();
        Round::new(name, ccc, fresh, 0, rows)
    };
    let degree = 1f64.to_radians();
    vec![
        replay(
            "contour_ccc_5x_dome",
            dome_raster(40.0, 2.0, 2, 0.5, 45.0 * degree, 0.0),
            true,
        ),
        replay(
            "contour_ccc_5x_pole_at_constant_feed",
            tilting_pass(0.0, 60.0, 0.5, 30.0 * degree),
            false,
        ),
    ]
}

/// The recorded closed loop on the figure-eight, replayed on ContourCCC5X, with the same
/// values on PassThrough, and with its velocity commands on FiveAxisPlant.
fn five_axis() -> Vec<Round> {
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
    let recorded = records.iter().map(|r| <[f64; 5]>::from(r.u));
    let deviation = deviation(&mut ccc, &ccc_rows, recorded);
    assert!(
        deviation < 1e-9,
        "ContourCCC5X does not reproduce the recorded commands (relative deviation {deviation:e})"
    );
    let pass = Fmu::pass_through(&CCC_INPUTS, &CCC_OUTPUTS);
    let plant = Fmu::new("FiveAxisPlant", &PLANT_INPUTS, &PLANT_OUTPUTS);
    vec![
        Round::new("contour_ccc_5x_sample", ccc, fresh, 0, ccc_rows.clone()),
        Round::fresh("pass_through_5x_round", pass, ccc_rows),
        Round::fresh("five_axis_plant_round", plant, plant_rows),
    ]
}

/// The helix of benches/five_axis.rs as ContourCCC5X inputs: `n` distinct reference
/// samples, the measured joints trailing by 35 samples and displaced slightly.
fn helix(n: usize) -> Vec<[f64; 10]> {
    let q = |k: usize| {
        let t = k as f64 * 2.5e-3;
        [
            30.0 + 20.0 * math::cos(t),
            10.0 + 20.0 * math::sin(t),
            0.8 * t,
            0.35 + 0.1 * math::sin(0.3 * t),
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

/// ContourCCC5X on the last 500 samples of a 1 000 and a 100 000 point helix, each
/// instance having stepped through all the points before them.
fn path_lengths() -> Vec<Round> {
    [("path_1k", 1_000), ("path_100k", 100_000)]
        .into_iter()
        .map(|(name, n)| {
            let mut rows = helix(n);
            let timed = rows.split_off(n - 500);
            let mut ccc = Fmu::new("ContourCCC5X", &CCC_INPUTS, &CCC_OUTPUTS);
            ccc.replay(0, &rows);
            let warmed = ccc.save();
            Round::new(name, ccc, warmed, rows.len(), timed)
        })
        .collect()
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    let mut summary = Summary::default();
    let mut rounds = two_axis();
    rounds.extend(two_axis_programs());
    rounds.extend(five_axis());
    rounds.extend(cam_paths());
    rounds.extend(path_lengths());
    let mut group = c.benchmark_group("fmu_abi");
    // Each run is milliseconds long: the same number of runs per sample (criterion's
    // advice for long routines).
    group.sampling_mode(SamplingMode::Flat).sample_size(SAMPLES);
    for round in &mut rounds {
        bench(&mut group, &mut summary, round);
    }
    group.finish();
    c.final_summary();
    // Criterion's test, list and profile modes time nothing worth keeping; a filter that
    // left nothing to run neither.
    let modes = ["--test", "--list", "--profile-time"];
    if std::env::args().any(|a| modes.contains(&a.as_str())) || summary.runs.is_empty() {
        return;
    }
    // Only the rounds criterion ran (a filter may have left some out).
    rounds.retain(|r| summary.runs.iter().any(|(name, _)| *name == r.name));
    summary.measure_pairs(&mut rounds);
    summary.print();
    let path = report_dir().join("fmu_abi.json");
    let text = serde_json::to_string_pretty(&summary.json()).expect("plain numbers") + "\n";
    let written = std::fs::create_dir_all(report_dir()).and_then(|()| std::fs::write(&path, text));
    if let Err(e) = written {
        eprintln!("fmu_abi: cannot write {}: {e}", path.display());
    }
}
