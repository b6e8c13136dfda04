//! [`survey`]: which shards of a run a set of states holds and which are
//! missing, and how far the run has got, so that a failed shard can be run
//! again before the merge (`geosens merge --missing`). Book: chapter "Beyond
//! one machine", section "When a shard fails".
use super::*;

/// What a set of states of one run holds: see [`survey`].
#[derive(Debug, Clone, PartialEq)]
pub struct Survey {
    /// The run the states are of; `None` when there were none.
    pub run: Option<RunId>,
    /// The run's number of shards.
    pub shards: u64,
    /// The shards present, ascending.
    pub present: Vec<u64>,
    /// Paths the present shards sampled.
    pub paths: u64,
    /// Paths of the whole run (a rendering's: per pixel times its pixels);
    /// `None` when there were no states.
    pub planned: Option<u64>,
    /// A rendering's image size (width, height); `None` for a probe's run.
    pub image: Option<(u32, u32)>,
    /// Their sampling time, in core-seconds (the sum of the shards').
    pub seconds: f64,
}

impl Survey {
    /// The shards no state holds, ascending.
    pub fn missing(&self) -> Vec<u64> {
        let mut present = self.present.iter().peekable();
        (1..=self.shards)
            .filter(|i| {
                let here = present.peek() == Some(&i);
                if here {
                    present.next();
                }
                !here
            })
            .collect()
    }
}

/// `shards` as a Slurm array's indices: ascending runs of consecutive
/// numbers as `a-b`, joined by commas (`2,5-7`); empty for none.
pub fn array_spec(shards: &[u64]) -> String {
    let mut parts: Vec<String> = Vec::new();
    let mut i = 0;
    while i < shards.len() {
        let mut j = i;
        while j + 1 < shards.len() && shards[j + 1] == shards[j] + 1 {
            j += 1;
        }
        parts.push(if j == i {
            shards[i].to_string()
        } else {
            format!("{}-{}", shards[i], shards[j])
        });
        i = j + 1;
    }
    parts.join(",")
}

/// Checks that `labelled` (each state with the name messages give it) are
/// states of one run, each shard at most once, of `shards` shards if given,
/// and says which shards they hold. Unlike [`merge`] it takes a run in part;
/// the merge still checks every state's blocks or rows.
///
/// Errors, naming the state at fault, as [`merge`] does for another version
/// or run and for a shard given twice, and for a run of another number of
/// shards than `shards` (a folder holding another run's states); with no
/// state, unless `shards` says how many the run has.
pub fn survey(labelled: &[(String, State)], shards: Option<u64>) -> Result<Survey, Error> {
    let Some((first_label, first)) = labelled.first() else {
        let n = shards.ok_or_else(|| {
            Error::Merge("no state given: --shards N says how many the run has".into())
        })?;
        Shard::new(1, n)?;
        return Ok(Survey {
            run: None,
            shards: n,
            present: Vec::new(),
            paths: 0,
            planned: None,
            image: None,
            seconds: 0.0,
        });
    };
    let n = first.run.shards;
    // The count comes from a file: checked before a slot per shard is
    // allocated.
    Shard::new(first.shard, n).map_err(|e| Error::Merge(format!("{first_label}: {e}")))?;
    if let Some(want) = shards.filter(|&want| want != n) {
        return Err(Error::Merge(format!(
            "{first_label} is shard {}/{n}, of a run of {n} shards, not {want}: the states \
             given (their folder) hold another run; use another folder, or remove them",
            first.shard
        )));
    }
    let mut by_index: Vec<Option<&str>> = vec![None; n as usize];
    let (mut paths, mut seconds) = (0u64, 0.0);
    for (label, s) in labelled {
        merge::of_one_run(label, s, first_label, first)?;
        let shard = Shard::new(s.shard, n).map_err(|e| Error::Merge(format!("{label}: {e}")))?;
        let slot = &mut by_index[(shard.index - 1) as usize];
        if let Some(other) = slot {
            return Err(Error::Merge(format!(
                "shard {shard} given twice: {other} and {label}"
            )));
        }
        *slot = Some(label);
        paths = paths.saturating_add(s.paths);
        seconds += s.seconds;
    }
    Ok(Survey {
        run: Some(first.run.clone()),
        shards: n,
        present: (1..=n)
            .filter(|i| by_index[(i - 1) as usize].is_some())
            .collect(),
        paths,
        planned: Some(match first.payload {
            Payload::Blocks { .. } => first.run.paths,
            Payload::Rows { width, height, .. } => first
                .run
                .paths
                .saturating_mul(u64::from(width) * u64::from(height)),
        }),
        image: match first.payload {
            Payload::Blocks { .. } => None,
            Payload::Rows { width, height, .. } => Some((width, height)),
        },
        seconds,
    })
}
