//! The directional integrands of 3D scenes: the cosine lobe (the irradiance
//! sensor, a Lambertian reflector), sampled with density `(η·n)⁺/π`, and the
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
    /// `c (η·n)⁺`: the sensor (`c = 1`) or a Lambertian reflector
    /// (`c = ρ/π`), sampled with density `(η·n)⁺/π`.
    Cosine {
        /// Unit normal.
        n: DVec3,
        /// Factor.
        c: f64,
    },
    /// The Henyey–Greenstein phase function about the incoming `w_in`:
    /// `p(μ) = (1 − g²) / (4π (1 + g² − 2gμ)^{3/2})`, `μ = η·w_in`.
    Phase {
        /// Mean cosine.
        g: f64,
        /// Incoming direction (unit).
        w_in: DVec3,
    },
    /// A camera pixel's stratum: `p(η) = |ξ|³ / A` for the directions
    /// through the image-plane rectangle `rect` (`ξ = f + x r + y u`, `A`
    /// its area), 0 elsewhere; value and density alike (weight 1). See
    /// [`super::camera`].
    Pixel {
        /// The camera's frame: view axis, right, up.
        frame: [DVec3; 3],
        /// `[x0, x1, y0, y1]` on the image plane at unit distance.
        rect: [f64; 4],
        /// The pixel (its edges for the boundary term).
        pixel: u32,
    },
}

/// The density of a camera pixel's lobe at `w`.
#[inline]
fn pixel_density(frame: &[DVec3; 3], rect: &[f64; 4], w: DVec3) -> f64 {
    let c = w.dot(frame[0]);
    if c <= 0.0 {
        return 0.0;
    }
    let (x, y) = (w.dot(frame[1]) / c, w.dot(frame[2]) / c);
    if x < rect[0] || x > rect[1] || y < rect[2] || y > rect[3] {
        return 0.0;
    }
    1.0 / (c * c * c * (rect[1] - rect[0]) * (rect[3] - rect[2]))
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
            SpaceLobe::Pixel { frame, rect, .. } => pixel_density(&frame, &rect, w),
        }
    }
    #[inline]
    fn pdf(&self, w: DVec3) -> f64 {
        match *self {
            SpaceLobe::Cosine { n, .. } => w.dot(n).max(0.0) * FRAC_1_PI,
            SpaceLobe::Phase { g, w_in } => henyey_greenstein(g, w.dot(w_in)),
            SpaceLobe::Pixel { frame, rect, .. } => pixel_density(&frame, &rect, w),
        }
    }
    #[inline]
    fn weight(&self) -> f64 {
        match *self {
            SpaceLobe::Cosine { c, .. } => c * PI,
            SpaceLobe::Phase { .. } | SpaceLobe::Pixel { .. } => 1.0,
        }
    }
    #[inline]
    fn sample(&self, rng: &mut PathRng) -> DVec3 {
        let (u1, u2): (f64, f64) = (rng.random(), rng.random());
        let phi = 2.0 * PI * u2;
        match *self {
            // Uniform on the footprint.
            SpaceLobe::Pixel { frame, rect, .. } => {
                let x = rect[0] + (rect[1] - rect[0]) * u1;
                let y = rect[2] + (rect[3] - rect[2]) * u2;
                (frame[0] + frame[1] * x + frame[2] * y).normalize()
            }
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
            // ln p = −3 ln(η·f) + const inside the footprint.
            SpaceLobe::Pixel { frame, .. } => -3.0 * wd.dot(frame[0]) / w.dot(frame[0]),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::stream;

    /// The lobes' samples have the density they report: the mean of
    /// `h(η)/pdf(η)` over draws is `∫ h dη` for a test function `h`.
    #[test]
    fn samples_follow_the_density() {
        let mut rng = stream(3, 0);
        let n = DVec3::new(0.3, -0.4, 0.8).normalize();
        // ∫ (η·a)² dη over the sphere = 4π/3; over the hemisphere 2π/3.
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
            // The hemisphere about n: ∫ (η·a)² = (2π/3)(…) by symmetry of
            // the quadratic form: ∫_{H} η_i η_j dη = (2π/3) δ_ij.
            let exact = exact.unwrap_or(2.0 * PI / 3.0);
            assert!(
                (mean - exact).abs() < 4.0 * se,
                "{lobe:?}: {mean} ± {se} vs {exact}"
            );
        }
    }

    /// A pixel's lobe integrates to 1 over the sphere: the mean of
    /// `1/pdf` over uniform directions inside its footprint's cone,
    /// checked by sampling the sphere uniformly.
    #[test]
    fn pixel_density_integrates_to_one() {
        let f = DVec3::new(0.2, 0.3, -0.9).normalize();
        let r = f.cross(DVec3::Y).normalize();
        let lobe = SpaceLobe::Pixel {
            frame: [f, r, r.cross(f)],
            rect: [-0.9, 0.3, -0.5, 0.7],
            pixel: 0,
        };
        let mut rng = stream(5, 0);
        let m = 400_000;
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in 0..m {
            let z: f64 = 2.0 * rng.random::<f64>() - 1.0;
            let phi: f64 = 2.0 * PI * rng.random::<f64>();
            let q = (1.0 - z * z).sqrt();
            let w = DVec3::new(q * phi.cos(), q * phi.sin(), z);
            let x = 4.0 * PI * lobe.pdf(w);
            s += x;
            s2 += x * x;
        }
        let mean = s / m as f64;
        let se = ((s2 / m as f64 - mean * mean) / m as f64).sqrt();
        assert!((mean - 1.0).abs() < 4.0 * se, "{mean} ± {se}");
        // Its samples land inside, where the density is positive.
        for _ in 0..1000 {
            assert!(lobe.pdf(lobe.sample(&mut rng)) > 0.0);
        }
    }

    /// `dlog` is the derivative of `ln value` along a moving direction.
    #[test]
    fn dlog_is_the_log_derivative() {
        let n = DVec3::new(0.2, 0.1, 0.9).normalize();
        let w = DVec3::new(0.5, -0.3, 0.7).normalize();
        let wd = DVec3::new(0.4, 0.9, -0.1).cross(w);
        let frame = [
            DVec3::new(0.5, -0.2, 0.8).normalize(),
            DVec3::ZERO,
            DVec3::ZERO,
        ];
        let r = frame[0].cross(DVec3::Y).normalize();
        let frame = [frame[0], r, r.cross(frame[0])];
        let (cx, cy) = (
            w.dot(frame[1]) / w.dot(frame[0]),
            w.dot(frame[2]) / w.dot(frame[0]),
        );
        let rect = [cx - 0.1, cx + 0.1, cy - 0.1, cy + 0.1];
        for lobe in [
            SpaceLobe::Cosine { n, c: 0.4 },
            SpaceLobe::Phase { g: 0.6, w_in: n },
            SpaceLobe::Pixel {
                frame,
                rect,
                pixel: 0,
            },
        ] {
            let h = 1e-6;
            let f = |t: f64| lobe.value((w + wd * t).normalize()).ln();
            let fd = (f(h) - f(-h)) / (2.0 * h);
            assert!((lobe.dlog(w, wd) - fd).abs() < 1e-6, "{lobe:?}");
        }
    }
}
