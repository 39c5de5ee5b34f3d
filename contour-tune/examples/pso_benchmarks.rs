//! Runs the standard and the improved PSO on the classic benchmark functions (D = 5)
//! for a range of seeds and prints the final fitness and position of every run as JSON,
//! for tests/reference/test_pso_benchmarks.py and benches/pso_tables.py.
//!
//! Usage: `pso_benchmarks [SEEDS] [SWARM] [ITERATIONS]` (20, 30, 200).

use contour_core::math;
use contour_tune::{minimize, Algorithm, PsoSettings};
use serde_json::json;

fn sphere(x: &[f64]) -> f64 {
    x.iter().map(|v| v * v).sum()
}

fn rosenbrock(x: &[f64]) -> f64 {
    x.windows(2)
        .map(|w| 100.0 * (w[1] - w[0] * w[0]).powi(2) + (1.0 - w[0]).powi(2))
        .sum()
}

fn rastrigin(x: &[f64]) -> f64 {
    10.0 * x.len() as f64
        + x.iter()
            .map(|v| v * v - 10.0 * math::cos(2.0 * std::f64::consts::PI * v))
            .sum::<f64>()
}

type Function = fn(&[f64]) -> f64;

fn main() {
    let arg = |i: usize, default: usize| -> usize {
        std::env::args()
            .nth(i)
            .map(|s| s.parse().expect("arguments are whole numbers"))
            .unwrap_or(default)
    };
    let (seeds, swarm, iterations) = (arg(1, 20), arg(2, 30), arg(3, 200));
    let problems: [(&str, Function, f64); 3] = [
        ("sphere", sphere, 5.12),
        ("rosenbrock", rosenbrock, 5.0),
        ("rastrigin", rastrigin, 5.12),
    ];
    let mut out = serde_json::Map::new();
    for (name, f, bound) in problems {
        let mut by_algorithm = serde_json::Map::new();
        for (label, algorithm) in [
            ("standard", Algorithm::Standard),
            ("improved", Algorithm::Improved),
        ] {
            let finals: Vec<serde_json::Value> = (0..seeds as u64)
                .map(|seed| {
                    let settings = PsoSettings {
                        algorithm,
                        swarm,
                        iterations,
                        lower: vec![-bound; 5],
                        upper: vec![bound; 5],
                        velocity_fraction: 0.2,
                        seed,
                    };
                    let result = minimize(settings, f, |_, _| {}).expect("valid settings");
                    json!({"fitness": result.fitness, "best": result.best})
                })
                .collect();
            by_algorithm.insert(label.into(), json!(finals));
        }
        out.insert(name.into(), serde_json::Value::Object(by_algorithm));
    }
    println!("{}", serde_json::Value::Object(out));
}
