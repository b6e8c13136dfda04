//! The runner at path counts no run reaches in practice: memory must not grow
//! with the count (issue 11, item 1), the merge order must not depend on the
//! thread count or the batching, and counts that are not exact in f64 are
//! refused with a message.
use geosens::Error;
use geosens::estimator::{Estimator, Quantity};
use geosens::rng::{self, PathRng};
use geosens::runner::{BLOCK, CHUNK, RunConfig, run, run_with_progress};
use geosens::stats::{ChunkSums, Moments};
use rand::Rng;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicU64, Ordering};

/// Cheap weights of three kinds: a uniform, a rare spike (mostly 0) and a
/// constant 0.
struct Cheap;

impl Estimator for Cheap {
    fn method(&self) -> &'static str {
        "cheap"
    }

    fn quantities(&self) -> Vec<Quantity> {
        vec![
            Quantity::Intensity,
            Quantity::sensitivity("spike"),
            Quantity::sensitivity("none"),
        ]
    }

    fn sample(&self, rng: &mut PathRng, weights: &mut [f64]) {
        let u = rng.next_u64();
        weights[0] = (u >> 11) as f64 * (1.0 / (1u64 << 53) as f64);
        weights[1] = if u.is_multiple_of(1000) { 1e3 } else { 0.0 };
        weights[2] = 0.0;
    }
}

/// The runner's contract, written out: chunk `c` of `CHUNK` paths from
/// `rng::stream(seed, c)`; the moments of each block of `BLOCK` chunks
/// merged serially in chunk order, then the blocks' in block order.
fn serial_reference(est: &impl Estimator, paths: u64, seed: u64) -> Vec<Moments> {
    let nq = est.quantities().len();
    let mut total = vec![Moments::default(); nq];
    let chunks = paths.div_ceil(CHUNK);
    for b in 0..chunks.div_ceil(BLOCK) {
        let mut block = vec![Moments::default(); nq];
        for c in b * BLOCK..chunks.min((b + 1) * BLOCK) {
            let mut rng = rng::stream(seed, c);
            let mut sums = vec![ChunkSums::default(); nq];
            est.accumulate(&mut rng, CHUNK.min(paths - c * CHUNK), &mut sums);
            for (t, s) in block.iter_mut().zip(&sums) {
                *t = t.merge(&s.moments());
            }
        }
        for (t, m) in total.iter_mut().zip(&block) {
            *t = t.merge(m);
        }
    }
    total
}

#[test]
fn batches_merge_in_chunk_order_for_any_thread_count() {
    // Two and a half batches of 1024 chunks, plus a partial last chunk (so
    // a partial last block too).
    let paths = 2 * 1024 * CHUNK + 512 * CHUNK + 77;
    let reference: Vec<_> = serial_reference(&Cheap, paths, 5)
        .iter()
        .map(Moments::estimate)
        .collect();
    for threads in [1, 2, 3, 0] {
        let cfg = RunConfig::new(paths, 5).unwrap().threads(threads);
        let r = run(&Cheap, &cfg).unwrap();
        let got: Vec<_> = r.estimates.iter().map(|(_, e)| *e).collect();
        // Bit-identical, the NaN-free way: PartialEq on every field.
        assert_eq!(got, reference, "{threads} threads");
    }
}

/// A run that reports its progress gives the same bits, and its reports
/// count every path once: they rise to the path count (a partial last
/// chunk included), each a multiple of the chunk or the total.
#[test]
fn progress_counts_every_path_and_changes_no_bit() {
    let paths = 40 * CHUNK + 77;
    for threads in [1, 3] {
        let cfg = RunConfig::new(paths, 9).unwrap().threads(threads);
        let (calls, last) = (AtomicU64::new(0), AtomicU64::new(0));
        let with = run_with_progress(&Cheap, &cfg, &|done| {
            assert!(done <= paths, "{done} of {paths}");
            calls.fetch_add(1, Ordering::Relaxed);
            last.fetch_max(done, Ordering::Relaxed);
            Ok(())
        })
        .unwrap();
        assert_eq!(with.estimates, run(&Cheap, &cfg).unwrap().estimates);
        assert_eq!(calls.into_inner(), paths.div_ceil(CHUNK));
        assert_eq!(last.into_inner(), paths);
    }
}

