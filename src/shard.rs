//! A run split over processes and machines: shard `I/N` samples only its
//! share of the run's blocks ([`runner::BLOCK`] chunks each) and writes
//! their exact moments to a [`State`]; [`merge`] checks that a set of states
//! is one whole run and folds their blocks in order, which is the single
//! run's own reduction (see [`crate::runner`]): the merged result is the
//! single run's, bit for bit, whatever the number of shards, machines or
//! threads. Book: chapter "Beyond one machine".
//!
//! A state is JSON: the run's identity (method, seed, total paths, number of
//! shards, and a SHA-256 of the crate version, the chunking, the step of
//! `fd` and the rod or the scene in full, meshes inline), this shard's index
//! and blocks, what the printing needs ([`Header`], caveats), and per block
//! and quantity the moments, every float as its IEEE-754 bits (JSON numbers
//! would lose NaN and infinity, which an overflowed run must keep), and a
//! SHA-256 of all that ([`State::data_checksum`]), which the reader checks:
//! a bit flipped in a file is an error, not another result.
use crate::error::Error;
use crate::estimator::Quantity;
use crate::image::{PixelSums, assemble, render_pixels};
use crate::job::{ImageReport, Job, RenderJob};
use crate::method::Method;
use crate::report::{Header, Report};
use crate::runner::{self, BLOCK, CHUNK, RunConfig, RunResult};
use crate::scene::file::read_bytes_capped;
use crate::stats::Moments;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::fmt;
use std::ops::Range;
use std::str::FromStr;

/// The format tag of a state file; a reader refuses any other (`/1`
/// states carried no checksum).
pub const STATE_FORMAT: &str = "geosens-state/2";

/// Largest state file [`State::read`] reads (bytes): 4 GiB, some 25
/// million blocks × quantities at about 170 bytes each (a state of
/// 10¹⁰ paths and 100 quantities is 2.6 GB). A path that names an endless
/// stream stops there, or at its first byte when that is not `{`.
pub const MAX_STATE_BYTES: u64 = 4 << 30;

/// Most shards a run may be split into.
pub const MAX_SHARDS: u64 = 1 << 20;

/// Shard `index` of `count` (1 ≤ index ≤ count), written `I/N` as on the
/// command line (`--shard 2/4`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// Which shard, from 1.
    pub index: u64,
    /// How many shards the run is split into.
    pub count: u64,
}

impl Shard {
    /// The whole run as one shard.
    pub const WHOLE: Shard = Shard { index: 1, count: 1 };

    /// Shard `index` of `count`; errors unless `1 ≤ index ≤ count ≤
    /// MAX_SHARDS`.
    pub fn new(index: u64, count: u64) -> Result<Shard, Error> {
        if count == 0 || count > MAX_SHARDS || index == 0 || index > count {
            return Err(Error::Config(format!(
                "shard {index}/{count}: expected I/N with 1 ≤ I ≤ N ≤ {MAX_SHARDS}"
            )));
        }
        Ok(Shard { index, count })
    }

    /// The blocks of this shard among `total` blocks: the `index`-th of
    /// `count` contiguous, nearly equal ranges (some empty if `count >
    /// total`).
    pub fn blocks(&self, total: u64) -> Range<u64> {
        let at = |i: u64| (u128::from(total) * u128::from(i) / u128::from(self.count)) as u64;
        at(self.index - 1)..at(self.index)
    }

