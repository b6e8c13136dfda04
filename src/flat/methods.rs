//! The flatland estimators behind the crate's [`Estimator`](crate::Estimator)
//! interface: one call samples one path (with its nested paths) and writes
//! `I` then `∂I/∂π_j` for every declared parameter, in declaration order.
//!
//! - [`Method::Intensity`]: backward path tracing, the path core's loop
//!   with no hooks ([`crate::path::walk`]);
//! - [`Method::Rendering`], [`Method::Expectation`], [`Method::Transport`]:
//!   the same loop with each method's hooks ([`crate::path::rendering`],
//!   [`crate::path::expectation`], [`crate::path::transport`]) over the
//!   plane's geometry ([`Plane`]);
//! - [`Method::Fd`]: central differences with common random numbers, one
//!   pair of displaced scenes per parameter ([`finite_difference`], built on
//!   [`crate::fd`]).
//!
//! The dispatch is the dimension-neutral method layer's
//! ([`crate::method::model`]); this file says what it needs of a flatland
//! scene ([`Model`]).
pub use super::caveats::ties;
use super::caveats::view_change;
use super::geometry::{direction, perp};
use super::lobe::FlatLobe;
use super::scene::Phase;
use super::scene::{Motion, Scene, Sensor};
use super::space::Plane;
use crate::error::Error;
use crate::estimator::Quantity;
use crate::fd::CentralDifference;
use crate::method::model::{self, Model, Step};
use crate::path::deform::SlotSet;
use crate::path::estimator::{DerivativeEstimator, Scheme};
use crate::path::thin_media::chord_bound;
use crate::path::walk::{Frame, Vertex};
use crate::path::{MovingVertex, NO_PRIM, Surface, Warping};
use crate::scene::pose::pose;
use glam::DVec2;
use std::sync::Arc;

pub use super::caveats::TIE;
/// The methods: every [`Method`] runs on a flatland scene
/// (`method.estimator(scene)` with `scene: Arc<Scene>`).
pub use crate::method::Method;
pub use crate::scene::material::MAX_EXPECTATION_G;

impl Model for Scene {
    type Geometry = Plane;
    type FdView = ();
    const SHAPE: &'static str = "shape";
    const GRADIENT_AXES: &'static [&'static str] = &super::scene::GRADIENT_AXES;

    fn geometry(scene: Arc<Self>) -> Plane {
        Plane::new(scene)
    }
    fn is_camera(&self) -> bool {
        matches!(self.sensor(), Sensor::Camera { .. })
    }
    fn shape_count(&self) -> usize {
        self.shapes().len()
    }
    fn shape_name(&self, k: u32) -> &str {
        &self.shapes()[k as usize].name
    }
    fn surface(&self, k: u32) -> Surface {
        self.shapes()[k as usize].surface
    }
    fn medium(&self, k: u32) -> Option<(f64, f64)> {
        self.shapes()[k as usize]
            .medium
            .map(|m| (m.ks, m.phase.g()))
    }
    fn chord(&self, k: u32) -> f64 {
        chord_bound(&self.shapes()[k as usize].vertices)
    }
    fn parent_medium(&self, k: u32) -> Option<u32> {
        Scene::parent_medium(self, k)
    }
    fn parameter_names(&self) -> impl Iterator<Item = &str> {
        self.parameters().iter().map(|p| p.name.as_str())
    }
    fn parameter_shape(&self, j: usize) -> u32 {
        Scene::parameter_shape(self, j)
    }
    fn translates(&self, j: usize) -> bool {
        matches!(
            self.parameters()[j].motion,
            Motion::TranslateX | Motion::TranslateY
        )
    }
    fn size(&self) -> f64 {
        Scene::size(self)
    }
    fn displaced(&self, j: usize, delta: f64) -> Result<Self, Error> {
        Scene::displaced(self, j, delta)
    }
    type Sensor = Sensor;
    fn sensor(&self) -> Sensor {
        Scene::sensor(self)
    }
    fn with_sensor(&self, sensor: Sensor) -> Result<Self, Error> {
        Scene::new(self.shapes().to_vec(), self.parameters().to_vec(), sensor)
    }
    fn posed(&self, offsets: &[f64]) -> Result<Self, Error> {
        let params = self.parameters();
        let owner: Vec<u32> = (0..params.len()).map(|j| self.parameter_shape(j)).collect();
        let (shapes, params) = pose(self.shapes(), params, &owner, offsets)?;
        Scene::new(shapes, params, self.sensor())
    }
    fn offset_rate(&self, j: usize, offset: f64) -> f64 {
        crate::scene::pose::Pose::offset_rate(&self.parameters()[j].motion, offset)
    }
    fn bounds(&self, j: usize) -> Option<[f64; 2]> {
        self.parameters()[j].bounds
    }
    fn pixels(sensor: &Sensor) -> u64 {
        match sensor {
            Sensor::Camera { width, .. } => u64::from(*width),
            _ => 1,
        }
    }
    fn derivative_caveats(plane: &Plane, _gradient: bool) -> Vec<(Quantity, String)> {
        ties(plane.scene())
    }
    fn fd_view(&self) {}
    fn fd_caveat(&self, step: &Step<'_, Self>, _: &()) -> Option<String> {
        view_change(self, step)
    }
    fn fd_nominal_caveats(_: &Plane) -> Vec<(Quantity, String)> {
        Vec::new()
    }
}

