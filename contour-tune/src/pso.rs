//! Particle swarm optimisation, standard and improved (docs/design/two-axis.md §4.4), behind one ask/tell
//! interface: the caller asks for the positions to evaluate, evaluates them however it
//! likes (in parallel), and tells the fitness back. All randomness comes from one seeded
//! ChaCha8 stream consumed in a fixed order, so the same seed gives the same run
//! whatever the evaluation order or thread count.

use contour_core::math;
use rand_chacha::rand_core::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// How inertia and learning factors evolve over the iterations.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Algorithm {
    /// w falls linearly from 0.9 to 0.4; c1 = c2 = 2.
    Standard,
    /// The paper's improvement: w falls along a sigmoid (w_start 0.9, w_end 0.4, α 3.4,
    /// β 0.07) and the learning factors follow it (c1 from 1 to 0.5, c2 from 0.5 to 1).
    Improved,
}

impl std::str::FromStr for Algorithm {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "standard" => Ok(Algorithm::Standard),
            "improved" => Ok(Algorithm::Improved),
            _ => Err(format!(
                "unknown algorithm '{s}': expected improved or standard"
            )),
        }
    }
}

const W_START: f64 = 0.9;
const W_END: f64 = 0.4;
const ALPHA: f64 = 3.4;
const BETA: f64 = 0.07;
const C_START: f64 = 0.5;
const C_END: f64 = 1.0;

/// Inertia weight and learning factors (w, c1, c2) at iteration `t` of `iterations`.
pub fn coefficients(algorithm: Algorithm, t: usize, iterations: usize) -> (f64, f64, f64) {
    match algorithm {
        Algorithm::Standard => {
            let fraction = if iterations > 1 {
                t as f64 / (iterations - 1) as f64
            } else {
                0.0
            };
            (W_START - (W_START - W_END) * fraction, 2.0, 2.0)
        }
        Algorithm::Improved => {
            // The paper's formula was lost; docs/design/two-axis.md §4.4 reconstructs it as this sigmoid.
            let w = W_END + (W_START - W_END) / (1.0 + math::exp(BETA * t as f64 - ALPHA));
            let lambda = (w - W_END) / (W_START - W_END);
            let c1 = C_START + (C_END - C_START) * lambda * lambda;
            let c2 = C_END - (C_END - C_START) * lambda * lambda;
            (w, c1, c2)
        }
    }
}

/// Everything that defines a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PsoSettings {
    pub algorithm: Algorithm,
    /// Particles (m).
    pub swarm: usize,
    /// Iterations (T), the first being the random initial swarm: T·m evaluations.
    pub iterations: usize,
    /// Inclusive lower and upper bound per dimension.
    pub lower: Vec<f64>,
    pub upper: Vec<f64>,
    /// Velocity clamp as a fraction of each dimension's range.
    pub velocity_fraction: f64,
    pub seed: u64,
}

impl PsoSettings {
    /// Checks the settings; the error says which one is wrong.
    pub fn validate(&self) -> Result<(), String> {
        if self.swarm == 0 {
            return Err("the swarm needs at least one particle".into());
        }
        if self.iterations == 0 {
            return Err("at least one iteration is needed".into());
        }
        if self.lower.is_empty() || self.lower.len() != self.upper.len() {
            return Err(format!(
                "bounds need one lower and one upper value per dimension (got {} and {})",
                self.lower.len(),
                self.upper.len()
            ));
        }
        for (d, (lo, hi)) in self.lower.iter().zip(&self.upper).enumerate() {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(format!(
                    "bounds of dimension {d} must be finite with lower < upper (got [{lo}, {hi}])"
                ));
            }
        }
        if !(self.velocity_fraction > 0.0 && self.velocity_fraction <= 1.0) {
            return Err(format!(
                "velocity fraction must be in (0, 1] (got {})",
                self.velocity_fraction
            ));
        }
        Ok(())
    }
}

/// A swarm being optimised (minimisation).
pub struct Swarm {
    settings: PsoSettings,
    rng: ChaCha8Rng,
    positions: Vec<Vec<f64>>,
    velocities: Vec<Vec<f64>>,
    personal_best: Vec<Vec<f64>>,
    personal_fitness: Vec<f64>,
    global_best: Vec<f64>,
    global_fitness: f64,
    /// Iterations told so far.
    iteration: usize,
    history: Vec<f64>,
}

