//! The parallel, deterministic runner: paths are split into fixed-size chunks,
//! chunk `c` draws from [`rng::stream(seed, c)`](crate::rng::stream), chunks
//! run on a rayon pool, their moments are collected in chunk order and merged
//! serially. The result is therefore bit-identical for any thread count
//! (rayon's own float reductions are not: rayon-rs/rayon#663).
//!
//! The reduction is two-level, and fixed: the chunks of a *block* of
//! [`BLOCK`] chunks are merged in chunk order into the block's moments, and
//! the blocks' moments in block order into the run's. A shard of a run
//! ([`crate::shard`]) samples whole blocks and keeps their moments, so
//! merging the shards' blocks in order repeats the single run's reduction,
//! bit for bit.
//!
//! Chunks run in batches of [`BATCH`]: a batch's chunk moments are
//! collected, merged into its blocks and the blocks into the running total,
//! then dropped before the next batch starts. Memory is one batch's moments
//! whatever the path count, and the batch size changes no bit of the
//! result.
use crate::error::Error;
use crate::estimator::{Estimator, Quantity};
use crate::rng;
use crate::stats::{ChunkSums, Estimate, Moments};
#[cfg(feature = "parallel")]
use rayon::prelude::*;
use serde::Serialize;
use std::sync::atomic::{AtomicU64, Ordering};

/// Paths per chunk. Part of what a seed means: changing it changes results.
pub const CHUNK: u64 = 4096;

/// Chunks per block (65 536 paths), the unit a run is sharded by. Part of
/// what a seed means (it fixes the order of the merges).
pub const BLOCK: u64 = 16;

/// Chunks per batch, a multiple of [`BLOCK`] (4.2 million paths): enough
/// to keep every core busy between the batch's merges (a core idles at most one chunk per batch),
/// few enough that a batch's moments stay small (64 bytes per quantity and
/// chunk: 256 KiB for the rod's 4 quantities, 17 MB for a scene with 253
/// parameters). Not part of what a seed means: any batch size gives the
/// same bits.
pub const BATCH: u64 = 1024;

/// Most paths a run may sample: 2⁵³, the largest count below which every
/// count is exact as an `f64` (the moments' merge weighs chunks by their
/// counts in `f64`). At 10⁸ paths a second it would take three years.
pub const MAX_PATHS: u64 = 1 << 53;

/// What a run calls after each chunk of [`CHUNK`] paths (a rendering after
/// each row) with the work done so far, from the worker threads: to show
/// it (a progress bar's `set_position`: keep it cheap), and to stop the run
/// by returning an error (an interrupt, a time budget), which the run
/// returns once the chunks under way have ended. Progress changes no bit of
/// a run that ends.
pub type Progress<'a> = &'a (dyn Fn(u64) -> Result<(), Error> + Sync);

/// The progress hook that shows nothing and never stops a run.
pub fn quiet(_done: u64) -> Result<(), Error> {
    Ok(())
}

/// The first error a progress hook returned, shared by the workers: once
/// set, the chunks not yet started are skipped.
#[derive(Default)]
pub(crate) struct Stop(std::sync::OnceLock<Error>);

impl Stop {
    /// Whether the run is stopping.
    #[inline]
    pub(crate) fn stopping(&self) -> bool {
        self.0.get().is_some()
    }

    /// Records the hook's verdict.
    #[inline]
    pub(crate) fn check(&self, verdict: Result<(), Error>) {
        if let Err(e) = verdict {
            let _ = self.0.set(e);
        }
    }

    /// The error that stopped the run, if any.
    pub(crate) fn into_result(self) -> Result<(), Error> {
        self.0.into_inner().map_or(Ok(()), Err)
    }
}

/// Most worker threads a run accepts: beyond it a pool would cost more to
/// start than the runs it serves (and rayon itself stops at 65535).
pub const MAX_THREADS: usize = 1024;

/// How many paths to sample, from which seed, on how many threads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RunConfig {
    /// Number of paths (or path pairs); at least 2 for an error bar.
    pub paths: u64,
    /// Seed of the run.
    pub seed: u64,
    /// Worker threads; 0 means rayon's default (all cores).
    pub threads: usize,
}

impl RunConfig {
    /// A configuration on all cores; errors if `paths < 2` or
    /// `paths > MAX_PATHS`.
    pub fn new(paths: u64, seed: u64) -> Result<RunConfig, Error> {
        check_paths(paths)?;
        Ok(RunConfig {
            paths,
            seed,
            threads: 0,
        })
    }

    /// The same configuration on `threads` threads (0 = all cores).
    pub fn threads(self, threads: usize) -> RunConfig {
        RunConfig { threads, ..self }
    }
}

