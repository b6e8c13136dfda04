//! The design problem `scenes/design_reflector.toml`: every method turns
//! and moves the reflector to maximise the hidden receiver's irradiance,
//! and a dense scan of the objective (common random numbers, a quadratic
//! fitted about its peak) says where the maximum is.
//!
//! `cargo run --release --example design_reflector [-- --quick]`
use geosens::flat::file::load_study;
use geosens::optimize::scan::{fit_quadratic, scan};
use geosens::optimize::{Optimizer, Product, Sampling, Settings, optimize};
use geosens::{Error, Method};
use std::path::Path;
use std::time::Instant;

fn main() -> Result<(), Error> {
    let quick = std::env::args().any(|a| a == "--quick");
    let study = load_study(Path::new("scenes/design_reflector.toml"))?;
    let sampling = |paths, seed| Sampling {
        paths,
        batches: 8,
        seed,
        threads: 0,
        fd_step: None,
        product: Product::Independent,
    };
    // The scan: J on a grid about the peak, every point from one seed.
    let n = if quick { 11 } else { 31 };
    let axis = |lo: f64, hi: f64| -> Vec<f64> {
        (0..n)
            .map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64)
            .collect()
    };
    let (tx, rot) = (axis(-0.35, 0.25), axis(-0.85, -0.25));
    let start = Instant::now();
    let points = scan(
        &study,
        &[0.0, 0.0],
        (0, &tx),
        (1, &rot),
        &sampling(1 << 16, 7),
    )?;
    let best = points
        .iter()
        .min_by(|a, b| a.loss.total_cmp(&b.loss))
        .expect("a scan point");
    // The quadratic through the points within 0.15 of the best one.
    let near: Vec<([f64; 2], f64)> = points
        .iter()
        .filter(|p| {
            (p.offsets[0] - best.offsets[0]).abs() <= 0.15
                && (p.offsets[1] - best.offsets[1]).abs() <= 0.15
        })
        .map(|p| ([p.offsets[0], p.offsets[1]], -p.loss))
        .collect();
    let fit = fit_quadratic(&near)?;
    let peak = fit
        .stationary()
        .unwrap_or([best.offsets[0], best.offsets[1]]);
    println!(
        "scan {n}×{n}, 65536 paths a point ({:.1} s): grid best J = {:.5} at ({:.4}, {:.4}); \
         fitted peak J = {:.5} at ({:.4}, {:.4})",
        start.elapsed().as_secs_f64(),
        -best.loss,
        best.offsets[0],
        best.offsets[1],
        fit.at(peak),
        peak[0],
        peak[1]
    );
    println!(
        "{:<12} {:>10} {:>10} {:>10} {:>10} {:>8}",
        "method", "tx", "rotate", "J there", "J peak", "time [s]"
    );
    for method in [
        Method::Expectation,
        Method::Rendering,
        Method::Transport,
        Method::Fd,
    ] {
        let settings = Settings {
            method,
            optimizer: Optimizer::Adam,
            iterations: if quick { 150 } else { 300 },
            step: 0.02,
            sampling: sampling(16384, 1),
            tolerance: 0.0,
        };
        let t = Instant::now();
        let records = optimize(&study, &settings, |_| true)?;
        let seconds = t.elapsed().as_secs_f64();
        let last = records.last().expect("a record");
        let answer = [
            last.average["reflector_tx"],
            last.average["reflector_rotate"],
        ];
        // J at the answer, by the scan's own estimator and seed.
        let there = scan(
            &study,
            &answer,
            (0, &[answer[0]]),
            (1, &[answer[1]]),
            &sampling(1 << 16, 7),
        )?;
        println!(
            "{:<12} {:>10.4} {:>10.4} {:>10.5} {:>10.5} {:>8.2}",
            method.name(),
            answer[0],
            answer[1],
            -there[0].loss,
            fit.at(peak),
            seconds
        );
    }
    Ok(())
}
