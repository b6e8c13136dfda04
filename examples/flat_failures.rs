//! The three tables of the book's "Where the methods fail" (chapter
//! "Flatland: one deformation, three estimators"), recomputed with the
//! current code: per configuration, the exact `∂E/∂π` where one exists, each
//! derivative method's estimate and per-path variance `σ²N`, and finite
//! differences (default step), all from seed 7.
//!
//! `cargo run --release --example flat_failures -- [PATHS]` (default
//! 400 000; the slab's table uses half as many, as the book's).
use geosens::flat::cases;
use geosens::flat::exact::Reference;
use geosens::{Method, Problem, Quantity, RunConfig, run};
use std::sync::Arc;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let paths: u64 = std::env::args().nth(1).map_or(Ok(400_000), |s| s.parse())?;
    let estimate = |scene: &Arc<geosens::flat::Scene>, m: Method, n: u64| {
        let e = scene.estimator(m, None)?;
        let r = run(e.as_ref(), &RunConfig::new(n, 7)?)?;
        let s = r
            .get(&Quantity::sensitivity("p"))
            .ok_or("no sensitivity p")?;
        Ok::<_, Box<dyn std::error::Error>>((s, s.stderr * s.stderr * n as f64))
    };
    let methods = [Method::Rendering, Method::Expectation, Method::Transport];
    println!("Two warp knots that meet ({paths} paths, seed 7): gap, exact, σ²N per method, FD");
    for g in [0.1, 0.01, 1e-3, 1e-4] {
        let scene = Arc::new(cases::knots(g)?);
        let exact = Reference::for_scene(&scene)?.derivative(0);
        let mut row = format!("| {g} | {exact:.4} |");
        for m in methods {
            row += &format!(" {:.3} |", estimate(&scene, m, paths)?.1);
        }
        let (fd, _) = estimate(&scene, Method::Fd, paths)?;
        row += &format!(" {:.3} ± {:.3} |", fd.mean, fd.stderr);
        println!("{row}");
    }
    println!(
        "\nA sensor near a moving boundary ({paths} paths): d, exact, estimate ± se (σ²N) per method, FD"
    );
    for d in [0.3, 0.01, 1e-3] {
        let scene = Arc::new(cases::sensor_near_edge(d)?);
        let exact = Reference::for_scene(&scene)?.derivative(0);
        let mut row = format!("| {d} | {exact:.4} |");
        for m in methods.into_iter().chain([Method::Fd]) {
            let (e, v) = estimate(&scene, m, paths)?;
            row += &format!(" {:.4} ± {:.4} ({v:.3}) |", e.mean, e.stderr);
        }
        println!("{row}");
    }
    let half = paths / 2;
    println!("\nThin dense media ({half} paths): thickness, σ²N per method, and the estimates");
    for t in [0.3, 0.03, 0.003] {
        let scene = Arc::new(cases::thin_slab(t)?);
        let mut row = format!("| {t} |");
        let mut means = String::new();
        for m in methods {
            let (e, v) = estimate(&scene, m, half)?;
            row += &format!(" {v:.3} |");
            means += &format!(" {:.4} ± {:.4}", e.mean, e.stderr);
        }
        println!("{row}   estimates:{means}");
    }
    Ok(())
}