/// The estimates of one run, in the estimator's quantity order.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunResult {
    /// Method name.
    pub method: &'static str,
    /// One estimate per quantity.
    pub estimates: Vec<(Quantity, Estimate)>,
    /// Paths sampled.
    pub paths: u64,
    /// Wall time of the sampling, in seconds.
    pub seconds: f64,
}

impl RunResult {
    /// The estimate of `q`, if the method estimates it.
    pub fn get(&self, q: &Quantity) -> Option<Estimate> {
        self.estimates
            .iter()
            .find_map(|(k, e)| (k == q).then_some(*e))
    }
}

/// Errors unless `threads ≤ MAX_THREADS`.
pub fn check_threads(threads: usize) -> Result<(), Error> {
    if threads > MAX_THREADS {
        return Err(Error::Config(format!(
            "threads = {threads}: expected 0 (all cores) to {MAX_THREADS}"
        )));
    }
    Ok(())
}

/// Errors unless `2 ≤ cfg.paths ≤ MAX_PATHS` and `cfg.threads ≤
/// MAX_THREADS`.
fn check_config(cfg: &RunConfig) -> Result<(), Error> {
    check_threads(cfg.threads)?;
    check_paths(cfg.paths)
}

/// Errors unless `2 ≤ paths ≤ MAX_PATHS`.
fn check_paths(paths: u64) -> Result<(), Error> {
    if paths < 2 {
        return Err(Error::InvalidParameter {
            name: "paths",
            value: paths as f64,
            expected: "at least 2 (an error bar needs two samples)",
        });
    }
    if paths > MAX_PATHS {
        // The exact count: as an f64 it would print other digits.
        return Err(Error::Config(format!(
            "paths = {paths}: expected at most 2^53 = {MAX_PATHS} \
             (a path count must be exact as an f64)"
        )));
    }
    Ok(())
}

/// Moments of every quantity over chunk `c`.
fn run_chunk<E: Estimator + ?Sized>(est: &E, cfg: &RunConfig, nq: usize, c: u64) -> Vec<Moments> {
    let mut rng = rng::stream(cfg.seed, c);
    let len = CHUNK.min(cfg.paths - c * CHUNK);
    let mut sums = vec![ChunkSums::default(); nq];
    est.accumulate(&mut rng, len, &mut sums);
    sums.iter().map(ChunkSums::moments).collect()
}

/// Number of blocks of a run of `paths` paths (the last may be partial).
pub fn blocks(paths: u64) -> u64 {
    paths.div_ceil(CHUNK).div_ceil(BLOCK)
}

/// The moments of blocks `blocks`, each its chunks' moments merged in chunk
/// order, handed to `sink` in block order; the chunks of a batch run in
/// parallel on the current rayon pool unless `serial`. After each chunk,
/// `progress` is called with the paths these blocks have sampled so far
/// (in no fixed order across threads: a count to show, not to compute
/// with); its error stops the run, after the chunks under way, and is
/// returned.
fn run_blocks<E: Estimator + ?Sized>(
    est: &E,
    cfg: &RunConfig,
    blocks: std::ops::Range<u64>,
    serial: bool,
    progress: Progress,
    sink: &mut impl FnMut(Vec<Moments>),
) -> Result<(), Error> {
    let nq = est.quantities().len();
    let chunks = cfg.paths.div_ceil(CHUNK);
    let per_batch = BATCH / BLOCK;
    let done = AtomicU64::new(0);
    let stop = Stop::default();
    let chunk = |c: u64| {
        if stop.stopping() {
            return Vec::new();
        }
        let moments = run_chunk(est, cfg, nq, c);
        let len = CHUNK.min(cfg.paths - c * CHUNK);
        stop.check(progress(done.fetch_add(len, Ordering::Relaxed) + len));
        moments
    };
    let mut first = blocks.start;
    while first < blocks.end {
        let last = blocks.end.min(first + per_batch);
        let range = first * BLOCK..chunks.min(last * BLOCK);
        #[cfg(feature = "parallel")]
        let per_chunk: Vec<Vec<Moments>> = if serial {
            range.map(chunk).collect()
        } else {
            range.into_par_iter().map(chunk).collect()
        };
        // No threads (the feature `parallel` off): the same chunks in the
        // same order, so the same bits.
        #[cfg(not(feature = "parallel"))]
        let per_chunk: Vec<Vec<Moments>> = {
            let _ = serial;
            range.map(chunk).collect()
        };
        if stop.stopping() {
            break;
        }
        for block in per_chunk.chunks(BLOCK as usize) {
            sink(fold_blocks(nq, block.iter().map(Vec::as_slice)));
        }
        first = last;
    }
    stop.into_result()
}

