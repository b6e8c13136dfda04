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
//! - the *count of non-zero weights*: below [`Estimate::MIN_NONZERO`] the
//!   sample variance rests on too few values to mean anything (at 0 it is
//!   `0 ± 0` whatever the truth).
//!
//! Neither can see what was never sampled: a weight of huge size and tiny
//! probability that no path hit leaves a small, wrong error bar and clean
//! diagnostics (the stability map of the book's chapter "Comparing the
//! approaches" shows where this happens).
//!
//! Overflow is never hidden: power sums that overflow give a NaN or infinite
//! moment, hence a non-finite standard error or VOV and an unreliable
//! estimate, not a clamped 0.
use serde::ser::{Serialize, SerializeStruct, Serializer};

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
    /// Jumps counted apart ([`ChunkSums::track_jumps`]), if the estimator
    /// counts them.
    jumps: Option<u64>,
}

impl ChunkSums {
    /// Declares that this quantity's weights rest on rare jumps the
    /// estimator counts ([`ChunkSums::push_jump`]): the estimate is then
    /// reliable only with [`Estimate::MIN_NONZERO`] of them or more.
    #[inline]
    pub fn track_jumps(&mut self) {
        self.jumps.get_or_insert(0);
    }

    /// Counts one jump (a weight, pushed as usual, that came from one).
    #[inline]
    pub fn push_jump(&mut self) {
        *self.jumps.get_or_insert(0) += 1;
    }

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
                jumps: self.jumps,
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
            nonzero: self.n,
            mean: self.shift + m,
            m2: rounding_floor(s2 - n * m2),
            m3: s3 - 3.0 * m * s2 + 2.0 * n * m2 * m,
            m4: rounding_floor(s4 - 4.0 * m * s3 + 6.0 * m2 * s2 - 3.0 * n * m2 * m2),
            max_abs: self.max_abs,
            sum_abs: self.sum_abs,
            jumps: self.jumps,
        }
    }
}

/// An even central moment, whose rounding may leave it slightly below 0,
/// clamped at 0; NaN and ±∞ (overflowed power sums) pass through, unlike
/// `f64::max`, which would turn NaN into 0.
/// The sums of one pixel's stratified samples, for one quantity: the
/// current stratum's [`ChunkSums`], and over the strata closed so far the
/// sum of their means, of their means' variances, and their pooled
/// moments. Equal-area strata: the pixel's mean is the mean of the strata's
/// means, its variance `Σ_s (s_s² / n_s) / S²` (`s_s²` the stratum's sample
/// variance); the reliability diagnostics (VOV, non-zero count, largest
/// share) come from the pooled weights.
#[derive(Debug, Clone, Copy, Default)]
pub struct StratumSums {
    stratum: ChunkSums,
    pooled: Moments,
    means: f64,
    variances: f64,
    strata: u32,
    jumps: bool,
}

impl StratumSums {
    /// Counts jumps in every stratum ([`ChunkSums::track_jumps`]).
    pub fn track_jumps(&mut self) {
        self.jumps = true;
        self.stratum.track_jumps();
    }

    /// Counts one jump in the current stratum ([`ChunkSums::push_jump`]).
    #[inline]
    pub fn push_jump(&mut self) {
        self.stratum.push_jump();
    }

    /// Adds one weight to the current stratum.
    #[inline]
    pub fn push(&mut self, w: f64) {
        self.stratum.push(w);
    }

    /// Closes the current stratum (it must hold two weights or more for
    /// its variance).
    pub fn end_stratum(&mut self) {
        let m = self.stratum.moments();
        let n = m.n as f64;
        self.means += m.mean;
        self.variances += m.m2 / ((n - 1.0) * n);
        self.pooled = self.pooled.merge(&m);
        self.strata += 1;
        self.stratum = ChunkSums::default();
        if self.jumps {
            self.stratum.track_jumps();
        }
    }

    /// The moments of every weight of the closed strata, pooled.
    pub fn pooled(&self) -> Moments {
        self.pooled
    }

    /// The pixel's estimate.
    pub fn estimate(&self) -> Estimate {
        let s = f64::from(self.strata.max(1));
        // A spread lost to underflow in the pooled weights is lost in the
        // strata's variances too (`Moments::lost_to_underflow`).
        let stderr = if self.pooled.lost_to_underflow() {
            f64::NAN
        } else {
            self.variances.sqrt() / s
        };
        Estimate {
            mean: self.means / s,
            stderr,
            ..self.pooled.estimate()
        }
    }
}