    /// The paths this shard samples of a run of `paths` paths.
    pub fn paths(&self, paths: u64) -> u64 {
        paths_in(&self.blocks(runner::blocks(paths)), paths)
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl FromStr for Shard {
    type Err = Error;

    /// Parses `I/N`.
    fn from_str(s: &str) -> Result<Shard, Error> {
        let bad = || Error::Config(format!("shard {s:?}: expected I/N, e.g. 2/4 (1 ≤ I ≤ N)"));
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let i = i.trim().parse().map_err(|_| bad())?;
        let n = n.trim().parse().map_err(|_| bad())?;
        Shard::new(i, n)
    }
}

/// One block's moments of one quantity, every float as its bits: count,
/// non-zero count, mean, M2, M3, M4, largest |w|, Σ|w|, jumps (`u64::MAX`
/// where not counted).
type Packed = [u64; 9];

/// [`Moments::jumps`] packed: `u64::MAX` for `None` (a count never gets there).
const NO_JUMPS: u64 = u64::MAX;

fn pack(m: &Moments) -> Packed {
    [
        m.n,
        m.nonzero,
        m.mean.to_bits(),
        m.m2.to_bits(),
        m.m3.to_bits(),
        m.m4.to_bits(),
        m.max_abs.to_bits(),
        m.sum_abs.to_bits(),
        m.jumps.unwrap_or(NO_JUMPS),
    ]
}

fn unpack(p: &Packed) -> Moments {
    Moments {
        n: p[0],
        nonzero: p[1],
        mean: f64::from_bits(p[2]),
        m2: f64::from_bits(p[3]),
        m3: f64::from_bits(p[4]),
        m4: f64::from_bits(p[5]),
        max_abs: f64::from_bits(p[6]),
        sum_abs: f64::from_bits(p[7]),
        jumps: (p[8] != NO_JUMPS).then_some(p[8]),
    }
}

/// A shard's accumulators.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Payload {
    /// A probe's run: its blocks' moments.
    Blocks {
        /// The shard's first block.
        first: u64,
        /// Per block (from `first`), per quantity, the packed moments.
        moments: Vec<Vec<Packed>>,
    },
    /// A rendering: its share of the image's pixels (a contiguous range in
    /// row-major order, so that even a single row splits over shards).
    Rows {
        /// The shard's first pixel (row-major index, row 0 at the top).
        first: u32,
        /// Pixels per row.
        width: u32,
        /// Rows of the whole image.
        height: u32,
        /// Per pixel of the shard's range (row-major), per quantity: the
        /// packed pooled moments, then the bits of the pixel's mean and
        /// standard error.
        pixels: Vec<Vec<PackedPixel>>,
    },
}

/// One pixel's [`PixelSums`] of one quantity: the packed pooled moments,
/// the bits of its mean and standard error.
type PackedPixel = [u64; 11];

fn pack_pixel(p: &PixelSums) -> PackedPixel {
    let mut out = [0; 11];
    out[..9].copy_from_slice(&pack(&p.pooled));
    out[9] = p.mean.to_bits();
    out[10] = p.stderr.to_bits();
    out
}

fn unpack_pixel(p: &PackedPixel) -> PixelSums {
    let mut m = [0; 9];
    m.copy_from_slice(&p[..9]);
    PixelSums {
        pooled: unpack(&m),
        mean: f64::from_bits(p[9]),
        stderr: f64::from_bits(p[10]),
    }
}

/// What identifies a run: two states merge only if these are equal.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct RunId {
    /// Method name.
    pub method: String,
    /// SHA-256 (hex) of what the run estimates on
    /// ([`Prepared::canonical_text`](crate::job::Prepared::canonical_text)).
    pub hash: String,
    /// Seed of the run.
    pub seed: u64,
    /// Paths of the whole run (per pixel, for a rendering).
    pub paths: u64,
    /// Number of shards.
    pub shards: u64,
}

/// The exact accumulator state of one shard of a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct State {
    /// [`STATE_FORMAT`].
    pub format: String,
    /// The crate version that wrote it.
    pub version: String,
    /// The run it belongs to.
    pub run: RunId,
    /// Which shard this is (from 1).
    pub shard: u64,
    /// What the printing needs.
    pub header: Header,
    /// The estimator's caveats.
    pub caveats: Vec<(Quantity, String)>,
    /// The quantities, in the estimator's order.
    pub quantities: Vec<Quantity>,
    /// The shard's accumulators.
    pub payload: Payload,
    /// Paths this shard sampled.
    pub paths: u64,
    /// Wall time of this shard's sampling, in seconds.
    pub seconds: f64,
    /// [`State::data_checksum`] when the shard wrote it.
    pub checksum: String,
}

impl State {
    /// The state as one line of JSON.
    pub fn to_json(&self) -> Result<String, Error> {
        serde_json::to_string(self).map_err(|e| Error::Output(e.to_string()))
    }

