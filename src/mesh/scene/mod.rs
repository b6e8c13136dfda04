//! A 3D scene: triangle meshes with a surface and optionally a homogeneous
//! medium inside (closed meshes only), the shape parameters whose
//! sensitivities are wanted, and the sensor. [`Scene::new`] welds each mesh
//! by position and validates everything a user can get wrong (the book's 3D
//! chapter lists the rules), so the path tracer never meets a degenerate
//! configuration.
//!
//! This file holds the data types and the validated [`Scene`] with its
//! accessors; `validate` builds a scene step by step, `geometry` holds the
//! exact predicates it uses (triangle distances, winding numbers) and `repr`
//! the file forms of the tagged enums.
use crate::error::Error;
use crate::mesh::edge_sampler::EdgeTables;
use crate::mesh::part::{MeshPart, PartCell};
use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};
use std::sync::{Arc, OnceLock};

mod crossings;
pub mod geometry;
mod repr;
#[cfg(test)]
mod tests;
mod validate;

pub use crate::scene::limits::{
    MAX_OFFSET, MAX_OPTICAL_THICKNESS, MAX_PARAMETERS, MAX_SIZE, MIN_SIZE,
};
use crate::scene::material::Phase;
pub(crate) use geometry::bounds;

/// The sensor's axes, as transport's gradient names them.
pub(crate) const AXES: [(&str, glam::DVec3); 3] = [
    ("x", glam::DVec3::X),
    ("y", glam::DVec3::Y),
    ("z", glam::DVec3::Z),
];

/// The axes of 3D's sensor gradient (transport's `∂I/∂x`, `∂I/∂y`, `∂I/∂z`).
pub(crate) const GRADIENT_AXES: [&str; 3] = ["x", "y", "z"];
pub use validate::DEGENERATE_AREA;

/// Two meshes closer than `TOUCH_DISTANCE × size` (the scene's size) touch:
/// at such distances a ray tracer's offsets cannot tell them apart.
pub const TOUCH_DISTANCE: f64 = 1e-12;

/// What happens to light arriving at a mesh: the path core's surfaces, read
/// and written in the same file form as flatland's.
pub use crate::path::Surface;

/// A homogeneous medium filling a closed mesh, with a Henyey–Greenstein
/// phase function (`g = 0`: isotropic). A file gives it as `g` or, as
/// flatland files do, as `phase = { kind = …, g = … }`, not both.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "MediumFile")]
pub struct Medium {
    /// Scattering coefficient κs ≥ 0.
    pub ks: f64,
    /// Extinction coefficient κe ≥ κs.
    pub ke: f64,
    /// Mean cosine of the Henyey–Greenstein phase function, `|g| < 1`.
    #[serde(default)]
    pub g: f64,
}

/// A medium as a file gives it: 3D's `g` or flatland's `phase` table.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MediumFile {
    ks: f64,
    ke: f64,
    #[serde(default)]
    g: Option<f64>,
    #[serde(default)]
    phase: Option<Phase>,
}

impl TryFrom<MediumFile> for Medium {
    type Error = String;

    fn try_from(m: MediumFile) -> Result<Self, String> {
        let g = match (m.g, m.phase) {
            (Some(_), Some(_)) => {
                return Err(
                    "a medium takes `g` or `phase` (the flatland spelling), not both".into(),
                );
            }
            (Some(g), None) => g,
            (None, Some(phase)) => phase.g(),
            (None, None) => 0.0,
        };
        Ok(Medium {
            ks: m.ks,
            ke: m.ke,
            g,
        })
    }
}

/// A triangle mesh (after [`Scene::new`]: welded by position, every
/// triangle non-degenerate).
#[derive(Debug, Clone, PartialEq)]
pub struct Shape {
    /// Unique name, used by parameters.
    pub name: String,
    /// Vertex positions.
    pub vertices: Vec<DVec3>,
    /// Triangles as indices into `vertices`, counter-clockwise seen from
    /// outside for a closed mesh (its normals point out).
    pub triangles: Vec<[u32; 3]>,
    /// The surface's behaviour (two-sided).
    pub surface: Surface,
    /// The medium inside (closed, transparent meshes only).
    pub medium: Option<Medium>,
}

impl Shape {
    /// The corners of triangle `i`.
    #[inline]
    pub fn triangle(&self, i: usize) -> [DVec3; 3] {
        self.triangles[i].map(|v| self.vertices[v as usize])
    }

    /// Mean of the vertices: the default pivot.
    pub fn centroid(&self) -> DVec3 {
        self.vertices.iter().sum::<DVec3>() / self.vertices.len().max(1) as f64
    }
}

impl crate::scene::pose::Posable for Shape {
    type V = DVec3;
    fn vertices_mut(&mut self) -> &mut [DVec3] {
        &mut self.vertices
    }
}

