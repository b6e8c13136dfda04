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
use crate::runner::{Progress, Stop};
use crate::stats::{Estimate, Moments, StratumSums};
#[cfg(feature = "parallel")]
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

/// One pixel's result for one quantity: its estimate's mean and standard
/// error (from its strata) and the moments of all its weights pooled (the
/// reliability diagnostics). What a shard of a rendering keeps per pixel.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PixelSums {
    /// The pixel's mean (the mean of its strata's means).
    pub mean: f64,
    /// Its stratified standard error.
    pub stderr: f64,
    /// The moments of all its weights.
    pub pooled: Moments,
}

impl PixelSums {
    /// The pixel's sums of one quantity, its strata closed.
    pub fn of(s: &StratumSums) -> PixelSums {
        let e = s.estimate();
        PixelSums {
            mean: e.mean,
            stderr: e.stderr,
            pooled: s.pooled(),
        }
    }

    /// The pixel's estimate (as [`StratumSums::estimate`]).
    pub fn estimate(&self) -> Estimate {
        Estimate {
            mean: self.mean,
            stderr: self.stderr,
            ..self.pooled.estimate()
        }
    }
}

/// Checks that `est` has a camera and `spp` is in range; its image size.
fn image_size(est: &dyn Estimator, spp: u64) -> Result<(u32, u32), Error> {
    let Some(size) = est.image() else {
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
    Ok(size)
}

/// Bytes an image holds per pixel and quantity at its peak, while its
/// pixels' sums, their estimates and the planes written out coexist
/// (measured: 405 MB for 1024² pixels of two quantities).
pub const BYTES_PER_PIXEL: usize = 64
    + std::mem::size_of::<PixelSums>()
    + std::mem::size_of::<Estimate>()
    + 4 * std::mem::size_of::<f64>();
// The bound covers what a run was measured to hold.
const _: () = assert!(BYTES_PER_PIXEL >= 193);

/// The memory this machine has free, from `/proc/meminfo` (none where it
/// cannot be read: no check).
fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.saturating_mul(1024))
}

/// Refuses an image of `pixels` pixels and `quantities` images each whose
/// sums would not fit in the memory free now, before the run: the
/// allocation would otherwise fail hours in, and abort the process (a
/// Python interpreter with it). `within`, where known, is the memory free.
pub fn check_image_memory(
    pixels: u64,
    quantities: usize,
    within: Option<u64>,
) -> Result<(), Error> {
    let need = (pixels as u128) * (quantities.max(1) as u128) * (BYTES_PER_PIXEL as u128);
    match within {
        Some(free) if need > u128::from(free) => Err(Error::Config(format!(
            "the image needs about {:.1} GB ({pixels} pixels × {quantities} quantities × \
             {BYTES_PER_PIXEL} bytes) and {:.1} GB of memory is free: render fewer pixels \
             or fewer parameters",
            need as f64 / 1e9,
            free as f64 / 1e9
        ))),
        _ => Ok(()),
    }
}

