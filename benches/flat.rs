//! Per-method throughput on flatland scenes.
//!
//! ```text
//! cargo bench --bench flat                  # all groups
//! cargo bench --bench flat -- three_shapes  # the 12-parameter scene only
//! ```
//!
//! Groups `flat/<scene>`: `scenes/occluder.toml` (one segment occluder, 4
//! parameters), `scenes/fog.toml` (a scattering medium, 4 parameters) and
//! `scenes/three_shapes.toml` (absorber, reflector and fog, 12 parameters).
//! In each group, one thread, [`PATHS`] paths per iteration, throughput in
//! paths per second for `intensity`, `rendering`, `expectation`,
//! `transport` and `fd`: `method / intensity` is the cost of all of a
//! scene's sensitivities over its intensity alone. The 10⁴-segment scene is
//! timed by `cargo run --release --example flat_perf` (its slow methods take
//! seconds per iteration) and ray casting alone by `cargo bench --bench
//! raycast`.
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use geosens::flat::{Method, file};
use geosens::{RunConfig, run};
use std::hint::black_box;
use std::path::Path;
use std::sync::Arc;
use std::time::Duration;

/// Paths per iteration.
const PATHS: u64 = 50_000;

fn methods(c: &mut Criterion) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for name in ["occluder", "fog", "three_shapes"] {
        let scene = Arc::new(file::load(&dir.join(format!("{name}.toml"))).expect("scene loads"));
        let mut g = c.benchmark_group(format!("flat/{name}"));
        g.throughput(Throughput::Elements(PATHS))
            .sample_size(20)
            .warm_up_time(Duration::from_millis(500))
            .measurement_time(Duration::from_secs(2));
        for method in [
            Method::Intensity,
            Method::Rendering,
            Method::Expectation,
            Method::Transport,
            Method::Fd,
        ] {
            let estimator = method.estimator(scene.clone()).expect("estimator");
            let cfg = RunConfig::new(PATHS, 1).expect("config").threads(1);
            g.bench_function(method.name(), |b| {
                b.iter(|| run(black_box(estimator.as_ref()), &cfg).expect("run"))
            });
        }
        g.finish();
    }
}

criterion_group!(benches, methods);
criterion_main!(benches);