/// Uniform in [0, 1) from the top 53 bits.
fn unit(rng: &mut ChaCha8Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// NaN counts as the worst possible fitness, so it never becomes a best.
fn worse(a: f64, b: f64) -> bool {
    a.is_nan() || (!b.is_nan() && a >= b)
}

impl Swarm {
    /// A random swarm inside the bounds with random velocities inside the clamp.
    pub fn new(settings: PsoSettings) -> Result<Self, String> {
        settings.validate()?;
        let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
        let dims = settings.lower.len();
        let mut positions = Vec::with_capacity(settings.swarm);
        let mut velocities = Vec::with_capacity(settings.swarm);
        for _ in 0..settings.swarm {
            let mut x = Vec::with_capacity(dims);
            let mut v = Vec::with_capacity(dims);
            for d in 0..dims {
                let range = settings.upper[d] - settings.lower[d];
                x.push(settings.lower[d] + unit(&mut rng) * range);
                v.push((2.0 * unit(&mut rng) - 1.0) * settings.velocity_fraction * range);
            }
            positions.push(x);
            velocities.push(v);
        }
        Ok(Swarm {
            personal_best: positions.clone(),
            personal_fitness: vec![f64::NAN; settings.swarm],
            global_best: positions[0].clone(),
            global_fitness: f64::NAN,
            positions,
            velocities,
            rng,
            settings,
            iteration: 0,
            history: Vec::new(),
        })
    }

    /// The positions to evaluate next.
    pub fn ask(&self) -> &[Vec<f64>] {
        &self.positions
    }

    /// Whether every iteration has been told.
    pub fn is_done(&self) -> bool {
        self.iteration >= self.settings.iterations
    }

    /// Records the fitness of the positions from [`Swarm::ask`] (same order) and, unless
    /// done, moves the swarm.
    pub fn tell(&mut self, fitness: &[f64]) -> Result<(), String> {
        if self.is_done() {
            return Err("the run is finished".into());
        }
        if fitness.len() != self.positions.len() {
            return Err(format!(
                "{} fitness values for {} particles",
                fitness.len(),
                self.positions.len()
            ));
        }
        for (i, &f) in fitness.iter().enumerate() {
            if !worse(f, self.personal_fitness[i]) {
                self.personal_fitness[i] = f;
                self.personal_best[i].clone_from(&self.positions[i]);
            }
            if !worse(f, self.global_fitness) {
                self.global_fitness = f;
                self.global_best.clone_from(&self.positions[i]);
            }
        }
        self.history.push(self.global_fitness);
        self.iteration += 1;
        if !self.is_done() {
            self.advance();
        }
        Ok(())
    }

    fn advance(&mut self) {
        let s = &self.settings;
        let (w, c1, c2) = coefficients(s.algorithm, self.iteration, s.iterations);
        for i in 0..self.positions.len() {
            for d in 0..s.lower.len() {
                let r1 = unit(&mut self.rng);
                let r2 = unit(&mut self.rng);
                let x = self.positions[i][d];
                let vmax = s.velocity_fraction * (s.upper[d] - s.lower[d]);
                let v = w * self.velocities[i][d]
                    + c1 * r1 * (self.personal_best[i][d] - x)
                    + c2 * r2 * (self.global_best[d] - x);
                let v = v.clamp(-vmax, vmax);
                let moved = (x + v).clamp(s.lower[d], s.upper[d]);
                // A particle stopped by a wall loses the velocity that pushed it there.
                self.velocities[i][d] = moved - x;
                self.positions[i][d] = moved;
            }
        }
    }

    pub fn best(&self) -> (&[f64], f64) {
        (&self.global_best, self.global_fitness)
    }

    /// Best fitness after each iteration told so far.
    pub fn history(&self) -> &[f64] {
        &self.history
    }

    pub fn settings(&self) -> &PsoSettings {
        &self.settings
    }
}

/// A finished run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PsoResult {
    pub best: Vec<f64>,
    pub fitness: f64,
    pub history: Vec<f64>,
}

