//! The flatland estimators behind the crate's [`Estimator`] interface: one
//! call samples one path (with its nested paths) and writes `I` then
//! `∂I/∂π_j` for every declared parameter, in declaration order.
//!
//! - [`Method::Intensity`]: backward path tracing ([`trace`](super::trace));
//! - [`Method::Rendering`], [`Method::Expectation`], [`Method::Transport`]:
//!   the differentiated walk (module `walk`) with its three bookkeepings of
//!   the path's deformation;
//! - [`Method::Fd`]: central differences with common random numbers, one
//!   pair of displaced scenes per parameter.
use super::geometry::NO_SEGMENT;
use super::scene::{Scene, Sensor};
use super::trace::{Lobe, cosine_direction, next_event, radiance, radiance_observed};
use super::walk::{Scheme, Slots, Walk};
use crate::error::{Error, check};
use crate::estimator::{Estimator, Quantity};
use crate::rng::PathRng;
use std::sync::Arc;

/// A flatland estimation method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Backward path tracing of `I` only.
    Intensity,
    /// Expectation differentiation: the warp field and stretched free paths;
    /// `I` and every `∂I/∂π` from the same path.
    Expectation,
    /// Differentiable rendering: boundary terms at corners and medium
    /// boundaries, joined by double randomisation.
    Rendering,
    /// Sensitivity transport: the path stays fixed in space; sources where
    /// it meets moving boundaries, coupled to the radiance gradient there
    /// (nested walks); also returns `∂I/∂x`, `∂I/∂y` at the sensor.
    Transport,
    /// Central finite differences with common random numbers (half step
    /// [`FD_STEP`] × scene size for translations, [`FD_STEP`] for rotations
    /// and scales).
    Fd,
}

/// Half step of [`Method::Fd`], relative to the scene size (radians for a
/// rotation, relative change for a scale).
pub const FD_STEP: f64 = 1e-3;

impl Method {
    /// The method's name, as the CLI spells it.
    pub fn name(self) -> &'static str {
        match self {
            Method::Intensity => "intensity",
            Method::Expectation => "expectation",
            Method::Rendering => "rendering",
            Method::Transport => "transport",
            Method::Fd => "fd",
        }
    }

    /// The estimator of this method on `scene`.
    pub fn estimator(self, scene: Arc<Scene>) -> Result<Box<dyn Estimator>, Error> {
        Ok(match self {
            Method::Intensity => Box::new(IntensityEstimator { scene }),
            Method::Expectation | Method::Rendering | Method::Transport => {
                Box::new(DerivativeEstimator {
                    slots: Slots::new(&scene, self == Method::Transport),
                    scene,
                    scheme: match self {
                        Method::Expectation => Scheme::Expectation,
                        Method::Rendering => Scheme::Rendering,
                        _ => Scheme::Transport,
                    },
                })
            }
            Method::Fd => Box::new(FiniteDifference::new(scene, FD_STEP)?),
        })
    }
}

/// `I` then one sensitivity per parameter.
fn sensitivities(scene: &Scene) -> Vec<Quantity> {
    std::iter::once(Quantity::Intensity)
        .chain(
            scene
                .parameters()
                .iter()
                .map(|p| Quantity::sensitivity(&p.name)),
        )
        .collect()
}

/// One-sample estimate of the sensor's reading.
#[inline]
fn reading(scene: &Scene, rng: &mut PathRng) -> f64 {
    let x = scene.sensor().point();
    let medium = scene.sensor_medium();
    match scene.sensor() {
        Sensor::Radiance { direction, .. } => {
            radiance(scene, rng, x, direction, medium, NO_SEGMENT)
        }
        Sensor::Irradiance { normal, .. } => {
            // ∫ L (ω·n)⁺ dθ = 2 × (the cosine lobe's normalised integral).
            let lobe = Lobe::Cosine(normal);
            let direct = next_event(scene, rng, x, medium, NO_SEGMENT, lobe);
            let w = cosine_direction(normal, rng);
            let pdf = lobe.pdf(w);
            2.0 * (direct
                + radiance_observed(scene, rng, x, w, medium, NO_SEGMENT, Some(pdf), &mut |_| {}))
        }
    }
}

