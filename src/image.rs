//! Images: every pixel of a camera is a probe. [`render`] runs an
//! [`Estimator`] whose sensor is a camera ([`Estimator::image`]) `spp` paths
//! per pixel, stratified over the pixel's footprint
//! ([`stratified`](crate::estimator::stratified)) with the stratified
//! estimator's own error bar ([`StratumSums`]), and keeps per pixel and per
//! quantity an [`Estimate`]: memory is the image's, whatever `spp`.
//!
//! Pixel `p` draws from [`rng::stream(seed, p)`](crate::rng::stream), rows
//! run in parallel and are collected in order, so an image is bit-identical
//! for any thread count. The image's mean pixel value comes with the
//! standard error of a mean over independent pixels,
//! `sqrt(Σ_p se_p²) / P`. Book: chapter "Three dimensions", section "A
//! camera".
use crate::error::Error;
use crate::estimator::{Estimator, Quantity};
use crate::rng;
use crate::stats::{Estimate, Moments, StratumSums};
use rayon::prelude::*;

/// Most paths per pixel.
pub const MAX_SPP: u64 = 1 << 32;

/// The images of one run: per quantity, one estimate per pixel.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageResult {
    /// Method name.
    pub method: &'static str,
    /// Pixels per row and rows.
    pub width: u32,
    /// See `width`.
    pub height: u32,
    /// Per quantity, its per-pixel estimates (row-major, row 0 at the top).
    pub images: Vec<(Quantity, Vec<Estimate>)>,
    /// Per quantity, the image's mean pixel value with its standard error
    /// over independent pixels (its other fields pool all the paths).
    pub means: Vec<Estimate>,
    /// Paths per pixel.
    pub spp: u64,
    /// Wall time of the sampling, in seconds.
    pub seconds: f64,
}

impl ImageResult {
    /// Total paths sampled.
    pub fn paths(&self) -> u64 {
        self.spp * self.width as u64 * self.height as u64
    }

    /// The per-pixel estimates of `q`.
    pub fn image(&self, q: &Quantity) -> Option<&[Estimate]> {
        self.images
            .iter()
            .find_map(|(k, e)| (k == q).then_some(e.as_slice()))
    }

    /// The image mean of `q`.
    pub fn mean(&self, q: &Quantity) -> Option<Estimate> {
        let i = self.images.iter().position(|(k, _)| k == q)?;
        Some(self.means[i])
    }
}

/// Runs `est` (a camera's) with `spp` paths per pixel from `seed` on
/// `threads` threads (0: all cores); `progress` is called with the number of
/// rows done after each row. Errors if the estimator has no camera, `spp`
/// is below 2 or above [`MAX_SPP`], or the pool cannot start.
pub fn render(
    est: &dyn Estimator,
    spp: u64,
    seed: u64,
    threads: usize,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<ImageResult, Error> {
    let Some((width, height)) = est.image() else {
        return Err(Error::Config(
            "the scene's sensor is not a camera: an image needs `[sensor] kind = \"camera\"`"
                .into(),
        ));
    };
    if !(2..=MAX_SPP).contains(&spp) {
        return Err(Error::Config(format!(
            "spp = {spp}: expected 2 to 2^32 paths per pixel (an error bar needs two)"
        )));
    }
    crate::runner::check_threads(threads)?;
    let quantities = est.quantities();
    let nq = quantities.len();
    let done = std::sync::atomic::AtomicU64::new(0);
    let row = |r: u32| -> Vec<Vec<StratumSums>> {
        let out = (0..width)
            .map(|c| {
                let p = r * width + c;
                let mut rng = rng::stream(seed, p as u64);
                let mut sums = vec![StratumSums::default(); nq];
                est.accumulate_pixel(&mut rng, p, spp, &mut sums);
                sums
            })
            .collect();
        progress(done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1);
        out
    };
    let (rows, seconds) = crate::runner::timed_on(threads, || -> Vec<Vec<Vec<StratumSums>>> {
        if threads == 1 {
            (0..height).map(row).collect()
        } else {
            (0..height).into_par_iter().map(row).collect()
        }
    })?;
    let pixels = (width as usize) * (height as usize);
    let mut images: Vec<(Quantity, Vec<Estimate>)> = quantities
        .into_iter()
        .map(|q| (q, Vec::with_capacity(pixels)))
        .collect();
    let mut pooled = vec![Moments::default(); nq];
    for pixel in rows.iter().flatten() {
        for ((_, img), (m, all)) in images.iter_mut().zip(pixel.iter().zip(&mut pooled)) {
            img.push(m.estimate());
            *all = all.merge(&m.pooled());
        }
    }
    let means = images
        .iter()
        .zip(&pooled)
        .map(|((_, img), all)| {
            let mut e = all.estimate();
            let p = img.len() as f64;
            e.mean = img.iter().map(|x| x.mean).sum::<f64>() / p;
            e.stderr = img.iter().map(|x| x.stderr * x.stderr).sum::<f64>().sqrt() / p;
            e
        })
        .collect();
    Ok(ImageResult {
        method: est.method(),
        width,
        height,
        images,
        means,
        spp,
        seconds,
    })
}