/// Runs a whole optimisation, evaluating each iteration's particles in parallel with
/// rayon; `progress` sees (iteration, best fitness) after every iteration.
pub fn minimize<F>(
    settings: PsoSettings,
    objective: F,
    mut progress: impl FnMut(usize, f64),
) -> Result<PsoResult, String>
where
    F: Fn(&[f64]) -> f64 + Sync,
{
    use rayon::prelude::*;
    let mut swarm = Swarm::new(settings)?;
    while !swarm.is_done() {
        let fitness: Vec<f64> = swarm.ask().par_iter().map(|x| objective(x)).collect();
        swarm.tell(&fitness)?;
        progress(swarm.history().len(), swarm.best().1);
    }
    let (best, fitness) = swarm.best();
    Ok(PsoResult {
        best: best.to_vec(),
        fitness,
        history: swarm.history().to_vec(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(algorithm: Algorithm, seed: u64) -> PsoSettings {
        PsoSettings {
            algorithm,
            swarm: 30,
            iterations: 100,
            lower: vec![-5.12; 5],
            upper: vec![5.12; 5],
            velocity_fraction: 0.2,
            seed,
        }
    }

    fn sphere(x: &[f64]) -> f64 {
        x.iter().map(|v| v * v).sum()
    }

    #[test]
    fn improved_schedule_follows_design() {
        let (w0, c1, c2) = coefficients(Algorithm::Improved, 0, 100);
        assert!((w0 - (0.4 + 0.5 / (1.0 + math::exp(-3.4f64)))).abs() < 1e-15);
        assert!((w0 - 0.8838).abs() < 1e-3);
        let lambda = (w0 - 0.4) / 0.5;
        assert!((c1 - (0.5 + 0.5 * lambda * lambda)).abs() < 1e-15);
        assert!((c1 + c2 - 1.5).abs() < 1e-15);
        let (w99, c1, c2) = coefficients(Algorithm::Improved, 99, 100);
        assert!((w99 - 0.4).abs() < 0.02 && c1 < 0.51 && c2 > 0.99);
        // Midpoint at t = α/β ≈ 48.6.
        let (w48, ..) = coefficients(Algorithm::Improved, 48, 100);
        let (w49, ..) = coefficients(Algorithm::Improved, 49, 100);
        assert!(w48 > 0.65 && w49 < 0.65);
        assert_eq!(coefficients(Algorithm::Standard, 99, 100), (0.4, 2.0, 2.0));
    }

    #[test]
    fn same_seed_same_run_and_sphere_solved() {
        for algorithm in [Algorithm::Standard, Algorithm::Improved] {
            let a = minimize(settings(algorithm, 7), sphere, |_, _| {}).unwrap();
            let b = minimize(settings(algorithm, 7), sphere, |_, _| {}).unwrap();
            assert_eq!(a, b);
            assert_eq!(a.history.len(), 100);
            assert!(a.history.windows(2).all(|w| w[1] <= w[0]));
            // 3000 evaluations on the 5-D sphere from [-5.12, 5.12]^5 (start ≈ 44).
            assert!(a.fitness < 1e-4, "{algorithm:?}: {}", a.fitness);
            let c = minimize(settings(algorithm, 8), sphere, |_, _| {}).unwrap();
            assert_ne!(a.best, c.best);
        }
    }

    #[test]
    fn nan_fitness_never_becomes_best_and_bad_settings_are_refused() {
        let r = minimize(
            settings(Algorithm::Improved, 1),
            |x| if x[0] > 0.0 { f64::NAN } else { sphere(x) },
            |_, _| {},
        )
        .unwrap();
        assert!(r.fitness.is_finite() && r.best[0] <= 0.0);
        let mut s = settings(Algorithm::Improved, 1);
        s.swarm = 0;
        assert!(Swarm::new(s)
            .err()
            .unwrap()
            .contains("at least one particle"));
        let mut s = settings(Algorithm::Improved, 1);
        s.lower[2] = 6.0;
        assert!(Swarm::new(s).err().unwrap().contains("dimension 2"));
        let mut s = settings(Algorithm::Improved, 1);
        s.upper.pop();
        assert!(Swarm::new(s).is_err());
    }
}
