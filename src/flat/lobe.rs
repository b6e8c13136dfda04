//! Flatland's directional integrands: the 2D cosine lobe (density
//! `(η·n)⁺/2` over the half circle) and the phase functions (isotropic
//! `1/2π`, and the 2D Henyey–Greenstein function, the wrapped Cauchy law,
//! sampled by its inverse CDF), with the derivative of their logarithm along
//! a moving direction. Book: chapter "Flatland", section "Backward path
//! tracing".
use super::geometry::{cross, perp};
use super::scene::Phase;
use crate::path::Lobe;
use crate::rng::PathRng;
use glam::DVec2;
use rand::RngExt;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// The directional integrands of flatland.
#[derive(Debug, Clone, Copy)]
pub enum FlatLobe {
    /// `c (η·n)⁺`: the sensor (`c = 1`) or a Lambertian reflector
    /// (`c = ρ/2`), sampled with density `(η·n)⁺/2`.
    Cosine {
        /// Unit normal.
        n: DVec2,
        /// Factor.
        c: f64,
    },
    /// The phase function about the incoming `w_in`, sampled exactly.
    Phase {
        /// The phase function.
        phase: Phase,
        /// Incoming direction.
        w_in: DVec2,
    },
    /// A line camera's pixel stratum: `p(η) = |ξ|² / (x1 − x0)` for the
    /// directions through `ξ = f + x r`, `x ∈ [x0, x1]` on the image line at
    /// unit distance (`dθ = dx / |ξ|²`), 0 elsewhere; value = density.
    Pixel {
        /// View axis.
        f: DVec2,
        /// The image line's direction (clockwise from `f`).
        r: DVec2,
        /// The stratum's footprint on the image line.
        x0: f64,
        /// See `x0`.
        x1: f64,
        /// The pixel (its corners for the boundary term).
        pixel: u32,
    },
}

/// The density of a line camera's pixel lobe at `w`.
#[inline]
fn pixel_density(f: DVec2, r: DVec2, x0: f64, x1: f64, w: DVec2) -> f64 {
    let c = w.dot(f);
    if c <= 0.0 {
        return 0.0;
    }
    let x = w.dot(r) / c;
    if x < x0 || x > x1 {
        return 0.0;
    }
    1.0 / (c * c * (x1 - x0))
}

/// The phase function at the cosine `c` of the scattering angle.
#[inline]
pub fn phase_value(phase: Phase, c: f64) -> f64 {
    match phase {
        Phase::Isotropic => 0.5 / PI,
        Phase::HenyeyGreenstein { g } => (1.0 - g * g) / (2.0 * PI * (1.0 + g * g - 2.0 * g * c)),
    }
}

/// `d ln p / d cos θ` of the phase function at the cosine `c`.
#[inline]
pub fn phase_dlog_dcos(phase: Phase, c: f64) -> f64 {
    match phase {
        Phase::Isotropic => 0.0,
        Phase::HenyeyGreenstein { g } => 2.0 * g / (1.0 + g * g - 2.0 * g * c),
    }
}

/// A direction about the unit normal `n` with density `cos θ / 2` over the
/// half circle (so `∫ cos θ L dθ` is estimated by `2 L`).
#[inline]
pub fn cosine_direction(n: DVec2, rng: &mut PathRng) -> DVec2 {
    let s = 2.0 * rng.random::<f64>() - 1.0;
    let c = (1.0 - s * s).max(0.0).sqrt();
    c * n + s * perp(n)
}

/// A scattering direction from the phase function about the incoming `w`.
#[inline]
pub fn phase_direction(phase: Phase, w: DVec2, rng: &mut PathRng) -> DVec2 {
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

impl Lobe<DVec2> for FlatLobe {
    #[inline]
    fn value(&self, w: DVec2) -> f64 {
        match *self {
            FlatLobe::Cosine { n, c } => c * w.dot(n).max(0.0),
            FlatLobe::Phase { phase, w_in } => phase_value(phase, w.dot(w_in)),
            FlatLobe::Pixel { f, r, x0, x1, .. } => pixel_density(f, r, x0, x1, w),
        }
    }
    #[inline]
    fn pdf(&self, w: DVec2) -> f64 {
        match *self {
            FlatLobe::Cosine { n, .. } => 0.5 * w.dot(n).max(0.0),
            FlatLobe::Phase { phase, w_in } => phase_value(phase, w.dot(w_in)),
            FlatLobe::Pixel { f, r, x0, x1, .. } => pixel_density(f, r, x0, x1, w),
        }
    }
    #[inline]
    fn weight(&self) -> f64 {
        match *self {
            FlatLobe::Cosine { c, .. } => 2.0 * c,
            FlatLobe::Phase { .. } | FlatLobe::Pixel { .. } => 1.0,
        }
    }
    #[inline]
    fn sample(&self, rng: &mut PathRng) -> DVec2 {
        match *self {
            FlatLobe::Cosine { n, .. } => cosine_direction(n, rng),
            FlatLobe::Phase { phase, w_in } => phase_direction(phase, w_in, rng),
            // Uniform on the footprint.
            FlatLobe::Pixel { f, r, x0, x1, .. } => {
                (f + r * (x0 + (x1 - x0) * rng.random::<f64>())).normalize()
            }
        }
    }
    #[inline]
    fn dlog(&self, w: DVec2, wd: DVec2) -> f64 {
        match *self {
            FlatLobe::Cosine { n, .. } => wd.dot(n) / w.dot(n),
            FlatLobe::Phase { phase, w_in } => phase_dlog_dcos(phase, w.dot(w_in)) * wd.dot(w_in),
            // ln p = −2 ln(η·f) + const inside the footprint.
            FlatLobe::Pixel { f, .. } => -2.0 * wd.dot(f) / w.dot(f),
        }
    }
}

impl FlatLobe {
    /// Angles from `w` to the lobe's horizon counter-clockwise and clockwise
    /// (`2π` for the full circle). Horizons are fixed in the lobe's frame, so
    /// the warp they pin is one field whatever direction was drawn.
    #[inline]
    pub(super) fn horizons(&self, w: DVec2) -> (f64, f64) {
        match *self {
            FlatLobe::Cosine { n, .. } => {
                // φ − φ_n in (−π/2, π/2).
                let a = cross(n, w).atan2(n.dot(w));
                (FRAC_PI_2 - a, FRAC_PI_2 + a)
            }
            // The whole circle: a knot found one way is found the other way
            // too, and none found means no corner at all.
            FlatLobe::Phase { .. } => (TAU, TAU),
            // The footprint's ends: x grows clockwise.
            FlatLobe::Pixel { f, r, x0, x1, .. } => {
                let angle = |x: f64| {
                    let e = f + r * x;
                    cross(w, e).atan2(w.dot(e))
                };
                (angle(x0).max(0.0), (-angle(x1)).max(0.0))
            }
        }
    }
}
