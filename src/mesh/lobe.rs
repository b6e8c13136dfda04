//! The directional integrands of 3D scenes: the cosine lobe (the irradiance
//! sensor, a Lambertian reflector), sampled with density `(ω·n)⁺/π`, and the
//! Henyey–Greenstein phase function, sampled exactly, each with the
//! derivative of its logarithm along a moving direction. Book: chapter
//! "Three dimensions", section "Lobes".
use crate::path::Lobe;
use crate::rng::PathRng;
use glam::DVec3;
use rand::RngExt;
use std::f64::consts::{FRAC_1_PI, PI};

/// A directional integrand in space.
#[derive(Debug, Clone, Copy)]
pub enum SpaceLobe {
    /// `c (ω·n)⁺`: the sensor (`c = 1`) or a Lambertian reflector
    /// (`c = ρ/π`), sampled with density `(ω·n)⁺/π`.
    Cosine {
        /// Unit normal.
        n: DVec3,
        /// Factor.
        c: f64,
    },
    /// The Henyey–Greenstein phase function about the incoming `w_in`:
    /// `p(μ) = (1 − g²) / (4π (1 + g² − 2gμ)^{3/2})`, `μ = ω·w_in`.
    Phase {
        /// Mean cosine.
        g: f64,
        /// Incoming direction (unit).
        w_in: DVec3,
    },
}

/// The Henyey–Greenstein phase function at the cosine `mu`.
#[inline]
pub fn henyey_greenstein(g: f64, mu: f64) -> f64 {
    let d = 1.0 + g * g - 2.0 * g * mu;
    (1.0 - g * g) / (4.0 * PI * d * d.sqrt())
}

/// The unit vector with cosine `mu` to the unit `axis` and azimuth `phi`.
#[inline]
fn about(axis: DVec3, mu: f64, phi: f64) -> DVec3 {
    let (t, b) = axis.any_orthonormal_pair();
    let s = (1.0 - mu * mu).max(0.0).sqrt();
    let (sp, cp) = phi.sin_cos();
    (s * cp) * t + (s * sp) * b + mu * axis
}

impl Lobe<DVec3> for SpaceLobe {
    #[inline]
    fn value(&self, w: DVec3) -> f64 {
        match *self {
            SpaceLobe::Cosine { n, c } => c * w.dot(n).max(0.0),
            SpaceLobe::Phase { g, w_in } => henyey_greenstein(g, w.dot(w_in)),
        }
    }
    #[inline]
    fn pdf(&self, w: DVec3) -> f64 {
        match *self {
            SpaceLobe::Cosine { n, .. } => w.dot(n).max(0.0) * FRAC_1_PI,
            SpaceLobe::Phase { g, w_in } => henyey_greenstein(g, w.dot(w_in)),
        }
    }
    #[inline]
    fn weight(&self) -> f64 {
        match *self {
            SpaceLobe::Cosine { c, .. } => c * PI,
            SpaceLobe::Phase { .. } => 1.0,
        }
    }
    #[inline]
    fn sample(&self, rng: &mut PathRng) -> DVec3 {
        let (u1, u2): (f64, f64) = (rng.random(), rng.random());
        let phi = 2.0 * PI * u2;
        match *self {
            // Malley: a uniform point of the disc lifted to the hemisphere.
            SpaceLobe::Cosine { n, .. } => about(n, (1.0 - u1).sqrt(), phi),
            SpaceLobe::Phase { g, w_in } => {
                let mu = if g.abs() < 1e-6 {
                    1.0 - 2.0 * u1
                } else {
                    let s = (1.0 - g * g) / (1.0 + g - 2.0 * g * u1);
                    ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
                };
                about(w_in, mu, phi)
            }
        }
    }
    #[inline]
    fn dlog(&self, w: DVec3, wd: DVec3) -> f64 {
        match *self {
            SpaceLobe::Cosine { n, .. } => wd.dot(n) / w.dot(n),
            SpaceLobe::Phase { g, w_in } => {
                3.0 * g * wd.dot(w_in) / (1.0 + g * g - 2.0 * g * w.dot(w_in))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::stream;

    /// The lobes' samples have the density they report: the mean of
    /// `h(ω)/pdf(ω)` over draws is `∫ h dω` for a test function `h`.
    #[test]
    fn samples_follow_the_density() {
        let mut rng = stream(3, 0);
        let n = DVec3::new(0.3, -0.4, 0.8).normalize();
        // ∫ (ω·a)² dω over the sphere = 4π/3; over the hemisphere 2π/3.
        let a = DVec3::new(1.0, 2.0, -0.5).normalize();
        for (lobe, exact) in [
            (SpaceLobe::Cosine { n, c: 1.0 }, None),
            (SpaceLobe::Phase { g: 0.0, w_in: n }, Some(4.0 * PI / 3.0)),
            (SpaceLobe::Phase { g: 0.7, w_in: n }, Some(4.0 * PI / 3.0)),
            (SpaceLobe::Phase { g: -0.5, w_in: n }, Some(4.0 * PI / 3.0)),
        ] {
            let m = 200_000;
            let (mut s, mut s2) = (0.0, 0.0);
            for _ in 0..m {
                let w = lobe.sample(&mut rng);
                assert!((w.length() - 1.0).abs() < 1e-12);
                let x = w.dot(a).powi(2) / lobe.pdf(w);
                s += x;
                s2 += x * x;
            }
            let mean = s / m as f64;
            let se = ((s2 / m as f64 - mean * mean) / m as f64).sqrt();
            // The hemisphere about n: ∫ (ω·a)² = (2π/3)(…) by symmetry of
            // the quadratic form: ∫_{H} ω_i ω_j dω = (2π/3) δ_ij.
            let exact = exact.unwrap_or(2.0 * PI / 3.0);
            assert!(
                (mean - exact).abs() < 4.0 * se,
                "{lobe:?}: {mean} ± {se} vs {exact}"
            );
        }
    }

    /// `dlog` is the derivative of `ln value` along a moving direction.
    #[test]
    fn dlog_is_the_log_derivative() {
        let n = DVec3::new(0.2, 0.1, 0.9).normalize();
        let w = DVec3::new(0.5, -0.3, 0.7).normalize();
        let wd = DVec3::new(0.4, 0.9, -0.1).cross(w);
        for lobe in [
            SpaceLobe::Cosine { n, c: 0.4 },
            SpaceLobe::Phase { g: 0.6, w_in: n },
        ] {
            let h = 1e-6;
            let f = |t: f64| lobe.value((w + wd * t).normalize()).ln();
            let fd = (f(h) - f(-h)) / (2.0 * h);
            assert!((lobe.dlog(w, wd) - fd).abs() < 1e-6, "{lobe:?}");
        }
    }
}