/// Samples blocks `blocks` of the run `cfg` of `est` on `cfg.threads`
/// threads; returns every block's moments in block order and the wall time.
/// The runner's own [`run`] is this over every block followed by
/// [`fold_blocks`]: a shard of a run ([`crate::shard`]) calls it on its
/// share.
pub fn sample_blocks<E: Estimator + ?Sized>(
    est: &E,
    cfg: &RunConfig,
    blocks: std::ops::Range<u64>,
    progress: Progress,
) -> Result<(Vec<Vec<Moments>>, f64), Error> {
    check_config(cfg)?;
    let mut out = Vec::new();
    let (ended, seconds) = timed_on(cfg.threads, || {
        run_blocks(est, cfg, blocks, cfg.threads == 1, progress, &mut |b| {
            out.push(b)
        })
    })?;
    ended?;
    Ok((out, seconds))
}

/// Merges block moments (each a slice of per-quantity moments) in the
/// order given into one total per quantity: the runner's reduction.
pub fn fold_blocks<'a>(nq: usize, blocks: impl IntoIterator<Item = &'a [Moments]>) -> Vec<Moments> {
    let mut total = vec![Moments::default(); nq];
    for block in blocks {
        merge_into(&mut total, block);
    }
    total
}

/// `total[q] ← total[q] ⊕ block[q]` for every quantity `q`.
fn merge_into(total: &mut [Moments], block: &[Moments]) {
    for (t, m) in total.iter_mut().zip(block) {
        *t = t.merge(m);
    }
}

/// Runs `work` on `threads` worker threads and returns its result with its
/// wall time in seconds. 0 and 1 run it on the calling thread, where rayon's
/// global pool (all cores, built once per process) serves any parallel
/// iterator inside (a caller that wants one thread iterates serially
/// itself: no pool to build, a thread spawn per call saved); any other
/// count builds a pool of its own, whose start is not timed. Without the
/// feature `parallel` every count runs on the calling thread.
pub(crate) fn timed_on<T: Send>(
    threads: usize,
    work: impl FnOnce() -> T + Send,
) -> Result<(T, f64), Error> {
    #[cfg(feature = "parallel")]
    if threads > 1 {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| Error::Config(format!("cannot start {threads} threads: {e}")))?;
        let start = Stopwatch::start();
        let out = pool.install(work);
        return Ok((out, start.seconds()));
    }
    #[cfg(not(feature = "parallel"))]
    let _ = threads;
    let start = Stopwatch::start();
    let out = work();
    Ok((out, start.seconds()))
}

/// Wall time since it started. WebAssembly in a browser has no clock in
/// `std` (`Instant::now` panics there): it reads 0 s, and the page times
/// the run itself.
pub(crate) struct Stopwatch {
    #[cfg(not(target_arch = "wasm32"))]
    start: std::time::Instant,
}

impl Stopwatch {
    /// A stopwatch started now.
    pub(crate) fn start() -> Stopwatch {
        Stopwatch {
            #[cfg(not(target_arch = "wasm32"))]
            start: std::time::Instant::now(),
        }
    }

    /// Seconds since [`Stopwatch::start`] (0 on wasm32).
    pub(crate) fn seconds(&self) -> f64 {
        #[cfg(not(target_arch = "wasm32"))]
        return self.start.elapsed().as_secs_f64();
        #[cfg(target_arch = "wasm32")]
        0.0
    }
}

/// Samples `cfg.paths` paths of `est` and returns its estimates.
///
/// Memory does not grow with `cfg.paths` (chunks run in batches of
/// [`BATCH`]); a run of [`MAX_PATHS`] starts like any other and runs until
/// interrupted.
pub fn run<E: Estimator + ?Sized>(est: &E, cfg: &RunConfig) -> Result<RunResult, Error> {
    run_with_progress(est, cfg, &quiet)
}

/// [`run`], calling `progress` with the paths sampled so far after every
/// chunk of [`CHUNK`] paths ([`Progress`]): the estimates are [`run`]'s,
/// bit for bit, unless the hook stops the run, whose error is then
/// returned.
pub fn run_with_progress<E: Estimator + ?Sized>(
    est: &E,
    cfg: &RunConfig,
    progress: Progress,
) -> Result<RunResult, Error> {
    check_config(cfg)?;
    let quantities = est.quantities();
    let mut total = vec![Moments::default(); quantities.len()];
    let (ended, seconds) = timed_on(cfg.threads, || {
        // One thread: no pool to build (a thread spawn per call), same
        // chunks in the same order, so the same bits.
        let all = 0..blocks(cfg.paths);
        run_blocks(est, cfg, all, cfg.threads == 1, progress, &mut |b| {
            merge_into(&mut total, &b)
        })
    })?;
    ended?;
    Ok(RunResult {
        method: est.method(),
        estimates: quantities
            .into_iter()
            .zip(total.iter().map(Moments::estimate))
            .collect(),
        paths: cfg.paths,
        seconds,
    })
}