impl crate::scene::pose::Pose for Motion {
    type V = DVec3;
    fn apply(&self, q: DVec3, delta: f64) -> DVec3 {
        Motion::apply(self, q, delta)
    }
    fn translation(&self, delta: f64) -> Option<DVec3> {
        match self {
            Motion::TranslateX | Motion::TranslateY | Motion::TranslateZ => {
                Some(self.apply(DVec3::ZERO, delta))
            }
            _ => None,
        }
    }
    fn offset_rate(&self, offset: f64) -> f64 {
        match self {
            Motion::Scale { .. } => 1.0 / (1.0 + offset),
            _ => 1.0,
        }
    }
    fn pivot_moved(&self, d: DVec3) -> Motion {
        match *self {
            Motion::Rotate { axis, pivot } => Motion::Rotate {
                axis,
                pivot: Some(pivot.unwrap_or(DVec3::ZERO) + d),
            },
            Motion::Scale { pivot } => Motion::Scale {
                pivot: Some(pivot.unwrap_or(DVec3::ZERO) + d),
            },
            m => m,
        }
    }
}

/// How a parameter moves its mesh (with its medium). File form:
/// `{ kind = "translate_x" }` (`_y`, `_z`), `{ kind = "rotate", axis = [x, y,
/// z], pivot = [x, y, z] }`, `{ kind = "scale", pivot = [x, y, z] }` (pivots
/// optional).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(from = "repr::Motion", into = "repr::Motion")]
pub enum Motion {
    /// Translation along x (π = offset, nominal 0).
    TranslateX,
    /// Translation along y (π = offset, nominal 0).
    TranslateY,
    /// Translation along z (π = offset, nominal 0).
    TranslateZ,
    /// Rotation about the line through `pivot` along `axis` (π = angle in
    /// radians, right-handed about `axis`, nominal 0).
    Rotate {
        /// Unit axis (normalised on validation).
        axis: DVec3,
        /// A point of the axis; the mesh's centroid if absent.
        pivot: Option<DVec3>,
    },
    /// Uniform scale about a pivot (π = factor − 1, nominal 0).
    Scale {
        /// Pivot; the mesh's centroid if absent.
        pivot: Option<DVec3>,
    },
}

impl Motion {
    /// Velocity `∂q/∂π` of the mesh point `q` (pivots resolved).
    #[inline]
    pub fn velocity(&self, q: DVec3) -> DVec3 {
        match *self {
            Motion::TranslateX => DVec3::X,
            Motion::TranslateY => DVec3::Y,
            Motion::TranslateZ => DVec3::Z,
            Motion::Rotate { axis, pivot } => axis.cross(q - pivot.unwrap_or(DVec3::ZERO)),
            Motion::Scale { pivot } => q - pivot.unwrap_or(DVec3::ZERO),
        }
    }

    /// Angular velocity `∂Ω/∂π` of the mesh's frame (its normals turn as
    /// `Ω × n`).
    #[inline]
    pub fn spin(&self) -> DVec3 {
        match *self {
            Motion::Rotate { axis, .. } => axis,
            _ => DVec3::ZERO,
        }
    }

    /// The point `q` moved by the finite parameter change `delta`.
    pub fn apply(&self, q: DVec3, delta: f64) -> DVec3 {
        match *self {
            Motion::TranslateX => q + DVec3::new(delta, 0.0, 0.0),
            Motion::TranslateY => q + DVec3::new(0.0, delta, 0.0),
            Motion::TranslateZ => q + DVec3::new(0.0, 0.0, delta),
            Motion::Rotate { axis, pivot } => {
                let c = pivot.unwrap_or(DVec3::ZERO);
                c + DQuat::from_axis_angle(axis.normalize(), delta) * (q - c)
            }
            Motion::Scale { pivot } => {
                let c = pivot.unwrap_or(DVec3::ZERO);
                c + (1.0 + delta) * (q - c)
            }
        }
    }
}

/// A shape parameter π whose sensitivity `∂I/∂π` is estimated: the
/// dimension-neutral [`crate::scene::parameter::Parameter`] with 3D's
/// [`Motion`].
pub type Parameter = crate::scene::parameter::Parameter<Motion>;

/// What is measured, at a static point. File form: `{ kind =
/// "irradiance", point = [x, y, z], normal = [x, y, z] }`, `{ kind =
/// "radiance", point = [x, y, z], direction = [x, y, z] }` or `{ kind =
/// "camera", position, look_at, up, fov_deg, width, height }`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(from = "repr::Sensor", into = "repr::Sensor")]
pub enum Sensor {
    /// Radiance arriving at `point` from `direction` (the direction the
    /// sensor looks toward; unit after validation).
    Radiance {
        /// Where.
        point: DVec3,
        /// Looking direction.
        direction: DVec3,
    },
    /// Irradiance `E = ∫ L(η) (η·n)⁺ dη` at `point` with unit normal `n`.
    Irradiance {
        /// Where.
        point: DVec3,
        /// Normal (unit after validation).
        normal: DVec3,
    },
    /// A pinhole camera: an image of pixel means (`geosens render`).
    Camera(crate::mesh::camera::Camera),
}

