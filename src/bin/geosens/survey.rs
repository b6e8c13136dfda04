//! `geosens merge --missing`: which shards of a run are missing, for a
//! scheduler's rerun, and how far the run has got.
use super::*;
use geosens::shard::{array_spec, survey};

/// Prints the shards of the run of `states` (of `shards` shards, when
/// given) that no state holds, as a Slurm array (`2,5-7`, nothing when
/// none is), and on stderr what the states hold.
pub(super) fn missing_command(
    states: &[(String, State)],
    shards: Option<u64>,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let s = survey(states, shards)?;
    let missing = s.missing();
    let run = match &s.run {
        Some(r) => format!(
            "{} shards of {}, {} paths{}, seed {}",
            s.shards,
            r.method,
            r.paths,
            match s.image {
                Some((w, h)) => format!(" per pixel of a {w}×{h} image"),
                None => String::new(),
            },
            r.seed
        ),
        None => format!("{} shards", s.shards),
    };
    let sampled = match s.planned {
        Some(planned) => format!(
            "{} of {planned} paths sampled ({:.2} core-seconds)",
            s.paths, s.seconds
        ),
        None => "no state yet".to_owned(),
    };
    let todo = if missing.is_empty() {
        "none missing: `geosens merge` merges them".to_owned()
    } else {
        format!("missing {}", array_spec(&missing))
    };
    eprintln!(
        "a run of {run}: {} present, {sampled}; {todo}",
        s.present.len()
    );
    if !missing.is_empty() {
        writeln!(out, "{}", array_spec(&missing))?;
    }
    Ok(())
}
