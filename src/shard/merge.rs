//! [`merge`]: the states of every shard of one run checked to be one whole
//! run and folded in block order, the single run's own reduction, so the
//! merged result is the single run's bit for bit. Book: chapter "Beyond
//! one machine".
use super::*;

/// A merged run: a probe's report or a rendering's images.
#[derive(Debug, Clone, PartialEq)]
pub enum Merged {
    /// What `geosens rod`, `flat` or `mesh` prints.
    Probe(Report),
    /// What `geosens render` writes and prints.
    Image(ImageReport),
}

/// Merges the states of every shard of one run (`labelled`: each with the
/// name the messages give it, e.g. its file) into the single run's result,
/// bit for bit: a probe's [`Report`] or a rendering's images. Its `seconds`
/// is the sum of the shards'.
///
/// Errors, naming the states at fault, unless they are of this format and
/// version, of one run (same method, hash, seed, paths, number of shards,
/// header, caveats and quantities), every shard present exactly once, each
/// holding exactly its blocks or pixels.
pub fn merge(labelled: &[(String, State)]) -> Result<Merged, Error> {
    let Some((first_label, first)) = labelled.first() else {
        return Err(Error::Merge("nothing to merge: no state given".into()));
    };
    let n = first.run.shards;
    // The count comes from a file: checked before a slot per shard is
    // allocated (a damaged count must be an error, not an abort).
    Shard::new(first.shard, n).map_err(|e| Error::Merge(format!("{first_label}: {e}")))?;
    let mut by_index: Vec<Option<&(String, State)>> = vec![None; n as usize];
    for pair in labelled {
        let (label, s) = pair;
        of_one_run(label, s, first_label, first)?;
        if !same_header(&s.header, &first.header)
            || s.caveats != first.caveats
            || s.quantities != first.quantities
            || std::mem::discriminant(&s.payload) != std::mem::discriminant(&first.payload)
        {
            return Err(Error::Merge(format!(
                "{label} and {first_label} are not of one run: their scenes or probes differ"
            )));
        }
        let shard = Shard::new(s.shard, n).map_err(|e| Error::Merge(format!("{label}: {e}")))?;
        let slot = &mut by_index[(shard.index - 1) as usize];
        if let Some((other, _)) = slot {
            return Err(Error::Merge(format!(
                "shard {shard} given twice: {other} and {label}"
            )));
        }
        if let Some(range) = misplaced(s, first) {
            return Err(Error::Merge(format!(
                "{label}: shard {shard} should hold {range} of the run: it is damaged"
            )));
        }
        *slot = Some(pair);
    }
    let missing: Vec<String> = by_index
        .iter()
        .enumerate()
        .filter(|(_, s)| s.is_none())
        .map(|(i, _)| format!("{}/{n}", i + 1))
        .collect();
    if !missing.is_empty() {
        return Err(Error::Merge(format!(
            "shard{} {} missing: a run of {n} shards merges only whole",
            if missing.len() > 1 { "s" } else { "" },
            missing.join(", ")
        )));
    }
    let states: Vec<&State> = by_index.iter().flatten().map(|(_, s)| s).collect();
    let nq = first.quantities.len();
    let method = first.run.method.parse::<Method>()?.name();
    let seconds = states.iter().map(|s| s.seconds).sum();
    let estimates = |total: Vec<Moments>| -> Vec<(Quantity, crate::stats::Estimate)> {
        first
            .quantities
            .iter()
            .cloned()
            .zip(total.iter().map(Moments::estimate))
            .collect()
    };
    Ok(match &first.payload {
        Payload::Blocks { .. } => {
            let blocks: Vec<Vec<Moments>> = states
                .iter()
                .flat_map(|s| match &s.payload {
                    Payload::Blocks { moments, .. } => moments.as_slice(),
                    Payload::Rows { .. } => &[],
                })
                .map(|b| b.iter().map(unpack).collect())
                .collect();
            let total = runner::fold_blocks(nq, blocks.iter().map(Vec::as_slice));
            Merged::Probe(Report {
                header: first.header.clone(),
                result: RunResult {
                    method,
                    estimates: estimates(total),
                    paths: first.run.paths,
                    seconds,
                },
                seed: first.run.seed,
                caveats: first.caveats.clone(),
            })
        }
        &Payload::Rows { width, height, .. } => {
            let pixels: Vec<Vec<PixelSums>> = states
                .iter()
                .flat_map(|s| match &s.payload {
                    Payload::Rows { pixels, .. } => pixels.as_slice(),
                    Payload::Blocks { .. } => &[],
                })
                .map(|p| p.iter().map(unpack_pixel).collect())
                .collect();
            Merged::Image(ImageReport {
                result: assemble(
                    method,
                    first.quantities.clone(),
                    (width, height),
                    first.run.paths,
                    &pixels,
                    seconds,
                ),
                caveats: first.caveats.clone(),
            })
        }
    })
}

