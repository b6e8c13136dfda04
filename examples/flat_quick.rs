//! Flatland in a few lines: load a scene file, run every method, print each
//! estimate beside the analytic reference.
//!
//! `cargo run --release --example flat_quick -- [SCENE] [PATHS]` (default
//! `scenes/polygon_occluder.toml`, 10⁶ paths). Scenes without a closed form
//! (reflectors, scattering media) print the estimates alone.
use geosens::flat::exact::Reference;
use geosens::flat::{Method, file};
use geosens::{Quantity, RunConfig, run};
use std::path::PathBuf;
use std::sync::Arc;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args.next().map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/polygon_occluder.toml"),
        PathBuf::from,
    );
    let paths: u64 = args.next().map_or(Ok(1_000_000), |a| a.parse())?;
    let scene = Arc::new(file::load(&path)?);
    let reference = Reference::for_scene(&scene).ok();
    let cfg = RunConfig::new(paths, 1)?;
    for method in [
        Method::Intensity,
        Method::Rendering,
        Method::Expectation,
        Method::Transport,
        Method::Fd,
    ] {
        let r = run(method.estimator(scene.clone())?.as_ref(), &cfg)?;
        println!("{} ({:.2} s)", method.name(), r.seconds);
        for (q, e) in &r.estimates {
            let exact = reference.as_ref().and_then(|reference| match q {
                Quantity::Intensity => Some(reference.value()),
                Quantity::Sensitivity(name) => scene
                    .parameters()
                    .iter()
                    .position(|p| &p.name == name)
                    .map(|j| reference.derivative(j)),
                Quantity::Gradient(_) => None,
            });
            match exact {
                Some(x) => println!(
                    "  {:<24} {:+.5} ± {:.5}   exact {:+.5}  (z = {:.1})",
                    q.to_string(),
                    e.mean,
                    e.stderr,
                    x,
                    e.z_score(x)
                ),
                None => println!("  {:<24} {:+.5} ± {:.5}", q.to_string(), e.mean, e.stderr),
            }
        }
    }
    Ok(())
}
