//! The targets of flatland's worked inverse problems: each measurement's
//! closed form (`flat::exact`) at the problem's true pose. The shipped
//! scene files hold these numbers; `tests/optimize_flat.rs` checks that
//! they still agree.
//!
//! `cargo run --release --example inverse_targets_flat`
use geosens::Error;
use geosens::flat::exact::Reference;
use geosens::flat::file::load_study;
use geosens::method::model::Model;
use std::path::Path;

/// The worked problems: scene file and true pose (offsets from the file's).
pub const PROBLEMS: [(&str, &[f64]); 1] = [("scenes/inverse_occluder.toml", &[0.12, 0.2])];

fn main() -> Result<(), Error> {
    for (file, truth) in PROBLEMS {
        let study = load_study(Path::new(file))?;
        let posed = study.posed(truth)?;
        println!("{file} at {truth:?}:");
        for m in study.measurements() {
            let seen = posed.with_sensor(m.sensor)?;
            println!("target = {:.15}", Reference::for_scene(&seen)?.value());
        }
    }
    Ok(())
}
