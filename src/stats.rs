//! Monte Carlo statistics: the per-chunk accumulator of weights, the exact
//! merge of accumulators across chunks (Chan et al.'s and Pébay's pairwise
//! update of the central moments up to order 4), and the [`Estimate`] a user
//! reads: mean, standard error, sample count and two tail diagnostics.
//!
//! The tail diagnostics say when the error bar itself cannot be trusted:
//! - the *relative variance of the variance* (VOV, as in MCNP),
//!   `VOV = Σ(w−w̄)⁴ / (Σ(w−w̄)²)² − 1/N`, the squared relative error of the
//!   estimated variance; below 0.1 the error bar is usually trustworthy;
//! - the *largest weight's share* `max|w| / Σ|w|`: a share near 1 means one
//!   path made the estimate.
//!
//! Neither can see what was never sampled: a weight of huge size and tiny
//! probability that no path hit leaves a small, wrong error bar and clean
//! diagnostics (the stability map of the book's chapter "Comparing the
//! approaches" shows where this happens).
use serde::Serialize;

/// Hot-loop accumulator over one chunk: power sums of the weights shifted by
/// the chunk's first weight (no division per sample, and the shift keeps the
/// power sums well conditioned).
#[derive(Debug, Clone, Copy, Default)]
pub struct ChunkSums {
    n: u64,
    /// Zero weights, counted apart: most sensitivity weights of a path are
    /// exactly zero, and they need no arithmetic in the hot loop.
    zeros: u64,
    shift: f64,
    s1: f64,
    s2: f64,
    s3: f64,
    s4: f64,
    max_abs: f64,
    sum_abs: f64,
}

impl ChunkSums {
    /// Adds one weight.
    #[inline]
    pub fn push(&mut self, w: f64) {
        if w == 0.0 {
            self.zeros += 1;
            return;
        }
        if self.n == 0 {
            self.shift = w;
        }
        self.n += 1;
        let d = w - self.shift;
        let d2 = d * d;
        self.s1 += d;
        self.s2 += d2;
        self.s3 += d2 * d;
        self.s4 += d2 * d2;
        let a = w.abs();
        self.sum_abs += a;
        self.max_abs = self.max_abs.max(a);
    }

    /// Central moments of the chunk.
    pub fn moments(&self) -> Moments {
        let total = self.n + self.zeros;
        if self.n == 0 {
            return Moments {
                n: total,
                ..Moments::default()
            };
        }
        // Each zero weight is `d = −shift` from the shift.
        let (z, c) = (self.zeros as f64, self.shift);
        let c2 = c * c;
        let (s1, s2, s3, s4) = (
            self.s1 - z * c,
            self.s2 + z * c2,
            self.s3 - z * c2 * c,
            self.s4 + z * c2 * c2,
        );
        let n = total as f64;
        let m = s1 / n;
        let m2 = m * m;
        Moments {
            n: total,
            mean: self.shift + m,
            m2: (s2 - n * m2).max(0.0),
            m3: s3 - 3.0 * m * s2 + 2.0 * n * m2 * m,
            m4: (s4 - 4.0 * m * s3 + 6.0 * m2 * s2 - 3.0 * n * m2 * m2).max(0.0),
            max_abs: self.max_abs,
            sum_abs: self.sum_abs,
        }
    }
}

/// Count, mean and central moment sums `Mk = Σ(w − w̄)^k`, k = 2..4, of a set
/// of weights; merging two sets is exact up to rounding and associative in
/// exact arithmetic, so the runner merges in a fixed order for bit
/// reproducibility.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Moments {
    /// Number of weights.
    pub n: u64,
    /// Their mean.
    pub mean: f64,
    /// Σ(w − w̄)².
    pub m2: f64,
    /// Σ(w − w̄)³.
    pub m3: f64,
    /// Σ(w − w̄)⁴.
    pub m4: f64,
    /// Largest |w|.
    pub max_abs: f64,
    /// Σ|w|.
    pub sum_abs: f64,
}

impl Moments {
    /// Moments of a slice of weights (a reference for tests and small samples).
    pub fn of(weights: &[f64]) -> Moments {
        let mut c = ChunkSums::default();
        weights.iter().for_each(|&w| c.push(w));
        c.moments()
    }

