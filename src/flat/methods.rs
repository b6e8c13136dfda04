//! The flatland estimators behind the crate's [`Estimator`] interface: one
//! call samples one path (with its nested paths) and writes `I` then
//! `∂I/∂π_j` for every declared parameter, in declaration order.
//!
//! - [`Method::Intensity`]: backward path tracing ([`trace`](super::trace));
//! - [`Method::Rendering`], [`Method::Expectation`], [`Method::Transport`]:
//!   the differentiated walk (module `walk`) with its three bookkeepings of
//!   the path's deformation;
//! - [`Method::Fd`]: central differences with common random numbers, one
//!   pair of displaced scenes per parameter ([`finite_difference`], built on
//!   [`crate::fd`]).
use super::geometry::NO_SEGMENT;
use super::scene::{Scene, Sensor};
use super::trace::{Lobe, cosine_direction, next_event, radiance, radiance_observed};
use super::walk::{Scheme, Slots, Walk};
use crate::error::{Error, check};
use crate::estimator::{Estimator, Quantity};
use crate::fd::{CentralDifference, DEFAULT_STEP, Pair, check_step, invalid_displacement};
use crate::method::Problem;
use crate::rng::PathRng;
use std::sync::Arc;

/// The methods: every [`Method`] runs on a flatland scene
/// (`method.estimator(scene)` with `scene: Arc<Scene>`).
pub use crate::method::Method;

impl Problem for Arc<Scene> {
    /// For [`Method::Fd`] the half step is `fd_step` times the scene's size
    /// for a translation, `fd_step` radians for a rotation and `fd_step` for a
    /// scale.
    fn estimator(&self, method: Method, fd_step: Option<f64>) -> Result<Box<dyn Estimator>, Error> {
        let scene = Arc::clone(self);
        Ok(match method {
            Method::Intensity => Box::new(IntensityEstimator { scene }),
            Method::Expectation | Method::Rendering | Method::Transport => {
                Box::new(DerivativeEstimator {
                    slots: Slots::new(&scene, method == Method::Transport),
                    scene,
                    scheme: match method {
                        Method::Expectation => Scheme::Expectation,
                        Method::Rendering => Scheme::Rendering,
                        _ => Scheme::Transport,
                    },
                })
            }
            Method::Fd => Box::new(finite_difference(
                &scene,
                fd_step.map_or(Ok(DEFAULT_STEP), check_step)?,
            )?),
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

/// Central differences with common random numbers: `I` on the nominal
/// scene, then per parameter `j` the readings of the scene displaced by
/// `±h_j` (`h_j = step` × the scene's size for a translation, `step` for a
/// rotation or a scale), all from one generator state. Errors if a displaced
/// scene is invalid (shapes touching): the error names the parameter and the
/// displacement.
pub fn finite_difference(scene: &Arc<Scene>, step: f64) -> Result<CentralDifference, Error> {
    let step = check("h", step, step > 0.0, "a finite number > 0")?;
    let pairs = scene
        .parameters()
        .iter()
        .enumerate()
        .map(|(j, p)| {
            let (h, note) = match p.motion {
                super::Motion::TranslateX | super::Motion::TranslateY => (
                    step * scene.size(),
                    format!(" (half step {step} × scene size {})", scene.size()),
                ),
                _ => (step, String::new()),
            };
            let displaced = |delta: f64| -> Result<Box<dyn Estimator>, Error> {
                let moved = scene
                    .displaced(j, delta)
                    .map_err(|e| invalid_displacement("scene", &p.name, delta, &note, e))?;
                Method::Intensity.estimator(Arc::new(moved))
            };
            Ok(Pair {
                parameter: p.name.clone(),
                plus: displaced(h)?,
                minus: displaced(-h)?,
                half_step: h,
            })
        })
        .collect::<Result<_, Error>>()?;
    CentralDifference::new(Some(Method::Intensity.estimator(Arc::clone(scene))?), pairs)
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