/// Renders pixels `pixels` (row-major indices, row 0 at the top) of
/// `est`'s camera, `spp` paths per pixel from `seed` on `threads` threads
/// (0: all cores); `progress` is called with the number of pixels done
/// after each pixel, and its error stops the rendering at the next pixel
/// ([`Progress`]). Returns, per pixel of the range and per quantity, its
/// [`PixelSums`], and the wall time. A pixel's samples depend on its index
/// only, so any split of the pixels (a shard's share of an image, even of a
/// single row) gives the same pixels. Errors as [`render`], and for a range
/// past the image's last pixel.
pub fn render_pixels(
    est: &dyn Estimator,
    spp: u64,
    seed: u64,
    threads: usize,
    pixels: std::ops::Range<u64>,
    progress: Progress,
) -> Result<(Vec<Vec<PixelSums>>, f64), Error> {
    let (width, height) = image_size(est, spp)?;
    crate::runner::check_threads(threads)?;
    let all = u64::from(width) * u64::from(height);
    if pixels.start > pixels.end || pixels.end > all {
        return Err(Error::Config(format!(
            "pixels {}..{}: the image has {all}",
            pixels.start, pixels.end
        )));
    }
    let nq = est.quantities().len();
    check_image_memory(pixels.end - pixels.start, nq, available_memory())?;
    let done = std::sync::atomic::AtomicU64::new(0);
    let stop = Stop::default();
    // The range in pieces of at most a row (cut at row starts): the unit of
    // work a thread takes, as rows were before an image could be split.
    let width = u64::from(width);
    let piece = |k: u64| -> std::ops::Range<u64> {
        let start = pixels.start.max(k * width);
        start..pixels.end.min((k + 1) * width)
    };
    let pieces = if pixels.is_empty() {
        0..0
    } else {
        pixels.start / width..(pixels.end - 1) / width + 1
    };
    let run = |k: u64| -> Vec<Vec<PixelSums>> {
        let range = piece(k);
        let mut out = Vec::with_capacity((range.end - range.start) as usize);
        for p in range {
            if stop.stopping() {
                break;
            }
            let mut rng = rng::stream(seed, p);
            let mut sums = vec![StratumSums::default(); nq];
            // An image's pixels are fewer than 2³² (a side is at most
            // `mesh::camera::MAX_SIDE` = 8192 pixels).
            est.accumulate_pixel(&mut rng, p as u32, spp, &mut sums);
            out.push(sums.iter().map(PixelSums::of).collect());
            stop.check(progress(
                done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1,
            ));
        }
        out
    };
    let (pieces, seconds) = crate::runner::timed_on(threads, || -> Vec<Vec<Vec<PixelSums>>> {
        #[cfg(feature = "parallel")]
        if threads != 1 {
            return pieces.into_par_iter().map(run).collect();
        }
        pieces.map(run).collect()
    })?;
    stop.into_result()?;
    Ok((pieces.into_iter().flatten().collect(), seconds))
}

/// The images of every pixel's sums (`pixels`: row-major, all of them),
/// with the image means: what [`render`] returns.
pub fn assemble(
    method: &'static str,
    quantities: Vec<Quantity>,
    (width, height): (u32, u32),
    spp: u64,
    pixels: &[Vec<PixelSums>],
    seconds: f64,
) -> ImageResult {
    let nq = quantities.len();
    let mut images: Vec<(Quantity, Vec<Estimate>)> = quantities
        .into_iter()
        .map(|q| (q, Vec::with_capacity(pixels.len())))
        .collect();
    let mut pooled = vec![Moments::default(); nq];
    for pixel in pixels {
        for ((_, img), (m, all)) in images.iter_mut().zip(pixel.iter().zip(&mut pooled)) {
            img.push(m.estimate());
            *all = all.merge(&m.pooled);
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
    ImageResult {
        method,
        width,
        height,
        images,
        means,
        spp,
        seconds,
    }
}

/// Runs `est` (a camera's) with `spp` paths per pixel from `seed` on
/// `threads` threads (0: all cores); `progress` is called with the number of
/// pixels done after each pixel ([`Progress`]: its error stops the
/// rendering and is returned). Errors if the estimator has no camera, `spp`
/// is below 2 or above [`MAX_SPP`], `threads` above
/// [`MAX_THREADS`](crate::runner::MAX_THREADS), the image would not fit in
/// the memory free ([`check_image_memory`]), or the pool cannot start.
pub fn render(
    est: &dyn Estimator,
    spp: u64,
    seed: u64,
    threads: usize,
    progress: Progress,
) -> Result<ImageResult, Error> {
    let size = image_size(est, spp)?;
    let all = u64::from(size.0) * u64::from(size.1);
    let (pixels, seconds) = render_pixels(est, spp, seed, threads, 0..all, progress)?;
    Ok(assemble(
        est.method(),
        est.quantities(),
        size,
        spp,
        &pixels,
        seconds,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_image_larger_than_the_free_memory_is_refused_before_the_run() {
        let gb = 1_000_000_000;
        assert!(check_image_memory(1024 * 1024, 2, Some(23 * gb)).is_ok());
        assert!(check_image_memory(8192 * 8192, 254, None).is_ok());
        let err = check_image_memory(8192 * 8192, 2, Some(23 * gb))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("67108864 pixels × 2 quantities") && err.contains("23.0 GB"),
            "{err}"
        );
    }
}