    /// Reads a state from JSON; errors if it is not one, of another
    /// format, or its data do not match its checksum.
    pub fn from_json(text: &str) -> Result<State, Error> {
        // A cut or damaged file says so, not "no format".
        let value = serde_json::from_str::<serde_json::Value>(text.trim_start_matches('\u{feff}'))
            .map_err(|e| {
                Error::Merge(format!(
                    "not a geosens state: not JSON (cut short or damaged?): {e}"
                ))
            })?;
        let format = value
            .get("format")
            .and_then(|f| f.as_str().map(str::to_owned));
        match format.as_deref() {
            Some(STATE_FORMAT) => {}
            Some(other) => {
                let why = if other == "geosens-state/1" {
                    " (written by an earlier geosens, without a checksum: run the shard again)"
                } else {
                    ""
                };
                return Err(Error::Merge(format!(
                    "a state of format {other:?}, expected {STATE_FORMAT:?}{why}"
                )));
            }
            None => return Err(Error::Merge("not a geosens state (no \"format\")".into())),
        }
        let state: State = serde_json::from_value(value)
            .map_err(|e| Error::Merge(format!("a malformed state: {e}")))?;
        if state.checksum != state.data_checksum()? {
            return Err(Error::Merge(
                "a damaged state: its data do not match its checksum (a bit changed or a \
                 field edited since its shard wrote it): run that shard again"
                    .into(),
            ));
        }
        state.check()?;
        Ok(state)
    }

    /// The SHA-256 (hex) of the state's data: the compact JSON of every
    /// field but `seconds` and `checksum`. A state read back writes the
    /// same JSON (floats round-trip exactly), so this sums the data, not
    /// the file's layout; the wall time, which differs between two
    /// identical runs, is left out so that they carry the same checksum.
    pub fn data_checksum(&self) -> Result<String, Error> {
        // Destructured without `..`: a field added to `State` must be
        // placed here, in the sum or out of it, or this does not compile.
        let State {
            format,
            version,
            run,
            shard,
            header,
            caveats,
            quantities,
            payload,
            paths,
            seconds: _,
            checksum: _,
        } = self;
        let data = (
            format, version, run, shard, header, caveats, quantities, payload, paths,
        );
        let mut sum = HashWriter(Sha256::new());
        serde_json::to_writer(&mut sum, &data).map_err(|e| Error::Output(e.to_string()))?;
        Ok(hex(&sum.0.finalize()))
    }

    /// The state with its checksum set to its data's.
    fn sealed(mut self) -> Result<State, Error> {
        self.checksum = self.data_checksum()?;
        Ok(self)
    }

    /// Refuses a state that contradicts itself (an edited or damaged file
    /// merged without complaint: more non-zero weights than weights, a
    /// negative time printed as such).
    fn check(&self) -> Result<(), Error> {
        let bad = |what: String| Err(Error::Merge(format!("a damaged state: {what}")));
        // A run's time beyond 10¹² s (31 700 years) is damage too.
        if !(self.seconds >= 0.0 && self.seconds < 1e12) {
            return bad(format!("its time is {} s", crate::error::Num(self.seconds)));
        }
        let packed: Vec<&[u64]> = match &self.payload {
            Payload::Blocks { moments, .. } => moments.iter().flatten().map(|p| &p[..]).collect(),
            Payload::Rows { pixels, .. } => pixels.iter().flatten().map(|p| &p[..9]).collect(),
        };
        for p in packed {
            let (n, nonzero, jumps) = (p[0], p[1], p[8]);
            if nonzero > n {
                return bad(format!("{nonzero} non-zero weights among {n}"));
            }
            if jumps != NO_JUMPS && jumps > n {
                return bad(format!("{jumps} jumps among {n} weights"));
            }
        }
        Ok(())
    }

    /// Writes the state to `path` as one line of JSON, through a temporary
    /// file beside it (`FILE.part`, renamed when complete), so that a shard
    /// killed while writing leaves no file that looks whole; a write that
    /// fails (a full disk) removes the temporary and leaves a state already
    /// at `path` as it was.
    pub fn write(&self, path: &std::path::Path) -> Result<(), Error> {
        crate::file_set::write_whole(path, (self.to_json()? + "\n").as_bytes())
    }

    /// Reads the state `text` named `name` in messages (its file), with
    /// the messages `geosens merge` prints: `NAME: not a geosens state …`.
    pub fn named(name: &str, text: &str) -> Result<State, Error> {
        State::from_json(text).map_err(|e| match e {
            Error::Merge(m) => Error::Merge(format!("{name}: {m}")),
            other => other,
        })
    }

    /// Reads the state file at `path`; errors name it (`cannot read FILE:
    /// …`, `FILE: not a geosens state …`).
    /// At most [`MAX_STATE_BYTES`] are read, and a pipe is refused.
    pub fn read(path: &std::path::Path) -> Result<State, Error> {
        let name = path.display().to_string();
        let cannot = |why: &dyn fmt::Display| Error::Merge(format!("cannot read {name}: {why}"));
        let bytes = read_bytes_capped(path, MAX_STATE_BYTES, Some(b'{')).map_err(|e| cannot(&e))?;
        let text =
            String::from_utf8(bytes).map_err(|e| cannot(&format!("not UTF-8 text ({e})")))?;
        State::named(&name, &text)
    }

