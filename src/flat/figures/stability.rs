//! Where the flatland methods fail (the book's "Where the methods fail"):
//! the per-path variance `σ² N` of `∂E/∂π` against the distance to a
//! singular configuration, log–log, one panel per failure, every derivative
//! method:
//!
//! 1. two warp knots meeting: a black segment's corner seen a gap `g` inside
//!    the lamp's end (expectation's variance grows like `1/g`);
//! 2. a sensor at distance `d` from the moving edge of the absorbing box it
//!    sits in (every method's variance grows like `1/d`; the exact
//!    derivative like `ln 1/d`);
//! 3. a thin dense scattering slab of thickness `t` and fixed optical
//!    thickness, translated (variance `∝ 1/t`, transport's `∝ 1/t²`).
//!
//! Top row: `σ²N` with error bars `±σ²N·√VOV`; bottom row: the bias,
//! `(mean − exact)/σ` against the closed form (the thin slab has none: its
//! estimates themselves). Finite differences are drawn too: they are biased
//! where their step is larger than `g` or `d`, which the bottom row shows.
//! The runs use the paths and the seed of the book's tables and of
//! `tests/flat_failures.rs`, which pins the first two cases: `4·10⁵` paths
//! (`2·10⁵` for the slab) and seed 7 for every run (at the default seed 1).
use super::FigureOptions;
use crate::error::Error;
use crate::figures_common::stability::{self, Case, Salt};
use crate::flat::Scene;
use crate::flat::exact::Reference;
use std::path::PathBuf;

/// Paths per run at effort 1 for the first two cases (the tables' and the
/// test's).
const PATHS: u64 = 400_000;
/// Paths per run at effort 1 for the thin slab (its table's).
const SLAB_PATHS: u64 = 200_000;
/// The salt of every run: seed 7 at the default seed 1, the seed of
/// `tests/flat_failures.rs` and of the book's tables.
const SALT: u64 = 6;

/// One run (`case`: `"knots"`, `"sensor"` or `"thin"`; `distance`: `g`, `d`
/// or `t`; `exact`: the analytic `∂E/∂π` where one exists; `z`:
/// `(mean − exact)/σ`).
pub use crate::figures_common::stability::Record;

pub use crate::flat::cases::{knots, sensor_near_edge, thin_slab};

/// `scene` with its analytic `∂E/∂π` where [`Reference`] has one.
fn with_exact(scene: Scene) -> (Scene, Option<f64>) {
    let exact = Reference::for_scene(&scene).ok().map(|r| r.derivative(0));
    (scene, exact)
}

/// The three cases.
const CASES: [Case<Scene>; 3] = [
    (
        "knots",
        "two warp knots meeting",
        "gap g between two warp knots",
        &[0.1, 0.03, 0.01, 3e-3, 1e-3, 3e-4, 1e-4],
        PATHS,
        |g| Ok(with_exact(knots(g)?)),
    ),
    (
        "sensor",
        "a sensor near a moving edge",
        "distance d of the sensor to the moving edge",
        &[0.3, 0.1, 0.03, 0.01, 3e-3, 1e-3],
        PATHS,
        |d| Ok(with_exact(sensor_near_edge(d)?)),
    ),
    (
        "thin",
        "a thin dense slab",
        "thickness t of the slab (optical thickness 0.3)",
        &[0.3, 0.1, 0.03, 0.01, 3e-3],
        SLAB_PATHS,
        |t| Ok(with_exact(thin_slab(t)?)),
    ),
];

/// Runs the three cases and writes `flat_stability.{png,svg,json}`.
pub fn stability(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let salt = Salt::All(SALT);
    stability::figure(opts, "flat", &CASES, salt, "∂E/∂π", (520, 420))
}
