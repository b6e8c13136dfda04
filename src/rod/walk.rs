//! The backward random walk shared by every rod estimator (the loop of
//! Algorithm 3 and Fig. 3): free paths `ξ ~ κs e^{−κs ξ}` (Eq. 25), isotropic
//! scattering between `±1` (Eq. 26), until the path leaves the rod at a
//! distance `d̂` (Eq. 27). Absorption is not sampled: it is the weight
//! `e^{−κa L}` of the total length `L`.
//!
//! Estimators that need more than the exit (the expectation method's
//! domain-deformation velocity) observe every event through [`Events`]; the
//! unit observer `()` compiles away. Book: chapter "Backward path tracing of
//! the intensity".
use super::{Direction, Rod, Side};
use crate::rng::PathRng;
use rand::Rng;

/// Where and after what length a backward path left the rod.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exit {
    /// The end it left through.
    pub side: Side,
    /// Total path length `L = Σ ξ_k + d̂_J`.
    pub length: f64,
}

// ANCHOR: walk
/// Observer of the events of a walk.
pub trait Events {
    /// A collision after a free path `xi < d`, travelling along `dir`, `d`
    /// being the distance to the boundary from the segment's origin.
    #[inline]
    fn collision(&mut self, _dir: Direction, _xi: f64, _d: f64) {}
    /// The last segment, of length `d`, leaves the rod along `dir`.
    #[inline]
    fn escape(&mut self, _dir: Direction, _d: f64) {}
}

impl Events for () {}

pub use crate::rng::free_path;

/// An isotropic scattering direction, `±1` with probability ½ each.
#[inline]
pub fn scatter_direction(rng: &mut PathRng) -> Direction {
    if rng.next_u64() >> 63 == 0 {
        Direction::Right
    } else {
        Direction::Left
    }
}

/// Walks from `x` along `dir` until the path leaves the rod.
#[inline]
pub fn walk<E: Events>(
    rod: &Rod,
    mut x: f64,
    mut dir: Direction,
    rng: &mut PathRng,
    events: &mut E,
) -> Exit {
    // The generator's state in registers for the whole walk, written back
    // once: through `&mut` it is stored to memory at every draw.
    let mut local = rng.clone();
    let mut length = 0.0;
    let exit = loop {
        let d = rod.distance_to_boundary(x, dir);
        let xi = free_path(rod.ks, &mut local);
        if xi >= d {
            events.escape(dir, d);
            break Exit {
                side: dir.end(),
                length: length + d,
            };
        }
        events.collision(dir, xi, d);
        length += xi;
        x += dir.sign() * xi;
        dir = scatter_direction(&mut local);
    };
    *rng = local;
    exit
}
// ANCHOR_END: walk

/// One intensity sample from `x` along `dir`: the incoming intensity where
/// the path leaves, attenuated by absorption, `Î e^{−κa L}` (Eq. 28).
#[inline]
pub fn intensity_weight(rod: &Rod, x: f64, dir: Direction, rng: &mut PathRng) -> f64 {
    let exit = walk(rod, x, dir, rng, &mut ());
    score(rod, exit.side, exit.length)
}

/// The incoming intensity at `side` attenuated over `length`: `Î e^{−κa L}`,
/// without evaluating the exponential where nothing enters.
#[inline]
pub fn score(rod: &Rod, side: Side, length: f64) -> f64 {
    match side {
        Side::Start => rod.incoming * attenuation(rod, length),
        Side::End => 0.0,
    }
}

/// Absorption along a path of length `l`, `e^{−κa l}`.
#[inline]
pub fn attenuation(rod: &Rod, l: f64) -> f64 {
    let ka = rod.ka();
    if ka > 0.0 { (-ka * l).exp() } else { 1.0 }
}
