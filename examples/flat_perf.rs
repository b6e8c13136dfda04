//! Paths per second per thread of every flatland method, and each method's
//! cost over the intensity's, on the occluder scene, the 3-shape scene (12
//! parameters) and a 10⁴-segment scene (a wavy reflecting vault of 10⁴
//! segments over the occluder scene).
//!
//! `cargo run --release --example flat_perf -- [ROUNDS] [PATHS]`: medians of
//! ROUNDS (default 5) one-thread runs of PATHS paths (default 200000).
//!
//! Two baselines: `intensity` (the intensity estimator, with next-event
//! estimation; `cost/int`) and `plain`, plain path tracing without
//! next-event estimation (`cost/plain`). Then σ²·t, the variance times the
//! run's time, per parameter and derivative method, with its ratio to the
//! best (finite differences left out: they are biased).
use geosens::flat::space::Plane;
use geosens::flat::{Method, Scene, file};
use geosens::path::intensity::PlainEstimator;
use geosens::{Quantity, RunConfig, RunResult, run};
use std::path::Path;
use std::sync::Arc;

fn main() {
    let mut args = std::env::args().skip(1);
    let rounds: usize = args.next().map_or(5, |a| a.parse().expect("ROUNDS"));
    let paths: u64 = args.next().map_or(200_000, |a| a.parse().expect("PATHS"));
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let scenes: Vec<(String, Arc<Scene>)> = vec![
        (
            "occluder".into(),
            Arc::new(file::load(&dir.join("occluder.toml")).unwrap()),
        ),
        (
            "three_shapes".into(),
            Arc::new(file::load(&dir.join("three_shapes.toml")).unwrap()),
        ),
        (
            "vault 10^4".into(),
            Arc::new(geosens::flat::cases::vault(10_000, 0.0).expect("the vault scene is valid")),
        ),
    ];
    let methods = [
        Method::Intensity,
        Method::Rendering,
        Method::Expectation,
        Method::Transport,
        Method::Fd,
    ];
    println!("{rounds} rounds of {paths} paths, one thread; medians");
    println!(
        "{:<14} {:>4} {:<12} {:>12} {:>9} {:>10}",
        "scene", "par", "method", "paths/s", "cost/int", "cost/plain"
    );
    let mut efficiency = Vec::new();
    for (name, scene) in &scenes {
        let cfg = RunConfig::new(paths, 1).unwrap().threads(1);
        // Median time of the rounds, and the run at that time.
        let median = |e: &dyn geosens::Estimator| {
            let mut runs: Vec<RunResult> = (0..rounds).map(|_| run(e, &cfg).unwrap()).collect();
            runs.sort_by(|a, b| a.seconds.total_cmp(&b.seconds));
            runs.swap_remove(runs.len() / 2)
        };
        let plain = median(&PlainEstimator {
            geometry: Plane::new(scene.clone()),
        })
        .seconds;
        let intensity =
            median(Method::Intensity.estimator(scene.clone()).unwrap().as_ref()).seconds;
        println!(
            "{:<14} {:>4} {:<12} {:>12.3e} {:>9.2} {:>10.2}",
            name,
            0,
            "plain",
            paths as f64 / plain,
            plain / intensity,
            1.0
        );
        for m in methods {
            let r = median(m.estimator(scene.clone()).unwrap().as_ref());
            let t = r.seconds;
            println!(
                "{:<14} {:>4} {:<12} {:>12.3e} {:>9.2} {:>10.2}",
                name,
                scene.parameters().len(),
                m.name(),
                paths as f64 / t,
                t / intensity,
                t / plain
            );
            if m != Method::Intensity {
                efficiency.push((name.clone(), m, r));
            }
        }
    }
    // σ²·t (variance times the run's time: the work-normalised variance) per
    // parameter, and its ratio to the best method's.
    println!("\nσ²·t per parameter (ratio to the best method)");
    for (name, scene) in &scenes {
        for p in scene.parameters() {
            let q = Quantity::sensitivity(&p.name);
            let cells: Vec<(Method, f64)> = efficiency
                .iter()
                .filter(|(n, m, _)| n == name && *m != Method::Fd)
                .map(|(_, m, r)| {
                    let e = r.get(&q).unwrap();
                    (*m, e.stderr * e.stderr * r.seconds)
                })
                .collect();
            let best = cells.iter().map(|c| c.1).fold(f64::INFINITY, f64::min);
            let row: Vec<String> = cells
                .iter()
                .map(|(m, v)| format!("{} {:.2e} ({:.1})", m.name(), v, v / best))
                .collect();
            println!("{:<14} {:<16} {}", name, p.name, row.join("  "));
        }
    }
}
