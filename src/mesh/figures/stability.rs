//! Where the 3D methods struggle: the per-path variance `σ²N` of `∂E/∂p`
//! (top row, log–log, error bars `σ²N·√VOV`) and the bias against the
//! closed form, `(mean − exact)/σ` (bottom row), against the distance to a
//! singular configuration, every derivative method, one column per case
//! ([`crate::mesh::cases`]):
//!
//! 1. a sensor close to a moving face: the black triangle shrunk about the
//!    sensor to height `d`, translated along x (same shadow, `∂E/∂p ∝ 1/d`);
//! 2. a grazing silhouette: a black square whose shadow edge runs parallel
//!    to the lamp's edge a gap `g` inside it (the square's edge on the
//!    sight lines to the lamp's edge at `g = 0`), translated along x;
//! 3. a thin dense fog slab of thickness `t`, optical thickness 1 (no closed
//!    form: the bottom panel shows the estimates themselves, `mean ± σ`);
//! 4. a black box whose face `y = δ` approaches the plane `y = 0` through
//!    the sensor (a kink of `E` at `δ = 0`), translated along y. The run at
//!    `δ = 0` itself, where the derivative is one-sided, is in the JSON
//!    (`distance` 0), not on the log axis. There (seed 1, effort 1)
//!    expectation gives the closed form's branch (0.342 ± 0.006 against
//!    0.3516), finite differences the mean of the two one-sided derivatives
//!    (0.300 ± 0.018; the other side is 0.2641), and rendering and
//!    transport give 0 (±10⁻²¹): they drop the edge terms of the face seen
//!    edge-on.
//!
//! Finite differences are drawn too; their half step (2·10⁻³ of the scene's
//! size) is larger than some of the distances, where they are biased.
use super::FigureOptions;
use crate::error::Error;
use crate::figures_common::stability::{self, Salt};
use crate::mesh::Scene;
use crate::mesh::cases::{self, Case};
use std::path::PathBuf;

/// Paths per run (times the effort).
pub const PATHS: u64 = 100_000;

/// Base of the seed salts of this figure.
const SALT: u64 = 73_000_000;

/// One run (`case`: `"near"`, `"grazing"`, `"thin"` or `"kink"`;
/// `distance`: `d`, `g`, `t` or `δ`; `exact`: the closed-form `∂E/∂p` where
/// one exists; `z`: `(mean − exact)/σ`).
pub use crate::figures_common::stability::Record;

/// One case: name, title, axis label, distances, scene builder (every
/// case runs [`PATHS`] paths).
type CaseSpec = (
    &'static str,
    &'static str,
    &'static str,
    &'static [f64],
    fn(f64) -> Result<Case, Error>,
);

const CASES: [CaseSpec; 4] = [
    (
        "near",
        "a sensor close to a moving face",
        "height d of the triangle over the sensor",
        &[1.0, 0.3, 0.1, 0.03, 0.01],
        cases::near_sensor,
    ),
    (
        "grazing",
        "a shadow edge along the lamp's edge",
        "gap g between shadow edge and lamp edge",
        &[0.1, 0.03, 0.01, 3e-3, 1e-3, 3e-4, 1e-4],
        cases::grazing,
    ),
    (
        "thin",
        "a thin dense fog slab (τ = 1)",
        "thickness t of the slab",
        &[0.3, 0.1, 0.03, 0.01, 3e-3],
        cases::thin_fog,
    ),
    (
        "kink",
        "a box face near a plane through the sensor",
        "distance δ of the face to that plane",
        &[0.1, 0.03, 0.01, 3e-3, 1e-3, 3e-4, 0.0],
        cases::box_kink,
    ),
];

/// σ²N and the bias of `∂E/∂p` of every derivative method against the
/// distance to four singular configurations (columns; see the module docs),
/// [`PATHS`] paths per run on `opts.threads`. Writes
/// `mesh_stability.{png,svg,json}`:
///
/// ```text
/// cargo run --release --example fig_mesh_stability -- [OUT_DIR] [EFFORT]
/// ```
pub fn stability(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let cases: Vec<stability::Case<Scene>> = CASES
        .iter()
        .map(|&(case, title, axis, distances, build)| (case, title, axis, distances, PATHS, build))
        .collect();
    let salt = Salt::Each(SALT);
    stability::figure(opts, "mesh", &cases, salt, "∂E/∂p", (480, 420))
}
