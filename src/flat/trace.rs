//! Backward path tracing of flatland radiance: free paths `ξ ~ κs e^{−κs ξ}`
//! in the homogeneous media (absorption carried as the weight `e^{−κa ξ}`),
//! phase-function sampling at collisions, cosine sampling at Lambertian
//! reflectors, Russian roulette on the throughput. The same loop serves the
//! intensity estimator and every nested path of the derivative estimators.
//! Book: chapter "Flatland", section "Backward path tracing".
use super::geometry::{NO_SEGMENT, perp};
use super::scene::{Phase, Scene, Surface};
use crate::rng::PathRng;
use glam::DVec2;
use rand::RngExt;
use rand::distr::Distribution;
use rand_distr::Exp1;
use std::f64::consts::PI;

/// Events after which Russian roulette starts.
pub(crate) const ROULETTE_DEPTH: u32 = 5;
/// Highest survival probability of the roulette: a path in a lossless
/// enclosure still ends.
pub(crate) const ROULETTE_CAP: f64 = 0.95;

/// A free path `ξ ~ κs e^{−κs ξ}`; infinite without scattering.
#[inline]
pub(crate) fn free_path(ks: f64, rng: &mut PathRng) -> f64 {
    if ks > 0.0 {
        let e: f64 = Exp1.sample(rng);
        e / ks
    } else {
        f64::INFINITY
    }
}

/// A direction about the unit normal `n` with density `cos θ / 2` over the
/// half circle (so `∫ cos θ L dθ` is estimated by `2 L`).
#[inline]
pub(crate) fn cosine_direction(n: DVec2, rng: &mut PathRng) -> DVec2 {
    let s = 2.0 * rng.random::<f64>() - 1.0;
    let c = (1.0 - s * s).max(0.0).sqrt();
    c * n + s * perp(n)
}

/// A scattering direction from the phase function about the incoming `w`.
#[inline]
pub(crate) fn phase_direction(phase: Phase, w: DVec2, rng: &mut PathRng) -> DVec2 {
    let u: f64 = rng.random();
    let theta = match phase {
        Phase::Isotropic => 2.0 * PI * u,
        // Inverse CDF of the wrapped Cauchy law.
        Phase::HenyeyGreenstein { g } => {
            2.0 * ((1.0 - g) / (1.0 + g) * (PI * (u - 0.5)).tan()).atan()
        }
    };
    DVec2::from_angle(theta).rotate(w)
}

/// The phase function at the cosine `c` of the scattering angle.
#[inline]
pub(crate) fn phase_value(phase: Phase, c: f64) -> f64 {
    match phase {
        Phase::Isotropic => 0.5 / PI,
        Phase::HenyeyGreenstein { g } => (1.0 - g * g) / (2.0 * PI * (1.0 + g * g - 2.0 * g * c)),
    }
}

/// `d ln p / dθ` at the scattering angle with cosine `c` and sine `s`.
#[inline]
pub(crate) fn phase_log_slope(phase: Phase, c: f64, s: f64) -> f64 {
    match phase {
        Phase::Isotropic => 0.0,
        Phase::HenyeyGreenstein { g } => -2.0 * g * s / (1.0 + g * g - 2.0 * g * c),
    }
}

/// The medium entered or left when a ray crosses the transparent boundary of
/// shape `k` from medium `current`.
#[inline]
pub(crate) fn crossed(scene: &Scene, current: Option<u32>, k: u32) -> Option<u32> {
    if current == Some(k) {
        scene.parent_medium(k)
    } else {
        Some(k)
    }
}

/// Russian roulette: `false` ends the path, else the throughput is divided
/// by the survival probability.
#[inline]
pub(crate) fn survives(depth: u32, beta: &mut f64, rng: &mut PathRng) -> bool {
    if depth < ROULETTE_DEPTH {
        return true;
    }
    let q = beta.abs().min(ROULETTE_CAP);
    if q <= 0.0 || rng.random::<f64>() >= q {
        return false;
    }
    *beta /= q;
    true
}

/// One-sample estimate of the radiance arriving at `x` from direction `w`
/// (the path travels along `w`), `x` lying in `medium`, leaving segment
/// `skip` (or [`NO_SEGMENT`]).
#[inline]
pub fn radiance(
    scene: &Scene,
    rng: &mut PathRng,
    x: DVec2,
    w: DVec2,
    medium: Option<u32>,
    skip: u32,
) -> f64 {
    radiance_observed(scene, rng, x, w, medium, skip, &mut |_| {})
}

/// [`radiance`], calling `vertex` at every scattering, reflection or
/// crossing point and at the end of the path (figures draw paths with it;
/// the no-op observer compiles away).
pub fn radiance_observed(
    scene: &Scene,
    rng: &mut PathRng,
    mut x: DVec2,
    mut w: DVec2,
    mut medium: Option<u32>,
    mut skip: u32,
    vertex: &mut impl FnMut(DVec2),
) -> f64 {
    let mut beta = 1.0;
    let mut depth = 0;
    loop {
        let hit = scene.cast(x, w, skip);
        let t_b = hit.map_or(f64::INFINITY, |h| h.t);
        if let Some(m) = scene.medium(medium) {
            let xi = free_path(m.ks, rng);
            let ka = m.ke - m.ks;
            if xi < t_b {
                beta *= (-ka * xi).exp();
                x += xi * w;
                vertex(x);
                w = phase_direction(m.phase, w, rng);
                skip = NO_SEGMENT;
                depth += 1;
                if !survives(depth, &mut beta, rng) {
                    return 0.0;
                }
                continue;
            }
            beta *= (-ka * t_b).exp();
        }
        let Some(h) = hit else {
            // Leaving the scene: the path's last leg, cut at the scene's size.
            vertex(x + 2.0 * scene.size() * w);
            return 0.0;
        };
        x += h.t * w;
        vertex(x);
        skip = h.segment;
        let k = scene.owner(h.segment);
        match scene.shapes()[k as usize].surface {
            Surface::Emitter { radiance } => return beta * radiance,
            Surface::Absorber => return 0.0,
            Surface::Transparent => medium = crossed(scene, medium, k),
            Surface::Reflector { albedo } => {
                let n = scene.normal(h.segment);
                let n = if w.dot(n) > 0.0 { -n } else { n };
                beta *= albedo;
                w = cosine_direction(n, rng);
                depth += 1;
                if !survives(depth, &mut beta, rng) {
                    return 0.0;
                }
            }
        }
    }
}
