//! Collisions in optically thin media: the rate at which the walk
//! ([`super::walk::walk`]) draws its free paths in a medium, raised above
//! the scattering coefficient where a run would otherwise draw almost no
//! collision, and the bound on a medium's chords it is measured against.
//! Book: chapter "When not to trust a number", section "Optically thin
//! media".
use super::Vector;

// ANCHOR: thin_media
/// The least scattering optical depth, over a medium's largest chord
/// ([`Geometry::medium_chord`](super::Geometry::medium_chord)), at which the walk draws its collisions.
///
/// A medium of scattering optical depth `κs ℓ ≪ 1` scatters a path with
/// probability `≈ κs ℓ`: with `N κs ℓ ≲ 1` a run draws no collision at all,
/// and the in-scattered light and every derivative that only collisions
/// carry (a scattering point moving with the medium) are missing while the
/// error bar, blind to what was never drawn, stays small. Drawn at the rate
/// `μ = max(κs, THIN_DEPTH/ℓ)`, a path crossing the medium collides with
/// probability up to `1 − e^{−THIN_DEPTH}` ≈ 9.5 %, whatever `κs`; the weights
/// `(κs/μ) e^{−(κe−μ) ξ}` (collision) and `e^{−(κe−μ) t_b}` (pass) keep every
/// estimate unbiased, and the pass weight stays below `e^{THIN_DEPTH}`.
/// Media with `κs ℓ ≥ THIN_DEPTH` are drawn as before, bit for bit.
pub const THIN_DEPTH: f64 = 0.1;

/// The rate `μ` of the free paths drawn in a medium of scattering
/// coefficient `ks` whose straight paths are at most `chord` long
/// (see [`THIN_DEPTH`]); 0 where nothing scatters.
#[inline]
pub fn collision_rate(ks: f64, chord: f64) -> f64 {
    if ks > 0.0 && chord > 0.0 && chord.is_finite() {
        ks.max(THIN_DEPTH / chord)
    } else {
        ks
    }
}
// ANCHOR_END: thin_media

/// Whether a medium of scattering coefficient `ks` and chords at most
/// `chord` has its collisions drawn at a raised rate ([`collision_rate`]).
#[inline]
pub fn is_thin(ks: f64, chord: f64) -> bool {
    collision_rate(ks, chord) > ks
}

/// An upper bound on the chords of a shape with these vertices: twice the
/// largest distance from their mean (at most twice its diameter).
pub fn chord_bound<V: Vector>(vertices: &[V]) -> f64 {
    if vertices.is_empty() {
        return 0.0;
    }
    let mean = vertices.iter().fold(V::ZERO, |a, &v| a + v) * (1.0 / vertices.len() as f64);
    2.0 * vertices
        .iter()
        .fold(0.0f64, |r, &v| r.max((v - mean).length()))
}