    /// The shard this state holds.
    pub fn shard(&self) -> Shard {
        Shard {
            index: self.shard,
            count: self.run.shards,
        }
    }
}

/// Paths in blocks `blocks` of a run of `paths` paths.
fn paths_in(blocks: &Range<u64>, paths: u64) -> u64 {
    let per_block = BLOCK * CHUNK;
    let at = |b: u64| paths.min(b.saturating_mul(per_block));
    at(blocks.end) - at(blocks.start)
}

impl Job {
    /// Runs shard `shard` of the job's run `cfg` and returns its state;
    /// `progress` is called with the shard's paths sampled so far. Errors
    /// as [`Job::run`] does, and for the rod's exact solution (nothing to
    /// sample).
    pub fn run_shard(
        &self,
        cfg: &RunConfig,
        shard: Shard,
        progress: crate::runner::Progress,
    ) -> Result<State, Error> {
        let prepared = self.prepare()?;
        let est = prepared.estimator.as_ref().ok_or_else(|| {
            Error::Config("the exact solution samples nothing: it has no shards".into())
        })?;
        let total = runner::blocks(cfg.paths);
        let range = shard.blocks(total);
        let (moments, seconds) = runner::sample_blocks(est.as_ref(), cfg, range.clone(), progress)?;
        State {
            format: STATE_FORMAT.to_owned(),
            version: env!("CARGO_PKG_VERSION").to_owned(),
            run: RunId {
                method: est.method().to_owned(),
                hash: sha256(&prepared.canonical_text(self.fd_step)?),
                seed: cfg.seed,
                paths: cfg.paths,
                shards: shard.count,
            },
            shard: shard.index,
            header: prepared.header,
            caveats: prepared.caveats,
            quantities: est.quantities(),
            payload: Payload::Blocks {
                first: range.start,
                moments: moments
                    .iter()
                    .map(|b| b.iter().map(pack).collect())
                    .collect(),
            },
            paths: paths_in(&range, cfg.paths),
            seconds,
            checksum: String::new(),
        }
        .sealed()
    }
}

impl RenderJob {
    /// Renders shard `shard` of the image (its share of the pixels, a
    /// contiguous range in row-major order) with `spp` paths per pixel from
    /// `seed` on `threads` threads, and returns its state; `progress` is
    /// called with the shard's pixels done.
    pub fn run_shard(
        &self,
        spp: u64,
        seed: u64,
        threads: usize,
        shard: Shard,
        progress: crate::runner::Progress,
    ) -> Result<State, Error> {
        let (est, canonical) = self.prepare()?;
        let Some((width, height)) = est.image() else {
            unreachable!("prepare checks the camera")
        };
        let range = shard.blocks(u64::from(width) * u64::from(height));
        let (pixels, seconds) =
            render_pixels(est.as_ref(), spp, seed, threads, range.clone(), progress)?;
        State {
            format: STATE_FORMAT.to_owned(),
            version: env!("CARGO_PKG_VERSION").to_owned(),
            run: RunId {
                method: est.method().to_owned(),
                hash: sha256(&canonical.text(self.fd_step)?),
                seed,
                paths: spp,
                shards: shard.count,
            },
            shard: shard.index,
            header: Header::Scene {
                scene: self.scene.name(),
                shapes: 0,
                parameters: 0,
            },
            caveats: est.caveats(),
            quantities: est.quantities(),
            payload: Payload::Rows {
                // Below 2³²: a side is at most `mesh::camera::MAX_SIDE`.
                first: range.start as u32,
                width,
                height,
                pixels: pixels
                    .iter()
                    .map(|p| p.iter().map(pack_pixel).collect())
                    .collect(),
            },
            paths: spp * (range.end - range.start),
            seconds,
            checksum: String::new(),
        }
        .sealed()
    }
}

/// The SHA-256 of `text`, in hex.
fn sha256(text: &str) -> String {
    hex(&Sha256::digest(text.as_bytes()))
}

/// `bytes` in lower-case hex.
fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// A SHA-256 fed by a writer: a state's data are summed as they are
/// serialised, never held as one more copy of the text.
struct HashWriter(Sha256);

impl std::io::Write for HashWriter {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.update(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

mod merge;
pub use merge::{Merged, merge};
mod survey;
pub use survey::{Survey, array_spec, survey};

#[cfg(test)]
mod tests;
