//! The flatland estimators behind the crate's [`Estimator`] interface: one
//! call samples one path (with its nested paths) and writes `I` then
//! `∂I/∂π_j` for every declared parameter, in declaration order.
//!
//! - [`Method::Intensity`]: backward path tracing, the path core's loop
//!   with no hooks ([`crate::path::walk`]);
//! - [`Method::Rendering`], [`Method::Expectation`], [`Method::Transport`]:
//!   the same loop with each method's hooks ([`crate::path::rendering`],
//!   [`crate::path::expectation`], [`crate::path::transport`]) over the
//!   plane's geometry ([`Plane`]);
//! - [`Method::Fd`]: central differences with common random numbers, one
//!   pair of displaced scenes per parameter.
use super::scene::Scene;
use super::space::Plane;
use crate::error::{Error, check};
use crate::estimator::{Estimator, Quantity};
use crate::path::deform::Slots;
use crate::path::estimator::{DerivativeEstimator, Scheme, reading};
use crate::path::intensity::IntensityEstimator;
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
        let scheme = match self {
            Method::Intensity => {
                return Ok(Box::new(IntensityEstimator {
                    geometry: Plane::new(scene),
                }));
            }
            Method::Fd => return Ok(Box::new(FiniteDifference::new(scene, FD_STEP)?)),
            Method::Expectation => Scheme::Expectation,
            Method::Rendering => Scheme::Rendering,
            Method::Transport => Scheme::Transport,
        };
        Ok(Box::new(derivative(scene, scheme)))
    }
}

/// The derivative estimator of `scheme` on `scene`.
pub fn derivative(scene: Arc<Scene>, scheme: Scheme) -> DerivativeEstimator<Plane> {
    let gradient = scheme == Scheme::Transport;
    let mut names: Vec<Quantity> = scene
        .parameters()
        .iter()
        .map(|p| Quantity::sensitivity(&p.name))
        .collect();
    if gradient {
        names.push(Quantity::gradient("x"));
        names.push(Quantity::gradient("y"));
    }
    let geometry = Plane::new(scene);
    let slots = Slots::new(&geometry, geometry.scene().shapes().len(), gradient);
    DerivativeEstimator {
        geometry,
        slots,
        scheme,
        names,
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

/// Central differences with common random numbers: per parameter `j`, the
/// reading of the scene displaced by `±h_j` from copies of one generator
/// state; `I` from the nominal scene with the same state.
pub struct FiniteDifference {
    nominal: Plane,
    displaced: Vec<(Plane, Plane, f64)>,
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
                let plus = Plane::new(Arc::new(scene.displaced(j, step)?));
                let minus = Plane::new(Arc::new(scene.displaced(j, -step)?));
                Ok((plus, minus, step))
            })
            .collect::<Result<_, Error>>()?;
        Ok(FiniteDifference {
            nominal: Plane::new(scene),
            displaced,
        })
    }
}

impl Estimator for FiniteDifference {
    fn method(&self) -> &'static str {
        "fd"
    }
    fn quantities(&self) -> Vec<Quantity> {
        sensitivities(self.nominal.scene())
    }
    fn sample(&self, rng: &mut PathRng, weights: &mut [f64]) {
        let start = rng.clone();
        weights[0] = reading(&self.nominal, &mut (), rng).0;
        for (w, (plus, minus, h)) in weights[1..].iter_mut().zip(&self.displaced) {
            let p = reading(plus, &mut (), &mut start.clone()).0;
            let m = reading(minus, &mut (), &mut start.clone()).0;
            *w = (p - m) / (2.0 * h);
        }
    }
}

/// The expectation method's warp field at the sensor: `V_j(φ)` (rad per
/// unit of parameter `j`) of the looking direction at angle `phi` from +x,
/// for every parameter. For an irradiance sensor, directions behind it get
/// 0 (the field is pinned to the frame at the horizons).
pub fn sensor_warp(plane: &Plane, phi: f64) -> Vec<f64> {
    super::boundaries::sensor_warp(plane, phi)
}
