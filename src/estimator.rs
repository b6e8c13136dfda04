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
use crate::stats::{ChunkSums, StratumSums};
use serde::{Deserialize, Serialize};
use std::fmt;

/// Where in a camera's image one path starts: pixel `pixel` (row-major,
/// row 0 at the top), and stratum `stratum` of the `strata × strata` grid
/// that splits its footprint (the path's direction is uniform in it).
/// Ignored by the other sensors.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PixelSample {
    /// Pixel index, `row × width + column`.
    pub pixel: u32,
    /// Stratum index in `0..strata²`, row-major.
    pub stratum: u32,
    /// Strata per side (1: the whole footprint).
    pub strata: u32,
}

/// The relative size below which a weight is the rounding residue of terms
/// that cancel exactly, not a signal: about 450 units of roundoff. A slab
/// translated along its own faces, for one, gives entry and exit terms equal
/// and opposite, and their computed difference (or the speed of a face
/// relative to a vertex that moves with it, or a central difference of two
/// paths that differ only by the rounding of the displaced geometry) is a
/// few units of roundoff of the terms. Reported as is, such weights make a
/// derivative that is exactly 0 read "−4e-18 ± 3e-20, reliable", a z-score
/// of 150 against the truth; set to 0, it reads "0 ± 0", flagged as
/// resting on no non-zero weight. A genuine weight that small beside its
/// terms would itself be mostly rounding.
pub const ROUNDING: f64 = 1e-13;

/// Whether `value`, computed from terms whose sizes add up to `scale`, is
/// their rounding residue ([`ROUNDING`]): then it is taken for 0.
#[inline]
pub fn within_rounding(value: f64, scale: f64) -> bool {
    value.abs() <= ROUNDING * scale
}

/// What one weight slot estimates.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize, Deserialize)]
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

    /// For a camera sensor: the image's `(width, height)`; the runner's
    /// [`render`](crate::image::render) then estimates every pixel. `None`
    /// (the default) for a probe.
    fn image(&self) -> Option<(u32, u32)> {
        None
    }

    /// Samples one path through `pixel` (a camera's); other sensors ignore
    /// it, and so does the default.
    fn sample_pixel(&self, rng: &mut PathRng, pixel: PixelSample, weights: &mut [f64]) {
        let _ = pixel;
        self.sample(rng, weights);
    }

    /// Samples `spp` paths through pixel `pixel`, stratified over its
    /// footprint ([`stratified`]), and adds their weights to `sums`.
    #[inline]
    fn accumulate_pixel(&self, rng: &mut PathRng, pixel: u32, spp: u64, sums: &mut [StratumSums]) {
        let mut w = vec![0.0; sums.len()];
        stratified(pixel, spp, sums, &mut w, |s, w| {
            self.sample_pixel(rng, s, w)
        });
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

/// Fewest samples in a stratum: each stratum's variance is estimated from
/// its own samples, and a stratum that a feature covers in part shows none
/// of it when all its samples miss (variance 0, the estimate off by the
/// feature's share): with two samples and a feature over 15 % of the
/// stratum, 72 % of the time; with eight, 27 %; with sixteen, 7 %.
pub const STRATUM_SAMPLES: u64 = 16;

/// Strata per side for `spp` samples of a pixel: the largest `m` with at
/// least [`STRATUM_SAMPLES`] samples in each of the `m²` strata; 1 below
/// 64 samples.
pub fn strata_per_side(spp: u64) -> u64 {
    let mut m = ((spp / STRATUM_SAMPLES) as f64).sqrt().floor().max(1.0) as u64;
    while m > 1 && STRATUM_SAMPLES * m * m > spp {
        m -= 1;
    }
    m
}

/// Samples `spp` paths through `pixel` stratified over its footprint,
/// `sample` writing each path's weights into `w`, and adds them to `sums`
/// (one per quantity): stratum `s` of the `m²` ([`strata_per_side`]) gets
/// `⌊spp/m²⌋` paths, one more for the first `spp mod m²`, in turn.
#[inline]
pub fn stratified(
    pixel: u32,
    spp: u64,
    sums: &mut [StratumSums],
    w: &mut [f64],
    mut sample: impl FnMut(PixelSample, &mut [f64]),
) {
    stratified_marked(pixel, spp, sums, w, &mut [], |s, w, _| sample(s, w));
}

/// [`stratified`], `sample` also setting `jumped[k]` when quantity `k`'s
/// weight came from a jump (a central difference's: see
/// [`StratumSums::push_jump`]); `jumped` may be shorter than `sums` (empty:
/// no jumps counted).
#[inline]
pub fn stratified_marked(
    pixel: u32,
    spp: u64,
    sums: &mut [StratumSums],
    w: &mut [f64],
    jumped: &mut [bool],
    mut sample: impl FnMut(PixelSample, &mut [f64], &mut [bool]),
) {
    let m = strata_per_side(spp);
    let cells = m * m;
    let (base, extra) = (spp / cells, spp % cells);
    for stratum in 0..cells {
        let s = PixelSample {
            pixel,
            stratum: stratum as u32,
            strata: m as u32,
        };
        for _ in 0..base + u64::from(stratum < extra) {
            sample(s, w, jumped);
            for (s, &x) in sums.iter_mut().zip(w.iter()) {
                s.push(x);
            }
            for (s, j) in sums.iter_mut().zip(jumped.iter_mut()) {
                if *j {
                    s.push_jump();
                    *j = false;
                }
            }
        }
        for s in sums.iter_mut() {
            s.end_stratum();
        }
    }
}