/// How far above the subnormal range (per weight) a sum of squared
/// deviations must lie to be trusted ([`Moments::lost_to_underflow`]).
const UNDERFLOW_GUARD: f64 = 1048576.0;

/// Relative difference of `Σ|w|` and `nonzero · max|w|` beyond which the
/// weights' absolute values differ ([`Moments::lost_to_underflow`]): above
/// the rounding of a sum of equal weights (~10⁻¹⁶ per addition), far below
/// any real spread of the weights.
const SAME_WEIGHTS: f64 = 1e-9;

#[inline]
fn rounding_floor(v: f64) -> f64 {
    if v < 0.0 { 0.0 } else { v }
}

/// Count, mean and central moment sums `Mk = Σ(w − w̄)^k`, k = 2..4, of a set
/// of weights; merging two sets is exact up to rounding and associative in
/// exact arithmetic, so the runner merges in a fixed order for bit
/// reproducibility.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Moments {
    /// Number of weights.
    pub n: u64,
    /// Number of non-zero weights among them.
    pub nonzero: u64,
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
    /// Jumps among the weights, where the estimator counts them (see
    /// [`ChunkSums::track_jumps`]).
    pub jumps: Option<u64>,
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
        let jumps = match (self.jumps, other.jumps) {
            (None, None) => None,
            (a, b) => Some(a.unwrap_or(0) + b.unwrap_or(0)),
        };
        if self.n == 0 {
            return Moments { jumps, ..*other };
        }
        if other.n == 0 {
            return Moments { jumps, ..*self };
        }
        let (na, nb) = (self.n as f64, other.n as f64);
        let n = na + nb;
        let d = other.mean - self.mean;
        let d2 = d * d;
        Moments {
            n: self.n + other.n,
            nonzero: self.nonzero + other.nonzero,
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
            jumps,
        }
    }

    /// Whether the weights vary but their squared deviations underflowed
    /// (weights below ~10⁻¹⁵⁴: a rod 380 mean free paths long, a lamp of
    /// radiance 10⁻¹⁷⁰), so that `m2` is 0 or subnormal: the error bar would
    /// read 0 ± 0 (or a few ulps of the smallest double) and the estimate
    /// "reliable" whatever its error (seen in random scenes: 1.43e-184 ± 0 against the
    /// exact 1.33e-184; −5.7e-168 ± 0 against +2.8e-193). The weights vary
    /// for sure when zeros sit beside non-zero weights, or when their
    /// absolute values do not all equal the largest (`Σ|w|` against
    /// `nonzero · max|w|`, to a rounding): then a spread of 0 is a lost
    /// one, and the standard error is NaN, as for an overflow.
    pub fn lost_to_underflow(&self) -> bool {
        let k = self.nonzero as f64;
        let varies = (self.nonzero > 0 && self.n > self.nonzero)
            || (self.sum_abs - k * self.max_abs).abs() > SAME_WEIGHTS * self.sum_abs;
        varies && self.m2 < UNDERFLOW_GUARD * self.n as f64 * f64::MIN_POSITIVE
    }

    /// The user-facing estimate of the mean. Non-finite moments (overflowed
    /// power sums) give a non-finite standard error and VOV.
    pub fn estimate(&self) -> Estimate {
        let n = self.n as f64;
        let variance = if self.lost_to_underflow() {
            f64::NAN
        } else if self.n > 1 {
            self.m2 / (n - 1.0)
        } else {
            0.0
        };
        let vov = if !(variance.is_finite() && self.m2.is_finite() && self.m4.is_finite()) {
            // The error bar's own error cannot be computed: say so.
            f64::NAN
        } else if self.m2 > 0.0 {
            let m2_squared = self.m2 * self.m2;
            let ratio = if m2_squared.is_finite() {
                self.m4 / m2_squared
            } else {
                // Finite moments whose square overflows (weights ≳ 1e77).
                self.m4 / self.m2 / self.m2
            };
            rounding_floor(ratio - 1.0 / n)
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
            nonzero: self.nonzero,
            n: self.n,
            vov,
            max_share,
            jumps: self.jumps,
        }
    }
}