/// Backward path tracing of the sensor's reading.
pub struct IntensityEstimator {
    /// The scene.
    pub scene: Arc<Scene>,
}

impl Estimator for IntensityEstimator {
    fn method(&self) -> &'static str {
        "intensity"
    }
    fn quantities(&self) -> Vec<Quantity> {
        vec![Quantity::Intensity]
    }
    #[inline]
    fn sample(&self, rng: &mut PathRng, weights: &mut [f64]) {
        weights[0] = reading(&self.scene, rng);
    }
}

/// The differentiated walk: `I` and all sensitivities from one path.
pub struct DerivativeEstimator {
    scene: Arc<Scene>,
    slots: Slots,
    scheme: Scheme,
}

impl Estimator for DerivativeEstimator {
    fn method(&self) -> &'static str {
        match self.scheme {
            Scheme::Rendering => "rendering",
            Scheme::Expectation => "expectation",
            Scheme::Transport => "transport",
        }
    }
    fn quantities(&self) -> Vec<Quantity> {
        let mut q = sensitivities(&self.scene);
        if self.slots.gradient {
            q.push(Quantity::gradient("x"));
            q.push(Quantity::gradient("y"));
        }
        q
    }
    #[inline]
    fn sample(&self, rng: &mut PathRng, weights: &mut [f64]) {
        Walk {
            scene: &self.scene,
            slots: &self.slots,
            scheme: self.scheme,
            frozen: false,
        }
        .sample(rng, weights);
    }
}

/// Central differences with common random numbers: per parameter `j`, the
/// reading of the scene displaced by `±h_j` from copies of one generator
/// state; `I` from the nominal scene with the same state.
pub struct FiniteDifference {
    scene: Arc<Scene>,
    displaced: Vec<(Scene, Scene, f64)>,
}

impl FiniteDifference {
    /// Half step `h` relative to the scene size for translations and
    /// absolute for rotations (radians) and scales; errors if `h` is not
    /// finite and positive or a displaced scene is invalid (shapes touching).
    pub fn new(scene: Arc<Scene>, h: f64) -> Result<FiniteDifference, Error> {
        let h = check("h", h, h > 0.0, "a finite number > 0")?;
        let displaced = (0..scene.parameters().len())
            .map(|j| {
                let step = match scene.parameters()[j].motion {
                    super::Motion::TranslateX | super::Motion::TranslateY => h * scene.size(),
                    _ => h,
                };
                Ok((scene.displaced(j, step)?, scene.displaced(j, -step)?, step))
            })
            .collect::<Result<_, Error>>()?;
        Ok(FiniteDifference { scene, displaced })
    }
}

impl Estimator for FiniteDifference {
    fn method(&self) -> &'static str {
        "fd"
    }
    fn quantities(&self) -> Vec<Quantity> {
        sensitivities(&self.scene)
    }
    fn sample(&self, rng: &mut PathRng, weights: &mut [f64]) {
        let start = rng.clone();
        weights[0] = reading(&self.scene, rng);
        for (w, (plus, minus, h)) in weights[1..].iter_mut().zip(&self.displaced) {
            let p = reading(plus, &mut start.clone());
            let m = reading(minus, &mut start.clone());
            *w = (p - m) / (2.0 * h);
        }
    }
}

/// The expectation method's warp field at the sensor: `V_j(φ)` (rad per
/// unit of parameter `j`) of the looking direction at angle `phi` from +x,
/// for every parameter. For an irradiance sensor, directions behind it get
/// 0 (the field is pinned to the frame at the horizons).
pub fn sensor_warp(scene: &Scene, phi: f64) -> Vec<f64> {
    let slots = Slots::new(scene, false);
    let mut out = vec![0.0; slots.len()];
    let w = super::geometry::direction(phi);
    if let Sensor::Irradiance { normal, .. } = scene.sensor()
        && w.dot(normal) <= 0.0
    {
        return out;
    }
    Walk {
        scene,
        slots: &slots,
        scheme: Scheme::Expectation,
        frozen: false,
    }
    .sensor_warp(w, &mut out);
    out
}
