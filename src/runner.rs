//! The parallel, deterministic runner: paths are split into fixed-size chunks,
//! chunk `c` draws from [`rng::stream(seed, c)`](crate::rng::stream), chunks
//! run on a rayon pool, their moments are collected in chunk order and merged
//! serially. The result is therefore bit-identical for any thread count
//! (rayon's own float reductions are not: rayon-rs/rayon#663).
use crate::error::Error;
use crate::estimator::{Estimator, Quantity};
use crate::rng;
use crate::stats::{ChunkSums, Estimate, Moments};
use rayon::prelude::*;
use serde::Serialize;
use std::time::Instant;

/// Paths per chunk. Part of what a seed means: changing it changes results.
pub const CHUNK: u64 = 4096;

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
    /// A configuration on all cores; errors if `paths < 2`.
    pub fn new(paths: u64, seed: u64) -> Result<RunConfig, Error> {
        if paths < 2 {
            return Err(Error::InvalidParameter {
                name: "paths",
                value: paths as f64,
                expected: "at least 2 (an error bar needs two samples)",
            });
        }
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

/// Moments of every quantity over chunk `c`.
fn run_chunk<E: Estimator + ?Sized>(est: &E, cfg: &RunConfig, nq: usize, c: u64) -> Vec<Moments> {
    let mut rng = rng::stream(cfg.seed, c);
    let len = CHUNK.min(cfg.paths - c * CHUNK);
    let mut sums = vec![ChunkSums::default(); nq];
    est.accumulate(&mut rng, len, &mut sums);
    sums.iter().map(ChunkSums::moments).collect()
}

/// Samples `cfg.paths` paths of `est` and returns its estimates.
pub fn run<E: Estimator + ?Sized>(est: &E, cfg: &RunConfig) -> Result<RunResult, Error> {
    if cfg.paths < 2 {
        return Err(Error::InvalidParameter {
            name: "paths",
            value: cfg.paths as f64,
            expected: "at least 2 (an error bar needs two samples)",
        });
    }
    let quantities = est.quantities();
    let nq = quantities.len();
    let chunks = cfg.paths.div_ceil(CHUNK);
    let per_chunk: Vec<Vec<Moments>>;
    let start;
    if cfg.threads == 1 {
        // One thread: no pool to build (a thread spawn per call), same chunks
        // in the same order, so the same bits.
        start = Instant::now();
        per_chunk = (0..chunks).map(|c| run_chunk(est, cfg, nq, c)).collect();
    } else if cfg.threads == 0 {
        // All cores: rayon's global pool, built once per process.
        start = Instant::now();
        per_chunk = (0..chunks)
            .into_par_iter()
            .map(|c| run_chunk(est, cfg, nq, c))
            .collect();
    } else {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(cfg.threads)
            .build()
            .map_err(|e| Error::Config(format!("cannot start {} threads: {e}", cfg.threads)))?;
        start = Instant::now();
        per_chunk = pool.install(|| {
            (0..chunks)
                .into_par_iter()
                .map(|c| run_chunk(est, cfg, nq, c))
                .collect()
        });
    }
    let mut total = vec![Moments::default(); nq];
    for chunk in &per_chunk {
        for (t, m) in total.iter_mut().zip(chunk) {
            *t = t.merge(m);
        }
    }
    let seconds = start.elapsed().as_secs_f64();
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