/// A Monte Carlo estimate with its error bar and tail diagnostics.
///
/// Serialised (JSON) as `mean`, `stderr`, `nonzero`, `reliable` (the value of
/// [`Estimate::is_reliable`]), `n`, `vov` and `max_share`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// Sample mean of the weights.
    pub mean: f64,
    /// Standard error of the mean, `sqrt(var / N)` (0 for exact values; NaN
    /// or ∞ if the variance overflowed).
    pub stderr: f64,
    /// Number of non-zero weights: how many paths contributed.
    pub nonzero: u64,
    /// Number of samples (paths or path pairs).
    pub n: u64,
    /// Relative variance of the variance estimate (see the module docs; NaN
    /// if the moments overflowed).
    pub vov: f64,
    /// Largest weight's share of `Σ|w|`.
    pub max_share: f64,
    /// Jumps the estimate rests on, where its estimator counts them: a
    /// central difference's pairs of paths that one side of the step
    /// changed discontinuously (one blocked, the other not, say), which
    /// carry its whole boundary part. `None` where not counted.
    pub jumps: Option<u64>,
}

impl Estimate {
    /// VOV above which the error bar is flagged as unreliable (MCNP's rule).
    pub const VOV_LIMIT: f64 = 0.1;

    /// Fewest non-zero weights for a reliable error bar.
    ///
    /// With `k` equal non-zero weights among `N ≫ k` zeros the VOV is
    /// `1/k − 1/N`, so [`VOV_LIMIT`](Self::VOV_LIMIT) already flags fewer
    /// than about 10 of them, except where the VOV cannot see: at `k = 0`
    /// (every weight 0: `0 ± 0`, VOV 0) and for a few weights that happen
    /// to be alike. Ten non-zero weights is the same bar stated as a count:
    /// a Poisson count of 10 is known to ±32 %, and so is an error bar that
    /// rests on it. A quantity that is exactly 0 (no path can contribute) is
    /// therefore flagged too: the sample cannot tell it from a quantity
    /// whose contributing paths were never drawn.
    pub const MIN_NONZERO: u64 = 10;

    /// An exact value: zero error, no samples.
    pub fn exact(value: f64) -> Estimate {
        Estimate {
            mean: value,
            stderr: 0.0,
            nonzero: 0,
            n: 0,
            vov: 0.0,
            max_share: 0.0,
            jumps: None,
        }
    }

    /// Whether the error bar can be trusted. A sampled estimate (`n > 0`) is
    /// reliable when its mean, standard error and VOV are finite, at least
    /// [`MIN_NONZERO`](Self::MIN_NONZERO) weights were non-zero (and as
    /// many jumps, where they are counted: a weight of tiny probability
    /// that no path drew leaves the other diagnostics clean, and a
    /// central difference knows how many of its pairs jumped; but not more
    /// than half of them: a boundary's share of the pairs shrinks with the
    /// step, and when most pairs jump, `I` itself jumps at the nominal
    /// parameter, where no derivative exists (a radiance sensor aimed
    /// exactly at a lamp's end: every pair jumped and fd read 1762 ± 0 at
    /// one step, −17 579 ± 0 at another, both "reliable"), and the VOV
    /// is below [`VOV_LIMIT`](Self::VOV_LIMIT). An exact value (`n = 0`) is
    /// reliable when finite. The largest weight's share is reported beside
    /// it for the reader to judge (it is at least 1/N, so no fixed threshold
    /// suits every N).
    pub fn is_reliable(&self) -> bool {
        let finite = self.mean.is_finite() && self.stderr.is_finite() && self.vov.is_finite();
        if self.n == 0 {
            return finite;
        }
        finite
            && self.nonzero >= Self::MIN_NONZERO
            && self
                .jumps
                .is_none_or(|k| k >= Self::MIN_NONZERO && 2 * k <= self.n)
            && self.vov < Self::VOV_LIMIT
    }

    /// Distance from `reference` in standard errors (∞ if the error bar is 0
    /// and the values differ).
    pub fn z_score(&self, reference: f64) -> f64 {
        let d = (self.mean - reference).abs();
        if d == 0.0 { 0.0 } else { d / self.stderr }
    }
}

impl Serialize for Estimate {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let fields = 7 + usize::from(self.jumps.is_some());
        let mut s = serializer.serialize_struct("Estimate", fields)?;
        s.serialize_field("mean", &self.mean)?;
        s.serialize_field("stderr", &self.stderr)?;
        s.serialize_field("nonzero", &self.nonzero)?;
        s.serialize_field("reliable", &self.is_reliable())?;
        s.serialize_field("n", &self.n)?;
        s.serialize_field("vov", &self.vov)?;
        s.serialize_field("max_share", &self.max_share)?;
        if let Some(k) = self.jumps {
            s.serialize_field("jumps", &k)?;
        } else {
            s.skip_field("jumps")?;
        }
        s.end()
    }
}

#[cfg(test)]
mod tests;