/// A progress hook's error stops the run soon after (each worker ends the
/// chunk it is on) and is what the run returns: a run of 2⁵³ paths, years
/// long, stopped at its fifth chunk, on one thread and on three.
#[test]
fn a_progress_hook_stops_a_run_with_its_error() {
    for threads in [1, 3] {
        let cfg = RunConfig::new(1 << 53, 1).unwrap().threads(threads);
        let calls = AtomicU64::new(0);
        let e = run_with_progress(&Cheap, &cfg, &|_| {
            if calls.fetch_add(1, Ordering::Relaxed) + 1 >= 5 {
                Err(Error::Stopped("enough".into()))
            } else {
                Ok(())
            }
        })
        .unwrap_err();
        assert_eq!(e, Error::Stopped("enough".into()));
        // One thread stops at once; on three, the chunks under way (or
        // started in the instant before the stop was recorded) end first.
        let calls = calls.into_inner();
        let most = if threads == 1 { 5 } else { 100 };
        assert!((5..=most).contains(&calls), "{calls} chunks");
    }
}

/// [`Cheap`] that stops the run (by panicking) after `limit` chunks: the
/// proof that the runner got to sampling.
struct Stopping {
    chunks: AtomicU64,
    limit: u64,
}

impl Estimator for Stopping {
    fn method(&self) -> &'static str {
        "stopping"
    }

    fn quantities(&self) -> Vec<Quantity> {
        Cheap.quantities()
    }

    fn sample(&self, rng: &mut PathRng, weights: &mut [f64]) {
        Cheap.sample(rng, weights)
    }

    fn accumulate(&self, _rng: &mut PathRng, _paths: u64, sums: &mut [ChunkSums]) {
        // Sampling every path would take years: push two weights per chunk.
        if self.chunks.fetch_add(1, Ordering::Relaxed) >= self.limit {
            panic!("stop: the run got this far");
        }
        for s in sums.iter_mut() {
            s.push(1.0);
            s.push(2.0);
        }
    }
}

#[test]
fn the_largest_run_starts_without_allocating_per_chunk() {
    // 2⁵³ paths are 2⁴¹ chunks: a vector of per-chunk moments would need
    // 50 TB (the runner used to abort with "memory allocation failed").
    // Stopped after three batches, the run must have reached sampling.
    let paths = 1u64 << 53;
    for threads in [1, 2] {
        let est = Stopping {
            chunks: AtomicU64::new(0),
            limit: 3 * 1024,
        };
        let cfg = RunConfig::new(paths, 1).unwrap().threads(threads);
        let result = catch_unwind(AssertUnwindSafe(|| run(&est, &cfg)));
        let payload = result.expect_err("the run should be stopped by the estimator");
        let message = payload
            .downcast_ref::<&str>()
            .copied()
            .or_else(|| payload.downcast_ref::<String>().map(String::as_str))
            .unwrap_or_default();
        assert!(message.starts_with("stop"), "{threads} threads: {message}");
        assert!(est.chunks.load(Ordering::Relaxed) > 3 * 1024);
    }
}

#[test]
fn path_counts_beyond_exact_f64_are_refused() {
    let largest = 1u64 << 53;
    assert!(RunConfig::new(largest, 1).is_ok());
    for paths in [largest + 1, u64::MAX] {
        let err = RunConfig::new(paths, 1).unwrap_err().to_string();
        assert!(
            err.contains(&format!("paths = {paths}")) && err.contains("2^53"),
            "{err}"
        );
        // A hand-built configuration is checked by `run` too.
        let cfg = RunConfig {
            paths,
            seed: 1,
            threads: 1,
        };
        assert!(run(&Cheap, &cfg).is_err());
    }
}
