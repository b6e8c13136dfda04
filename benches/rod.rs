//! Per-method throughput on the rods of He et al. (2024), Table 1.
//!
//! ```text
//! cargo bench --bench rod                 # all 21, about 80 s
//! cargo bench --bench rod -- thick        # one rod
//! cargo bench --bench rod -- 'omega=-1'   # the paper's hard case only
//! ```
//!
//! Groups `rod/{thin,thick}/x=1/omega={-1,+1}`: the thin rod (κs = 0.07,
//! κe = 0.1) and the thick rod (κs = 2.1, κe = 3), length 2, probe at x = 1,
//! both directions. ω = −1 is the case where the backward path starts towards
//! the moving end, so rendering and transport draw the most nested paths; ω =
//! +1 starts towards the fixed end. In each group, one thread, [`PATHS`]
//! paths per iteration, throughput in paths (elements) per second:
//!
//! - `baseline`: Algorithm 3 as one hand-written loop (`support/baseline.rs`),
//!   no runner, no trait, sum and sum of squares only;
//! - `intensity`, `expectation`, `rendering`, `transport`: `geosens::run` of
//!   each `Method::UNBIASED` estimator with `RunConfig::new(PATHS, SEED)?.threads(1)`.
//!
//! `intensity / baseline` is the cost of the generic interface (runner,
//! trait object, moments to order 4, thread pool); `method / intensity` is the
//! cost of each sensitivity method over plain intensity, Table 1's ratios.
//! A last group, `rod/run-overhead`, times `run` on 2 paths: the fixed cost
//! of one call, dominated by building the one-thread pool.
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use geosens::rod::{Direction, Method, Probe, Rod};
use geosens::{RunConfig, run};
use std::hint::black_box;
use std::time::Duration;

#[path = "support/baseline.rs"]
mod baseline;

/// Paths per iteration: a thick-rod iteration takes some milliseconds.
const PATHS: u64 = 100_000;
/// Seed of every run: the work per iteration is the same in every sample.
const SEED: u64 = 1;
/// The probe position, the middle of the rod as in Table 1.
const X: f64 = 1.0;
/// The paper's rods: name, κs, κe (length 2).
const RODS: [(&str, f64, f64); 2] = [("thin", 0.07, 0.1), ("thick", 2.1, 3.0)];

fn methods(c: &mut Criterion) {
    for (name, ks, ke) in RODS {
        let rod = Rod::new(ks, ke, 2.0).expect("valid rod");
        for omega in [Direction::Left, Direction::Right] {
            let probe = Probe::new(&rod, X, omega).expect("valid probe");
            let mut g = c.benchmark_group(format!("rod/{name}/x=1/omega={:+}", omega.sign()));
            g.throughput(Throughput::Elements(PATHS))
                .sample_size(20)
                .warm_up_time(Duration::from_millis(500))
                .measurement_time(Duration::from_secs(2));
            g.bench_function("baseline", |b| {
                b.iter(|| {
                    baseline::algorithm3(
                        black_box(ks),
                        black_box(ke),
                        black_box(rod.length),
                        black_box(X),
                        black_box(omega.sign()),
                        PATHS,
                        SEED,
                    )
                })
            });
            let cfg = RunConfig::new(PATHS, SEED)
                .expect("valid config")
                .threads(1);
            for method in Method::UNBIASED {
                let est = method.estimator((rod, probe)).expect("estimator");
                g.bench_function(method.name(), |b| {
                    b.iter(|| run(black_box(est.as_ref()), &cfg).expect("run"))
                });
            }
            g.finish();
        }
    }
}

fn overhead(c: &mut Criterion) {
    let rod = Rod::new(2.1, 3.0, 2.0).expect("valid rod");
    let probe = Probe::new(&rod, X, Direction::Left).expect("valid probe");
    let est = Method::Intensity
        .estimator((rod, probe))
        .expect("estimator");
    let cfg = RunConfig::new(2, SEED).expect("valid config").threads(1);
    let mut g = c.benchmark_group("rod/run-overhead");
    g.sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    g.bench_function("intensity, 2 paths, 1 thread", |b| {
        b.iter(|| run(black_box(est.as_ref()), &cfg).expect("run"))
    });
    g.finish();
}

criterion_group! {
    name = benches;
    // The plots take longer than the measurements (about 7 s a benchmark with
    // them, 4 s without); `cargo bench --bench rod -- --plotting-backend
    // plotters` brings them back.
    config = Criterion::default().without_plots();
    targets = methods, overhead
}
criterion_main!(benches);
