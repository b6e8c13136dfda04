//! Speed against accuracy in flatland: the work-normalised variance `σ²·t`
//! (the variance of one path's weight times the seconds one path takes, on
//! one thread; equal to the variance of the estimate one second of
//! sampling leaves) of every method, for `E` and every parameter of
//! `polygon_occluder.toml`, `fog.toml` and `three_shapes.toml`, as markers
//! side by side on a log axis; lower is better. A path of every method estimates
//! `E` and all the scene's sensitivities at once, so `t` is the time of the
//! whole path, and the markers of one method share it; finite differences pay
//! two extra readings per parameter.
//!
//! Every timing run uses one thread whatever `opts.threads`; runs shorter
//! than [`MIN_SECONDS`] are repeated (same seed) and the fastest time kept.
//! Values with `σ = 0` cannot be drawn on the log axis and are left out
//! (the JSON keeps them); hollow markers have a relative variance of the variance
//! (VOV) of at least [`Estimate::VOV_LIMIT`](crate::stats::Estimate::VOV_LIMIT): heavy tails, their `σ` and
//! so their `σ²·t` are not to be trusted.
use super::{FigureOptions, load};
use crate::error::Error;
use crate::figures_common::efficiency::{self, Spec};
use std::path::PathBuf;

pub use crate::figures_common::efficiency::{MIN_SECONDS, Record};

/// The scenes, one panel each.
pub const SCENES: [&str; 3] = ["polygon_occluder", "fog", "three_shapes"];

/// Paths per run (times the effort).
pub const PATHS: u64 = 400_000;

/// Most runs of one configuration when timing short runs.
pub const MAX_REPEATS: u32 = 5;

/// Base of the seed salts of this figure (distinct from the other figures').
const SALT: u64 = 60_000_000;

/// `σ²·t` of every method for `E` and every parameter of the [`SCENES`]
/// (one panel each, markers per quantity), [`PATHS`] paths per run on one thread.
/// Writes `flat_efficiency.{png,svg}` and `flat_efficiency.json`.
pub fn efficiency(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let spec = Spec {
        prefix: "flat",
        scenes: &SCENES,
        build: load,
        title: |name| format!("{name}.toml"),
        paths: PATHS,
        max_repeats: MAX_REPEATS,
        salt: SALT,
        panel_size: (1500, 440),
    };
    efficiency::efficiency(opts, &spec)
}