    /// The moments of the union of `self` and `other` (Pébay 2008, Eq. 3.1).
    pub fn merge(&self, other: &Moments) -> Moments {
        if self.n == 0 {
            return *other;
        }
        if other.n == 0 {
            return *self;
        }
        let (na, nb) = (self.n as f64, other.n as f64);
        let n = na + nb;
        let d = other.mean - self.mean;
        let d2 = d * d;
        Moments {
            n: self.n + other.n,
            mean: self.mean + d * nb / n,
            m2: self.m2 + other.m2 + d2 * na * nb / n,
            m3: self.m3
                + other.m3
                + d2 * d * na * nb * (na - nb) / (n * n)
                + 3.0 * d * (na * other.m2 - nb * self.m2) / n,
            m4: self.m4
                + other.m4
                + d2 * d2 * na * nb * (na * na - na * nb + nb * nb) / (n * n * n)
                + 6.0 * d2 * (na * na * other.m2 + nb * nb * self.m2) / (n * n)
                + 4.0 * d * (na * other.m3 - nb * self.m3) / n,
            max_abs: self.max_abs.max(other.max_abs),
            sum_abs: self.sum_abs + other.sum_abs,
        }
    }

    /// The user-facing estimate of the mean.
    pub fn estimate(&self) -> Estimate {
        let n = self.n as f64;
        let variance = if self.n > 1 { self.m2 / (n - 1.0) } else { 0.0 };
        let vov = if self.m2 > 0.0 {
            (self.m4 / (self.m2 * self.m2) - 1.0 / n).max(0.0)
        } else {
            0.0
        };
        let max_share = if self.sum_abs > 0.0 {
            self.max_abs / self.sum_abs
        } else {
            0.0
        };
        Estimate {
            mean: self.mean,
            stderr: (variance / n).sqrt(),
            n: self.n,
            vov,
            max_share,
        }
    }
}

/// A Monte Carlo estimate with its error bar and tail diagnostics.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Estimate {
    /// Sample mean of the weights.
    pub mean: f64,
    /// Standard error of the mean, `sqrt(var / N)` (0 for exact values).
    pub stderr: f64,
    /// Number of samples (paths or path pairs).
    pub n: u64,
    /// Relative variance of the variance estimate (see the module docs).
    pub vov: f64,
    /// Largest weight's share of `Σ|w|`.
    pub max_share: f64,
}

impl Estimate {
    /// VOV above which the error bar is flagged as unreliable (MCNP's rule).
    pub const VOV_LIMIT: f64 = 0.1;
    /// An exact value: zero error, no samples.
    pub fn exact(value: f64) -> Estimate {
        Estimate {
            mean: value,
            stderr: 0.0,
            n: 0,
            vov: 0.0,
            max_share: 0.0,
        }
    }

    /// False when the VOV says the error bar cannot be trusted. The largest
    /// weight's share is reported beside it for the reader to judge (it is
    /// at least 1/N, so no fixed threshold suits every N).
    pub fn is_reliable(&self) -> bool {
        self.vov < Self::VOV_LIMIT
    }

    /// Distance from `reference` in standard errors (∞ if the error bar is 0
    /// and the values differ).
    pub fn z_score(&self, reference: f64) -> f64 {
        let d = (self.mean - reference).abs();
        if d == 0.0 { 0.0 } else { d / self.stderr }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two-pass central moments: the independent reference.
    fn two_pass(w: &[f64]) -> (f64, f64, f64, f64) {
        let n = w.len() as f64;
        let mean = w.iter().sum::<f64>() / n;
        let m = |k: i32| w.iter().map(|x| (x - mean).powi(k)).sum::<f64>();
        (mean, m(2), m(3), m(4))
    }

    #[test]
    fn merge_matches_two_pass() {
        let w: Vec<f64> = (0..1000)
            .map(|i| ((i * 7919) % 1013) as f64 * 0.01 + 100.0)
            .collect();
        let (mean, m2, m3, m4) = two_pass(&w);
        let merged = w
            .chunks(77)
            .map(Moments::of)
            .fold(Moments::default(), |a, b| a.merge(&b));
        assert_eq!(merged.n, 1000);
        approx::assert_relative_eq!(merged.mean, mean, max_relative = 1e-12);
        approx::assert_relative_eq!(merged.m2, m2, max_relative = 1e-9);
        assert!((merged.m3 - m3).abs() < 1e-7 * m4.sqrt() * m2.sqrt());
        approx::assert_relative_eq!(merged.m4, m4, max_relative = 1e-9);
    }

    #[test]
    fn estimate_and_diagnostics() {
        let e = Moments::of(&[1.0, 2.0, 3.0, 4.0]).estimate();
        assert_eq!(e.mean, 2.5);
        // var = 5/3, stderr = sqrt(5/12)
        assert!((e.stderr - (5.0f64 / 12.0).sqrt()).abs() < 1e-15);
        assert!((e.max_share - 0.4).abs() < 1e-15);
        // one big weight among zeros: VOV ≈ 1, share = 1
        let mut w = vec![0.0; 999];
        w.push(1.0);
        let e = Moments::of(&w).estimate();
        assert!(e.vov > 0.9 && e.max_share == 1.0 && !e.is_reliable());
        // constant weights: zero variance, reliable
        assert!(Moments::of(&[3.0; 10]).estimate().is_reliable());
    }
}