/// The derivative estimator of `scheme` on `scene`.
pub fn derivative(scene: Arc<Scene>, scheme: Scheme) -> DerivativeEstimator<Plane> {
    model::derivative(scene, scheme)
}

/// Central differences with common random numbers on `scene`, half step
/// `step` (relative to the scene's size for a translation): see
/// [`model::finite_difference`].
pub fn finite_difference(scene: &Arc<Scene>, step: f64) -> Result<CentralDifference, Error> {
    model::finite_difference(scene, step)
}

/// The expectation method's warp field at the sensor, for figures: `V_j(φ)` (rad per unit of
/// parameter `j`) of the looking direction at angle `phi` from +x. For an
/// irradiance sensor, directions behind it get 0 (the field is pinned to the
/// frame at the horizons).
pub fn sensor_warp(plane: &Plane, phi: f64) -> Vec<f64> {
    let scene = plane.scene();
    let n = scene.parameters().len();
    let w = direction(phi);
    let (x, lobe, at_sensor) = match scene.sensor() {
        Sensor::Irradiance { point, normal } => {
            if w.dot(normal) <= 0.0 {
                return vec![0.0; n];
            }
            (point, FlatLobe::Cosine { n: normal, c: 1.0 }, true)
        }
        Sensor::Radiance { point, direction }
        | Sensor::Camera {
            position: point,
            direction,
            ..
        } => (
            point,
            FlatLobe::Phase {
                phase: Phase::Isotropic,
                w_in: direction,
            },
            false,
        ),
    };
    let v = Vertex {
        x,
        medium: scene.sensor_medium(),
        skip: NO_PRIM,
        lobe,
        w_in: w,
        frame: Frame::Sensor,
        beta: 1.0,
        at_sensor,
        mixed: false,
    };
    let field = plane.warp(&v, w, None, SlotSet::EMPTY);
    (0..n)
        .map(|j| {
            let velocity = |q: DVec2, k: u32| {
                if scene.parameter_shape(j) == k {
                    scene.parameters()[j].motion.velocity(q)
                } else {
                    DVec2::ZERO
                }
            };
            let still = MovingVertex {
                x,
                u: DVec2::ZERO,
                spin: 0.0,
            };
            let (wd, _) = plane.warp_velocity(&field, 0, still, w, velocity);
            wd.dot(perp(w))
        })
        .collect()
}