/// Checks that state `s` was written by this version of geosens and is of
/// the run of `first`, naming them by `label` and `first_label`: what
/// [`merge`] and [`survey`] ask of every state first.
pub(super) fn of_one_run(
    label: &str,
    s: &State,
    first_label: &str,
    first: &State,
) -> Result<(), Error> {
    let this_version = env!("CARGO_PKG_VERSION");
    if s.version != this_version {
        return Err(Error::Merge(format!(
            "{label}: written by geosens {}, this is {this_version}",
            s.version
        )));
    }
    if s.run != first.run {
        return Err(Error::Merge(format!(
            "{label} and {first_label} are not of one run: {}",
            differences(&s.run, &first.run)
        )));
    }
    Ok(())
}

/// Whether two shards' headers are of one run: equal but for the scene's
/// name (a shard may name the same file by another path; the hash compares
/// the contents, and the merge prints the first state's name).
fn same_header(a: &Header, b: &Header) -> bool {
    match (a, b) {
        (
            Header::Scene {
                shapes, parameters, ..
            },
            Header::Scene {
                shapes: s2,
                parameters: p2,
                ..
            },
        ) => (shapes, parameters) == (s2, p2),
        _ => a == b,
    }
}

/// `None` if state `s` holds exactly its shard's blocks or pixels (with one
/// accumulator per quantity, the paths they count, and the image size of
/// `first`); else what it should hold, for the message.
fn misplaced(s: &State, first: &State) -> Option<String> {
    let nq = s.quantities.len();
    let shard = s.shard();
    match (&s.payload, &first.payload) {
        (Payload::Blocks { first: at, moments }, _) => {
            let want = shard.blocks(runner::blocks(s.run.paths));
            let ok = *at == want.start
                && moments.len() as u64 == want.end - want.start
                && moments.iter().all(|b| b.len() == nq)
                && s.paths == paths_in(&want, s.run.paths);
            (!ok).then(|| format!("blocks {}..{}", want.start, want.end))
        }
        (
            Payload::Rows {
                first: at,
                width,
                height,
                pixels,
            },
            Payload::Rows {
                width: w0,
                height: h0,
                ..
            },
        ) => {
            let want = shard.blocks(u64::from(*width) * u64::from(*height));
            let count = want.end - want.start;
            let ok = (width, height) == (w0, h0)
                && u64::from(*at) == want.start
                && pixels.len() as u64 == count
                && pixels.iter().all(|p| p.len() == nq)
                && s.paths == s.run.paths * count;
            (!ok).then(|| format!("pixels {}..{} of a {w0}×{h0} image", want.start, want.end))
        }
        (Payload::Rows { .. }, Payload::Blocks { .. }) => Some("blocks, not pixels".into()),
    }
}

/// Which fields of two run identities differ, for a message.
fn differences(a: &RunId, b: &RunId) -> String {
    let mut d = Vec::new();
    if a.method != b.method {
        d.push(format!("method {} against {}", a.method, b.method));
    }
    if a.hash != b.hash {
        d.push("different scenes, probes or fd steps (their hashes differ)".to_owned());
    }
    if a.seed != b.seed {
        d.push(format!("seed {} against {}", a.seed, b.seed));
    }
    if a.paths != b.paths {
        d.push(format!("{} paths against {}", a.paths, b.paths));
    }
    if a.shards != b.shards {
        d.push(format!("{} shards against {}", a.shards, b.shards));
    }
    d.join("; ")
}
