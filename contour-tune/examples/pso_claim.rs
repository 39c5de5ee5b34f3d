//! The paper's claim, checked: improved vs standard PSO on the contour-tuning objective
//! at the paper's budget (m = 50, T = 100), over 10 seeds. Prints, per objective, the
//! final fitness of each algorithm (mean ± spread, best, worst) and how many seeds each
//! won. Takes about 10 minutes on two cores.
//!
//! Usage: `cargo run --release -p contour-tune --example pso_claim [SEEDS] [SWARM] [ITERATIONS] [json]`;
//! with `json` the final fitness of every run is printed as JSON instead of the table.

use contour_core::path::planar::builtin;
use contour_core::sim::{FREE_CURVE_FEED, PAPER_CIRCLE_FEED};
use contour_tune::objective::{ContourObjective, Fitness, LOWER, UPPER};
use contour_tune::{minimize, Algorithm, PsoSettings};

fn stats(v: &[f64]) -> (f64, f64, f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let spread = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt();
    let min = v.iter().cloned().fold(f64::INFINITY, f64::min);
    let max = v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    (mean, spread, min, max)
}

fn main() {
    let arg = |i: usize, default: usize| -> usize {
        std::env::args()
            .nth(i)
            .map_or(default, |s| s.parse().expect("whole numbers"))
    };
    let (seeds, swarm, iterations) = (arg(1, 10) as u64, arg(2, 50), arg(3, 100));
    let json = std::env::args().nth(4).as_deref() == Some("json");
    let mut document = serde_json::Map::new();
    let cases = [
        ("circle", PAPER_CIRCLE_FEED, Fitness::Max),
        ("circle", PAPER_CIRCLE_FEED, Fitness::Mean),
        ("infinity", FREE_CURVE_FEED, Fitness::Mean),
        ("infinity", FREE_CURVE_FEED, Fitness::Max),
    ];
    if !json {
        println!("PSO on the contour-tuning objective, m = {swarm}, T = {iterations}, seeds 1..={seeds}; fitness in um");
        println!(
            "{:9} {:5} {:9} {:>22} {:>9} {:>9} {:>5}",
            "path", "fit", "algorithm", "mean ± spread", "best", "worst", "wins"
        );
    }
    for (name, feed, fitness) in cases {
        let objective =
            ContourObjective::new(builtin::by_name(name).unwrap(), feed, "paper", fitness).unwrap();
        let paper = objective.evaluate(&[1.0, 1.2, 87.0, 8.5, 4.0]) * 1e3;
        let mut finals = Vec::new();
        for algorithm in [Algorithm::Standard, Algorithm::Improved] {
            let runs: Vec<f64> = (1..=seeds)
                .map(|seed| {
                    let settings = PsoSettings {
                        algorithm,
                        swarm,
                        iterations,
                        lower: LOWER.to_vec(),
                        upper: UPPER.to_vec(),
                        velocity_fraction: 0.2,
                        seed,
                    };
                    minimize(settings, |x| objective.evaluate(x), |_, _| {})
                        .unwrap()
                        .fitness
                        * 1e3
                })
                .collect();
            finals.push(runs);
        }
        let fit = format!("{fitness:?}").to_lowercase();
        if json {
            document.insert(
                format!("{name}/{fit}"),
                serde_json::json!({"standard": finals[0], "improved": finals[1], "paper": paper}),
            );
            continue;
        }
        for (i, label) in ["standard", "improved"].iter().enumerate() {
            let (mean, spread, best, worst) = stats(&finals[i]);
            let wins = (0..seeds as usize)
                .filter(|&s| finals[i][s] < finals[1 - i][s])
                .count();
            println!(
                "{name:9} {fit:5} {label:9} {mean:>13.4} ± {spread:<7.4} {best:9.4} {worst:9.4} {wins:>5}"
            );
        }
        println!("{name:9} {fit:5} paper factors (1, 1.2, 87, 8.5, 4): {paper:.4}");
    }
    if json {
        println!("{}", serde_json::Value::Object(document));
    }
}
