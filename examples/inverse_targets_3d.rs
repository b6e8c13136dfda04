//! The targets of the shipped 3D inverse problems (`scenes/mesh/inverse_*.toml`),
//! from the closed forms at their true poses
//! (`geosens::mesh::inverse`): prints each measurement's target; with
//! `--write`, puts them in the files (each `target = ...` in order).
//!
//! `cargo run --release --example inverse_targets_3d [-- --write]`
use geosens::mesh::file::load_study;
use geosens::mesh::inverse::{PROBLEMS, targets};
use std::path::Path;

/// A target as the files write it: shortest round-trip decimals, a
/// camera's one row of pixels per line.
fn toml_value(t: &[f64], width: usize) -> String {
    match t {
        [one] => format!("{one:?}"),
        many => {
            let rows: Vec<String> = many
                .chunks(width)
                .map(|row| {
                    let v: Vec<String> = row.iter().map(|x| format!("{x:?}")).collect();
                    format!("    {},", v.join(", "))
                })
                .collect();
            format!("[\n{}\n]", rows.join("\n"))
        }
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let write = std::env::args().any(|a| a == "--write");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for p in PROBLEMS {
        let path = p.path(root);
        let study = load_study(&path)?;
        let names = study.parameter_names();
        let at: Vec<String> = names
            .iter()
            .zip(p.truth)
            .map(|(n, t)| format!("{n} = {t}"))
            .collect();
        println!("# {} at {}", p.file, at.join(", "));
        let all = targets(&study, p.truth)?;
        let mut values = Vec::new();
        for (m, t) in study.measurements().iter().zip(&all) {
            let width = match m.sensor {
                geosens::mesh::Sensor::Camera(c) => c.width as usize,
                _ => 1,
            };
            let v = toml_value(t, width);
            println!("target = {v}");
            values.push(v);
        }
        if write {
            let text = std::fs::read_to_string(&path)?;
            let mut out = String::new();
            let mut lines = text.lines();
            let mut next = values.iter();
            while let Some(line) = lines.next() {
                if let Some(rest) = line.strip_prefix("target = ") {
                    if rest.starts_with('[') && !rest.ends_with(']') {
                        for l in lines.by_ref() {
                            if l == "]" {
                                break;
                            }
                        }
                    }
                    let v = next
                        .next()
                        .ok_or("more targets in the file than measurements")?;
                    out += &format!("target = {v}\n");
                } else {
                    out += line;
                    out.push('\n');
                }
            }
            std::fs::write(&path, out)?;
            println!("# written to {}", path.display());
        }
    }
    Ok(())
}
