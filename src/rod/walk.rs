//! The backward random walk shared by every rod estimator (the loop of
//! Algorithm 3 and Fig. 3): free paths `ξ ~ κs e^{−κs ξ}` (Eq. 25), isotropic
//! scattering between `±1` (Eq. 26), until the path leaves the rod at a
//! distance `d̂` (Eq. 27). Absorption is not sampled: it is the weight
//! `e^{−κa L}` of the total length `L`.
//!
//! In an optically thin rod (`κs π̃ <` [`THIN_DEPTH`](crate::path::thin_media::THIN_DEPTH)) a run would draw
//! almost no collision, and what only collisions carry (the light scattered
//! back toward the probe) would be missing behind a zero error bar: the free
//! paths are then drawn at the raised rate `μ = THIN_DEPTH/π̃` of
//! [`collision_rate`], and [`Exit::bias`] carries the ratio of the two
//! densities, `(κs/μ)^n e^{(μ−κs)L}` for `n` collisions, into every weight.
//! The paper's rods (`κs π̃` = 0.14 and 4.2) are drawn at `κs`, bit for bit.
//!
//! Since absorption never ends a path, a path deep in a thick absorbing rod
//! would scatter ~`(κs π̃)²/4` times before it escaped (millions of times,
//! 22 ms per path, at `κs π̃ = 5000`) while its weight is long 0:
//! `e^{−κa L}` underflows to exactly 0 once `κa L` passes 745.13. The walk
//! stops there ([`ABSORBED`]) and reports the path absorbed: its weight, and
//! every weight any estimator derives from it (all carry the factor
//! `e^{−κa L}` of a length at least this one), is the same 0 it would have
//! been at the exit. So no estimator gains a bias or a variance, and runs in
//! which no path gets there, every ordinary rod (the paper's thick rod
//! reaches `κa L ≈ 23` at most in 2·10⁷ paths), draw the same random numbers
//! and give the same bits. A Russian roulette on small weights would stop
//! such paths about ten times sooner (at `κa L ≈ 69` for a threshold 10⁻³⁰)
//! but adds variance and changes the random numbers of every path it
//! touches; the exact zero costs about `746 κs/κa` collisions (~750 at
//! albedo ½, 7–12 µs per path), which suffices. Paths of a nearly
//! conservative rod still take up to `(κs π̃)²/4` collisions:
//! `Rod::MAX_OPTICAL_THICKNESS` bounds that.
//!
//! Estimators that need more than the exit (the expectation method's
//! domain-deformation velocity) observe every event through [`Events`]; the
//! unit observer `()` compiles away. Book: chapter "Backward path tracing of
//! the intensity".
use super::{Direction, Rod, Side};
use crate::path::thin_media::collision_rate;
use crate::rng::PathRng;
use rand::Rng;

/// Where and after what length a backward path left the rod.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exit {
    /// The end it left through.
    pub side: Side,
    /// Total path length `L = Σ ξ_k + d̂_J`.
    pub length: f64,
    /// The plain walk's density over this one's (free paths drawn at `μ`
    /// rather than `κs`): `(κs/μ)^n e^{(μ−κs)L}`, exactly 1 where `μ = κs`.
    /// Every weight of the path carries it.
    pub bias: f64,
}

/// Absorption depth `κa L` from which the weight `e^{−κa L}` is exactly 0 in
/// `f64` (`e^{−745.14}` is below half the smallest subnormal; the margin
/// covers the rounding of `κa L`).
pub const ABSORBED: f64 = 746.0;

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

/// Walks from `x` along `dir` until the path leaves the rod, or until its
/// weight `e^{−κa L}` is exactly 0 (`None`: absorbed; see [`ABSORBED`]).
#[inline]
pub fn walk<E: Events>(
    rod: &Rod,
    mut x: f64,
    mut dir: Direction,
    rng: &mut PathRng,
    events: &mut E,
) -> Option<Exit> {
    // The generator's state in registers for the whole walk, written back
    // once: through `&mut` it is stored to memory at every draw.
    let mut local = rng.clone();
    let mut length = 0.0;
    // The length at which e^{−κa L} is 0: ∞ without absorption.
    let absorbed = ABSORBED / rod.ka();
    let mu = collision_rate(rod.ks, rod.length);
    let mut collisions = 0.0;
    let exit = loop {
        let d = rod.distance_to_boundary(x, dir);
        let xi = free_path(mu, &mut local);
        if xi >= d {
            events.escape(dir, d);
            let length = length + d;
            let bias = if mu > rod.ks {
                (collisions * (rod.ks / mu).ln() + (mu - rod.ks) * length).exp()
            } else {
                1.0
            };
            break Some(Exit {
                side: dir.end(),
                length,
                bias,
            });
        }
        events.collision(dir, xi, d);
        collisions += 1.0;
        length += xi;
        if length >= absorbed {
            break None;
        }
        x += dir.sign() * xi;
        dir = scatter_direction(&mut local);
    };
    *rng = local;
    exit
}
// ANCHOR_END: walk

/// One intensity sample from `x` along `dir`: the incoming intensity where
/// the path leaves, attenuated by absorption, `Î e^{−κa L}` (Eq. 28); 0 for
/// an absorbed path.
#[inline]
pub fn intensity_weight(rod: &Rod, x: f64, dir: Direction, rng: &mut PathRng) -> f64 {
    walk(rod, x, dir, rng, &mut ())
        .map_or(0.0, |exit| score(rod, exit.side, exit.length) * exit.bias)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absorbed_weight_is_exactly_zero() {
        // The cut is where the weight the path would have scored is 0.
        for ka in [1e-300, 1e-3, 0.9, 5e5, 1e300] {
            // A pure absorber (fields set directly: κe π̃ may exceed 10⁴).
            let rod = Rod {
                ks: 0.0,
                ke: ka,
                length: 1.0,
                incoming: 1.0,
            };
            let cut = ABSORBED / rod.ka();
            assert_eq!(attenuation(&rod, cut), 0.0, "κa = {ka}");
            assert_eq!(attenuation(&rod, cut * (1.0 + f64::EPSILON)), 0.0);
        }
        assert!(attenuation(&Rod::new(0.0, 1.0, 1.0).unwrap(), 745.0) > 0.0);
    }
}
