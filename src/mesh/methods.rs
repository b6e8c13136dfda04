//! The 3D estimators behind the crate's [`Estimator`](crate::Estimator) interface, the same
//! path core as flatland's ([`crate::path`]) over [`Space`]:
//!
//! - [`Method::Intensity`]: backward path tracing with next-event
//!   estimation and MIS, free-path sampling in media;
//! - [`Method::Rendering`]: interior derivative, Leibniz terms at moving
//!   medium boundaries, and edge terms (silhouettes, open edges, creases)
//!   seen from every path vertex and every lamp connection, double
//!   randomised, the jump evaluated exactly at the edge;
//! - [`Method::Transport`]: the coupled models of `s` and `∇I` with sources
//!   on the moving boundaries; it also returns `∂I/∂x`, `∂I/∂y`, `∂I/∂z` at
//!   the sensor (not for a camera);
//! - [`Method::Fd`]: central differences with common random numbers, one
//!   pair of displaced scenes per parameter;
//! - [`Method::Expectation`]: the same paths deformed by the fibre warp on
//!   the sphere of directions ([`super::warp`]) and stretched free paths in
//!   moving media; no boundary term, no nested path.
//!
//! The dispatch is the dimension-neutral method layer's
//! ([`crate::method::model`]); this file says what it needs of a 3D scene
//! ([`Model`]); the caveat detectors are in [`super::caveats`].
use super::caveats::fd::{outruns_lamp, passes_sensor, turns_face};
use super::caveats::fd_view::{outlines, view_crossing};
pub use super::caveats::{edge_ties, kinks, plane_kinks_of_the_gradient};
use super::scene::{Motion, Scene, Sensor};
use super::space::Space;
use crate::error::Error;
use crate::estimator::Quantity;
use crate::fd::CentralDifference;
use crate::method::model::{self, Model, Step};
use crate::path::Surface;
use crate::path::estimator::{DerivativeEstimator, Scheme};
use crate::path::thin_media::chord_bound;
use crate::scene::pose::pose;
use std::sync::Arc;

pub use super::caveats::{EDGE_ON_ULPS, TIE};
pub use crate::method::Method;

impl Model for Scene {
    type Geometry = Space;
    /// The opaque meshes' outlines seen from the sensor.
    type FdView = Vec<Vec<[u32; 2]>>;
    const SHAPE: &'static str = "mesh";
    const GRADIENT_AXES: &'static [&'static str] = &super::scene::GRADIENT_AXES;

    fn geometry(scene: Arc<Self>) -> Space {
        Space::new(scene)
    }
    fn is_camera(&self) -> bool {
        matches!(self.sensor(), Sensor::Camera(_))
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
        self.shapes()[k as usize].medium.map(|m| (m.ks, m.g))
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
            Motion::TranslateX | Motion::TranslateY | Motion::TranslateZ
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
        Scene::with_sensor(self, sensor)
    }
    fn posed(&self, offsets: &[f64]) -> Result<Self, Error> {
        let params = self.parameters();
        let owner: Vec<u32> = (0..params.len()).map(|j| self.parameter_shape(j)).collect();
        let (shapes, params) = pose(self.shapes(), params, &owner, offsets)?;
        self.moved(shapes, params)
    }
    fn offset_rate(&self, j: usize, offset: f64) -> f64 {
        crate::scene::pose::Pose::offset_rate(&self.parameters()[j].motion, offset)
    }
    fn bounds(&self, j: usize) -> Option<[f64; 2]> {
        self.parameters()[j].bounds
    }
    fn pixels(sensor: &Sensor) -> u64 {
        match sensor {
            Sensor::Camera(c) => u64::from(c.width) * u64::from(c.height),
            _ => 1,
        }
    }
    fn derivative_caveats(space: &Space, gradient: bool) -> Vec<(Quantity, String)> {
        let mut caveats = kinks(space.scene());
        if gradient {
            caveats.extend(plane_kinks_of_the_gradient(space.scene()));
        }
        // Ties also kink the sensor's gradient (its motion off their
        // plane), where transport estimates it.
        for (q, why) in edge_ties(space) {
            let wanted = gradient || matches!(q, Quantity::Sensitivity(_));
            if wanted && !caveats.iter().any(|c: &(Quantity, String)| c.0 == q) {
                caveats.push((q, why));
            }
        }
        caveats
    }
    fn fd_view(&self) -> Self::FdView {
        outlines(self)
    }
    fn fd_caveat(&self, step: &Step<'_, Self>, outlines: &Self::FdView) -> Option<String> {
        let &Step { j, h, .. } = step;
        passes_sensor(self, j, h)
            .or_else(|| turns_face(self, step))
            .or_else(|| outruns_lamp(self, j, h))
            .or_else(|| view_crossing(self, step, outlines))
    }
    fn fd_nominal_caveats(space: &Space) -> Vec<(Quantity, String)> {
        let mut caveats = kinks(space.scene());
        caveats.extend(edge_ties(space));
        caveats
    }
}

/// The derivative estimator of `scheme` on `scene`.
pub fn derivative(scene: Arc<Scene>, scheme: Scheme) -> DerivativeEstimator<Space> {
    model::derivative(scene, scheme)
}

/// Central differences with common random numbers on `scene`, half step
/// `step` (relative to the scene's size for a translation): see
/// [`model::finite_difference`].
pub fn finite_difference(scene: &Arc<Scene>, step: f64) -> Result<CentralDifference, Error> {
    model::finite_difference(scene, step)
}
