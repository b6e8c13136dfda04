//! Backward path tracing of flatland radiance: free paths `ξ ~ κs e^{−κs ξ}`
//! in the homogeneous media (absorption carried as the weight `e^{−κa ξ}`),
//! phase-function sampling at collisions, cosine sampling at Lambertian
//! reflectors, Russian roulette on the throughput. The same loop serves the
//! intensity estimator and every nested path of the derivative estimators.
//! Book: chapter "Flatland", section "Backward path tracing".
use super::geometry::{NO_SEGMENT, perp};
use super::scene::{Phase, Scene, Surface};
use crate::rng::{PathRng, free_path};
use glam::DVec2;
use rand::RngExt;
use std::f64::consts::PI;

/// Events after which Russian roulette starts.
pub(crate) const ROULETTE_DEPTH: u32 = 5;
/// Highest survival probability of the roulette: a path in a lossless
/// enclosure still ends.
pub(crate) const ROULETTE_CAP: f64 = 0.95;

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

/// The transmittance from `x` (in `medium`, leaving segment `skip`) to the
/// point `y` on segment `target`: `e^{−τ}` through the media crossed, 0 if
/// an opaque segment lies between.
pub(crate) fn transmittance(
    scene: &Scene,
    mut x: DVec2,
    y: DVec2,
    mut medium: Option<u32>,
    mut skip: u32,
    target: u32,
) -> f64 {
    let d = y - x;
    let mut left = d.length();
    let w = d / left;
    let mut tau = 0.0;
    loop {
        let ke = scene.medium(medium).map_or(0.0, |m| m.ke);
        match scene.cast(x, w, skip) {
            Some(h) if h.segment != target && h.t < left => {
                let k = scene.owner(h.segment);
                if scene.shapes()[k as usize].surface.is_opaque() {
                    return 0.0;
                }
                tau += ke * h.t;
                left -= h.t;
                x += h.t * w;
                skip = h.segment;
                medium = crossed(scene, medium, k);
            }
            _ => return (-(tau + ke * left)).exp(),
        }
    }
}

/// The angular density, seen from `x`, of drawing the emitter point `y` on
/// segment `seg` by length: `r / (|cos θ_e| L)`.
#[inline]
pub(crate) fn light_pdf(scene: &Scene, x: DVec2, y: DVec2, seg: u32) -> f64 {
    let d = y - x;
    let r = d.length();
    let c = (d / r).dot(scene.normal(seg)).abs();
    if c > 0.0 {
        r / (c * scene.emitter_length())
    } else {
        f64::INFINITY
    }
}

/// The power heuristic's weight of a strategy of density `a` against `b`.
#[inline]
fn mis(a: f64, b: f64) -> f64 {
    if a.is_infinite() {
        1.0
    } else {
        a * a / (a * a + b * b)
    }
}

/// The directional lobe at a scattering vertex, for next-event estimation:
/// `f(ω)` over its density is what cosine or phase sampling draws.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Lobe {
    /// Cosine about `n` (density `(ω·n)⁺/2`).
    Cosine(DVec2),
    /// The phase function about `w_in`.
    Phase(Phase, DVec2),
}

impl Lobe {
    /// Density of sampling `w` (equal to the normalised integrand).
    #[inline]
    pub(crate) fn pdf(&self, w: DVec2) -> f64 {
        match *self {
            Lobe::Cosine(n) => 0.5 * w.dot(n).max(0.0),
            Lobe::Phase(phase, w_in) => phase_value(phase, w.dot(w_in)),
        }
    }
}

/// Next-event estimation at `x`: one point drawn on the emitters, its
/// radiance through the media, weighted against the lobe's own sampling by
/// the power heuristic. Returns the contribution per unit of throughput
/// (the lobe normalised to integrate to 1).
pub(crate) fn next_event(
    scene: &Scene,
    rng: &mut PathRng,
    x: DVec2,
    medium: Option<u32>,
    skip: u32,
    lobe: Lobe,
) -> f64 {
    let Some((y, seg)) = scene.emitter_point(rng.random()) else {
        return 0.0;
    };
    let w = (y - x).normalize();
    let (f, p_light) = (lobe.pdf(w), light_pdf(scene, x, y, seg));
    if f <= 0.0 || !p_light.is_finite() {
        return 0.0;
    }
    let Surface::Emitter { radiance } = scene.shape_of(seg).surface else {
        return 0.0;
    };
    let t = transmittance(scene, x, y, medium, skip, seg);
    f * radiance * t / p_light * mis(p_light, f)
}

/// One-sample estimate of the radiance arriving at `x` from direction `w`
/// (the path travels along `w`), `x` lying in `medium`, leaving segment
/// `skip` (or [`NO_SEGMENT`]). With next-event estimation at every
/// collision and reflection (multiple importance sampling with the lobe).
#[inline]
pub fn radiance(
    scene: &Scene,
    rng: &mut PathRng,
    x: DVec2,
    w: DVec2,
    medium: Option<u32>,
    skip: u32,
) -> f64 {
    radiance_observed(scene, rng, x, w, medium, skip, None, &mut |_| {})
}

/// [`radiance`] continuing a direction that a lobe of density `first_pdf`
/// drew at `x` after a next-event estimate there (so a lamp hit first is
/// weighted by multiple importance sampling; `None`: the direction was
/// given), calling `vertex` at every scattering, reflection or crossing
/// point and at the end of the path (figures draw paths with it; the no-op
/// observer compiles away).
#[allow(clippy::too_many_arguments)]
pub fn radiance_observed(
    scene: &Scene,
    rng: &mut PathRng,
    mut x: DVec2,
    mut w: DVec2,
    mut medium: Option<u32>,
    mut skip: u32,
    first_pdf: Option<f64>,
    vertex: &mut impl FnMut(DVec2),
) -> f64 {
    let mut beta = 1.0;
    let mut depth = 0;
    let mut total = 0.0;
    // The last scattering vertex and the density its lobe drew `w` with.
    let mut from = x;
    let mut drawn = first_pdf;
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
                let lobe = Lobe::Phase(m.phase, w);
                total += beta * next_event(scene, rng, x, medium, NO_SEGMENT, lobe);
                w = phase_direction(m.phase, w, rng);
                from = x;
                drawn = Some(lobe.pdf(w));
                skip = NO_SEGMENT;
                depth += 1;
                if !survives(depth, &mut beta, rng) {
                    return total;
                }
                continue;
            }
            beta *= (-ka * t_b).exp();
        }
        let Some(h) = hit else {
            // Leaving the scene: the path's last leg, cut at the scene's size.
            vertex(x + 2.0 * scene.size() * w);
            return total;
        };
        x += h.t * w;
        vertex(x);
        skip = h.segment;
        let k = scene.owner(h.segment);
        match scene.shapes()[k as usize].surface {
            Surface::Emitter { radiance } => {
                let weight = drawn.map_or(1.0, |p| mis(p, light_pdf(scene, from, x, h.segment)));
                return total + beta * radiance * weight;
            }
            Surface::Absorber => return total,
            Surface::Transparent => medium = crossed(scene, medium, k),
            Surface::Reflector { albedo } => {
                let n = scene.normal(h.segment);
                let n = if w.dot(n) > 0.0 { -n } else { n };
                beta *= albedo;
                let lobe = Lobe::Cosine(n);
                total += beta * next_event(scene, rng, x, medium, skip, lobe);
                w = cosine_direction(n, rng);
                from = x;
                drawn = Some(lobe.pdf(w));
                depth += 1;
                if !survives(depth, &mut beta, rng) {
                    return total;
                }
            }
        }
    }
}
