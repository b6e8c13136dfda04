//! Quick start: every method on the paper's thin and thick rods, at a few
//! probes, against the exact solution.
//!
//! ```text
//! cargo run --release --example rod_quick
//! ```
use geosens::rod::{Direction, Method, Probe, Rod, exact};
use geosens::{Error, RunConfig, run};

fn main() -> Result<(), Error> {
    let cfg = RunConfig::new(1_000_000, 1)?;
    for (name, ks, ke) in [("thin", 0.07, 0.1), ("thick", 2.1, 3.0)] {
        let rod = Rod::new(ks, ke, 2.0)?;
        println!(
            "{name} rod: κs = {ks}, κe = {ke}, length 2, {} paths",
            cfg.paths
        );
        for x in [0.0, 1.0, 1.9, 2.0] {
            for omega in [Direction::Right, Direction::Left] {
                let probe = Probe::new(&rod, x, omega)?;
                let ex = exact::solve(&rod, x, omega);
                println!(
                    "  x = {x}, ω = {:+}: exact I = {:.5}, s = {:.5}, ∂xI = {:.5}",
                    omega.sign(),
                    ex.intensity,
                    ex.sensitivity,
                    ex.gradient_x
                );
                for method in Method::UNBIASED {
                    let r = run(method.estimator((rod, probe))?.as_ref(), &cfg)?;
                    let cells: Vec<String> = r
                        .estimates
                        .iter()
                        .map(|(q, e)| {
                            let z = e.z_score(ex.get(q));
                            format!("{q} = {:.5} ± {:.5} (z {z:.1})", e.mean, e.stderr)
                        })
                        .collect();
                    println!("    {:<12} {}", method.name(), cells.join(", "));
                }
            }
        }
    }
    Ok(())
}
