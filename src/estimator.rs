//! The one estimator interface that the rod, flatland and 3D scenes implement.
//!
//! An [`Estimator`] samples one path (or one path pair, for double
//! randomization) per call and writes one Monte Carlo weight per declared
//! [`Quantity`] into a caller-provided slice: the intensity, the sensitivity
//! to every declared parameter, the spatial gradient. A scene with twelve
//! parameters gets its twelve sensitivities from the same call, and the hot
//! loop allocates nothing. The [`runner`](crate::runner) turns the weights
//! into estimates.
use crate::rng::PathRng;
use crate::stats::ChunkSums;
use serde::Serialize;
use std::fmt;

/// What one weight slot estimates.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize)]
#[serde(tag = "kind", content = "name", rename_all = "snake_case")]
pub enum Quantity {
    /// The intensity `I` at the probe.
    Intensity,
    /// `∂I/∂π` for the named shape parameter `π`.
    Sensitivity(String),
    /// The spatial derivative `∂I/∂x` along the named axis.
    Gradient(String),
}

impl Quantity {
    /// `Quantity::Sensitivity(name)`.
    pub fn sensitivity(name: &str) -> Quantity {
        Quantity::Sensitivity(name.to_owned())
    }

    /// `Quantity::Gradient(axis)`.
    pub fn gradient(axis: &str) -> Quantity {
        Quantity::Gradient(axis.to_owned())
    }
}

impl fmt::Display for Quantity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Quantity::Intensity => write!(f, "I"),
            Quantity::Sensitivity(p) => write!(f, "∂I/∂{p}"),
            Quantity::Gradient(a) => write!(f, "∂I/∂{a}"),
        }
    }
}

/// A Monte Carlo estimator of one or more quantities at one probe.
///
/// `sample` must be a pure function of the generator's state: the runner's
/// reproducibility rests on it.
pub trait Estimator: Sync {
    /// Short name of the method (`"intensity"`, `"expectation"`, …).
    fn method(&self) -> &'static str;

    /// The quantities, in the order `sample` writes their weights.
    fn quantities(&self) -> Vec<Quantity>;

    /// Samples one path (or path pair) and writes one weight per quantity
    /// into `weights` (of length `self.quantities().len()`).
    fn sample(&self, rng: &mut PathRng, weights: &mut [f64]);

    /// Warnings about particular quantities, found when the estimator was
    /// built (finite differences whose two displaced problems differ in the
    /// sensor's view, say): their estimates may be far off whatever their
    /// error bars say, and are reported unreliable. None by default.
    fn caveats(&self) -> Vec<(Quantity, String)> {
        Vec::new()
    }

    /// Samples `paths` paths and adds their weights to `sums` (one
    /// accumulator per quantity). This provided loop is compiled once per
    /// estimator, so even through `dyn Estimator` the runner pays one
    /// dynamic call per chunk and `sample` is called statically (and
    /// inlined); estimators need not override it.
    #[inline]
    fn accumulate(&self, rng: &mut PathRng, paths: u64, sums: &mut [ChunkSums]) {
        let mut w = vec![0.0; sums.len()];
        for _ in 0..paths {
            self.sample(rng, &mut w);
            for (s, &x) in sums.iter_mut().zip(&w) {
                s.push(x);
            }
        }
    }
}
