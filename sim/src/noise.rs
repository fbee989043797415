//! Seeded measurement noise: a ChaCha8 generator per sensor, Gaussian
//! samples by the Box–Muller transform.
//!
//! Each sensor derives its own stream from the run's seed and a fixed
//! sensor number, so adding a reading to one sensor never changes another's
//! noise.

use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};

/// A seeded noise source.
#[derive(Debug)]
pub struct Noise {
    rng: ChaCha8Rng,
    spare: Option<f64>,
}

impl Noise {
    /// The stream of sensor number `stream` for a run's `seed`.
    pub fn new(seed: u64, stream: u64) -> Self {
        // SplitMix64 of the pair, so neighbouring seeds give unrelated streams.
        let mut z = seed ^ stream.wrapping_mul(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        Noise { rng: ChaCha8Rng::seed_from_u64(z), spare: None }
    }

    /// A uniform sample in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.rng.random::<f64>()
    }

    /// A Gaussian sample with mean 0 and standard deviation `sigma`.
    pub fn normal(&mut self, sigma: f64) -> f64 {
        if sigma <= 0.0 {
            return 0.0;
        }
        if let Some(z) = self.spare.take() {
            return z * sigma;
        }
        let u1 = self.uniform().max(f64::MIN_POSITIVE);
        let u2 = self.uniform();
        let r = (-2.0 * u1.ln()).sqrt();
        let (s, c) = (std::f64::consts::TAU * u2).sin_cos();
        self.spare = Some(r * s);
        r * c * sigma
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f64) -> bool {
        p > 0.0 && self.uniform() < p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seeded_and_gaussian() {
        let mut a = Noise::new(7, 1);
        let mut b = Noise::new(7, 1);
        let mut c = Noise::new(7, 2);
        let xs: Vec<f64> = (0..1000).map(|_| a.normal(2.0)).collect();
        let ys: Vec<f64> = (0..1000).map(|_| b.normal(2.0)).collect();
        assert_eq!(xs, ys);
        assert_ne!(xs[0], c.normal(2.0));
        let mean = xs.iter().sum::<f64>() / 1000.0;
        let sd = (xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / 1000.0).sqrt();
        assert!(mean.abs() < 0.2 && (sd - 2.0).abs() < 0.2, "mean {mean} sd {sd}");
    }
}