impl Sensor {
    /// The sensor's point (a camera's pinhole).
    pub fn point(&self) -> DVec3 {
        match *self {
            Sensor::Radiance { point, .. } | Sensor::Irradiance { point, .. } => point,
            Sensor::Camera(c) => c.position,
        }
    }
}

/// A validated scene: welded meshes, resolved parameters, medium nesting.
#[derive(Debug, Clone)]
pub struct Scene {
    shapes: Vec<Shape>,
    parameters: Vec<Parameter>,
    /// Shape index of each parameter.
    parameter_shape: Vec<u32>,
    sensor: Sensor,
    /// Per shape, whether its mesh is closed (every edge shared by exactly
    /// two triangles with opposite orientations).
    closed: Vec<bool>,
    /// Per shape, whether it is a solid: closed, opaque, and the sensor
    /// outside it, so no path reaches its inside.
    solid: Vec<bool>,
    /// For each shape, the medium shape around it (innermost enclosing
    /// closed mesh with a medium), if any.
    parent: Vec<Option<u32>>,
    sensor_medium: Option<u32>,
    size: f64,
    /// Per shape, the volume it encloses (0 if open).
    volume: Vec<f64>,
    /// Per shape, its tables (caster, edges), built on first use and
    /// shared with the scenes derived from this one that hold it unmoved.
    parts: Vec<PartCell>,
    /// The edge tables over all meshes (they do not depend on the sensor),
    /// built on first use and shared with the scenes derived from this one
    /// by another sensor.
    tables: Arc<OnceLock<EdgeTables>>,
}

impl Scene {
    /// The same scene with parameter `j` changed by `delta` (its mesh
    /// moved), validated again.
    pub fn displaced(&self, j: usize, delta: f64) -> Result<Scene, Error> {
        let p = crate::scene::parameter::displaced(&self.parameters, j, delta)?;
        let mut shapes = self.shapes.clone();
        let k = self.parameter_shape[j] as usize;
        for v in &mut shapes[k].vertices {
            *v = p.motion.apply(*v, delta);
        }
        self.moved(shapes, self.parameters.clone())
    }

    /// The edge tables, built by `build` if no scene sharing them has.
    pub(crate) fn edge_tables(&self, build: impl FnOnce() -> EdgeTables) -> &EdgeTables {
        self.tables.get_or_init(build)
    }

    /// Mesh `k`'s tables, built now if no scene sharing them has.
    pub(crate) fn part(&self, k: usize) -> Arc<MeshPart> {
        self.parts[k]
            .get_or_init(|| Arc::new(MeshPart::new(&self.shapes[k])))
            .clone()
    }

    /// The meshes, welded.
    pub fn shapes(&self) -> &[Shape] {
        &self.shapes
    }
    /// The parameters, pivots resolved and axes normalised.
    pub fn parameters(&self) -> &[Parameter] {
        &self.parameters
    }
    /// Shape index moved by parameter `j`.
    #[inline]
    pub fn parameter_shape(&self, j: usize) -> u32 {
        self.parameter_shape[j]
    }
    /// The sensor (its direction or normal normalised).
    pub fn sensor(&self) -> Sensor {
        self.sensor
    }
    /// Whether shape `k`'s mesh is closed.
    pub fn is_closed(&self, k: u32) -> bool {
        self.closed[k as usize]
    }
    /// Whether shape `k` is a solid: a closed opaque mesh the sensor is
    /// outside, whose inside no path reaches (a closed opaque mesh around
    /// the sensor is a room instead).
    #[inline]
    pub fn is_solid(&self, k: u32) -> bool {
        self.solid[k as usize]
    }
    /// Largest extent of the scene's bounding box.
    pub fn size(&self) -> f64 {
        self.size
    }
    /// The medium shape enclosing shape `k`.
    #[inline]
    pub fn parent_medium(&self, k: u32) -> Option<u32> {
        self.parent[k as usize]
    }
    /// The medium shape around the sensor.
    pub fn sensor_medium(&self) -> Option<u32> {
        self.sensor_medium
    }
    /// The medium of shape `k`, if any.
    #[inline]
    pub fn medium(&self, k: Option<u32>) -> Option<&Medium> {
        k.and_then(|k| self.shapes[k as usize].medium.as_ref())
    }
}
