//! A flatland scene: shapes (polylines and polygons) with a surface and
//! optionally a homogeneous medium inside, the shape parameters whose
//! sensitivities are wanted, and the sensor. [`Scene::new`] validates
//! everything a user can get wrong (the book's "Flatland" chapter lists the
//! rules); the path tracer then never meets a degenerate configuration.
//!
//! This file holds the data types and the validated [`Scene`] with its
//! accessors; `validate` builds a scene step by step (with the checks in
//! `shared`, which 3D's validation uses too) and `repr` holds the file
//! forms of the tagged enums.
use super::corners::CornerTree;
use super::geometry::{NO_SEGMENT, RayCast, Segment, perp};
use crate::error::Error;
use glam::DVec2;
use serde::{Deserialize, Serialize};

mod repr;
#[cfg(test)]
mod tests;
mod touch;
mod validate;

pub use crate::scene::limits::{
    MAX_OFFSET, MAX_OPTICAL_THICKNESS, MAX_PARAMETERS, MAX_SCATTERING_EVENTS, MAX_SIZE, MIN_SIZE,
};
pub use crate::scene::material::Phase;

/// The axes of flatland's sensor gradient (transport's `∂I/∂x`, `∂I/∂y`).
pub(crate) const GRADIENT_AXES: [&str; 2] = ["x", "y"];

/// What happens to light arriving at a shape's boundary: the path core's
/// surfaces (serialised through the file form in `crate::scene::material`).
pub use crate::path::Surface;

/// A homogeneous medium filling a closed shape. A file gives its phase
/// function as `phase = { kind = …, g = … }` or, as 3D files do, as `g` (0:
/// isotropic), not both.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "repr::Medium")]
pub struct Medium {
    /// Scattering coefficient κs ≥ 0.
    pub ks: f64,
    /// Extinction coefficient κe ≥ κs.
    pub ke: f64,
    /// Phase function.
    #[serde(default)]
    pub phase: Phase,
}

/// A polyline (`closed = false`) or polygon (`closed = true`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Shape {
    /// Unique name, used by parameters.
    pub name: String,
    /// Vertices in order, as `[x, y]`.
    #[serde(deserialize_with = "crate::rows::points2")]
    pub vertices: Vec<DVec2>,
    /// Whether the last vertex connects back to the first.
    #[serde(default)]
    pub closed: bool,
    /// The boundary's behaviour.
    pub surface: Surface,
    /// The medium inside (closed, transparent shapes only).
    #[serde(default)]
    pub medium: Option<Medium>,
}

impl Shape {
    /// The shape's segments, in vertex order.
    pub fn segments(&self) -> impl Iterator<Item = Segment> + '_ {
        let n = self.vertices.len();
        let m = if self.closed { n } else { n - 1 };
        (0..m).map(move |i| Segment {
            a: self.vertices[i],
            b: self.vertices[(i + 1) % n],
        })
    }

    /// Mean of the vertices: the default pivot.
    pub fn centroid(&self) -> DVec2 {
        self.vertices.iter().sum::<DVec2>() / self.vertices.len() as f64
    }
}

impl crate::scene::pose::Posable for Shape {
    type V = DVec2;
    fn vertices_mut(&mut self) -> &mut [DVec2] {
        &mut self.vertices
    }
}

impl crate::scene::pose::Pose for Motion {
    type V = DVec2;
    fn apply(&self, q: DVec2, delta: f64) -> DVec2 {
        Motion::apply(self, q, delta)
    }
    fn translation(&self, delta: f64) -> Option<DVec2> {
        match self {
            Motion::TranslateX | Motion::TranslateY => Some(self.apply(DVec2::ZERO, delta)),
            _ => None,
        }
    }
    fn offset_rate(&self, offset: f64) -> f64 {
        match self {
            Motion::Scale { .. } => 1.0 / (1.0 + offset),
            _ => 1.0,
        }
    }
    fn pivot_moved(&self, d: DVec2) -> Motion {
        match *self {
            Motion::Rotate { pivot } => Motion::Rotate {
                pivot: Some(pivot.unwrap_or(DVec2::ZERO) + d),
            },
            Motion::Scale { pivot } => Motion::Scale {
                pivot: Some(pivot.unwrap_or(DVec2::ZERO) + d),
            },
            m => m,
        }
    }
}

/// How a parameter moves its shape.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(from = "repr::Motion", into = "repr::Motion")]
pub enum Motion {
    /// Translation along x (π = offset, nominal 0).
    TranslateX,
    /// Translation along y (π = offset, nominal 0).
    TranslateY,
    /// Rotation about a pivot (π = angle in radians, nominal 0).
    Rotate {
        /// Pivot; the shape's centroid if absent.
        pivot: Option<DVec2>,
    },
    /// Uniform scale about a pivot (π = factor − 1, nominal 0).
    Scale {
        /// Pivot; the shape's centroid if absent.
        pivot: Option<DVec2>,
    },
}

impl Motion {
    /// Velocity `∂q/∂π` of the shape point `q` (pivots resolved).
    #[inline]
    pub fn velocity(&self, q: DVec2) -> DVec2 {
        match *self {
            Motion::TranslateX => DVec2::X,
            Motion::TranslateY => DVec2::Y,
            Motion::Rotate { pivot } => perp(q - pivot.unwrap_or(DVec2::ZERO)),
            Motion::Scale { pivot } => q - pivot.unwrap_or(DVec2::ZERO),
        }
    }

    /// Rate at which the shape's directions turn, `∂θ/∂π`.
    #[inline]
    pub fn spin(&self) -> f64 {
        if matches!(self, Motion::Rotate { .. }) {
            1.0
        } else {
            0.0
        }
    }

    /// The point `q` moved by the finite parameter change `delta`.
    pub fn apply(&self, q: DVec2, delta: f64) -> DVec2 {
        match *self {
            Motion::TranslateX => q + DVec2::new(delta, 0.0),
            Motion::TranslateY => q + DVec2::new(0.0, delta),
            Motion::Rotate { pivot } => {
                let c = pivot.unwrap_or(DVec2::ZERO);
                c + DVec2::from_angle(delta).rotate(q - c)
            }
            Motion::Scale { pivot } => {
                let c = pivot.unwrap_or(DVec2::ZERO);
                c + (1.0 + delta) * (q - c)
            }
        }
    }
}

/// A shape parameter π whose sensitivity `∂I/∂π` is estimated: the
/// dimension-neutral [`crate::scene::parameter::Parameter`] with flatland's
/// [`Motion`].
pub type Parameter = crate::scene::parameter::Parameter<Motion>;

/// What is measured, at a static point.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Sensor {
    /// Radiance arriving at `point` from `direction` (the direction the
    /// sensor looks toward).
    Radiance {
        /// Where.
        #[serde(deserialize_with = "repr::point")]
        point: DVec2,
        /// Looking direction (normalised on construction).
        #[serde(deserialize_with = "repr::direction")]
        direction: DVec2,
    },
    /// Irradiance `E = ∫ L(η) (η·n)⁺ dθ` at `point` with unit normal `n`.
    Irradiance {
        /// Where.
        #[serde(deserialize_with = "repr::point")]
        point: DVec2,
        /// Normal (normalised on construction).
        #[serde(deserialize_with = "repr::normal")]
        normal: DVec2,
    },
    /// A line camera (`geosens::image::render`): `width` pixels across the
    /// field of view `fov_deg` about `direction`, pixel 0 on the left
    /// (counter-clockwise side) as one looks along `direction`; each pixel
    /// is the mean radiance over its footprint on the image line.
    Camera {
        /// The pinhole.
        #[serde(deserialize_with = "repr::position")]
        position: DVec2,
        /// View axis (normalised on construction).
        #[serde(deserialize_with = "repr::direction")]
        direction: DVec2,
        /// Field of view in degrees, in `(0, 170]`.
        #[serde(deserialize_with = "repr::fov_deg")]
        fov_deg: f64,
        /// Pixels, 1 to 8192.
        #[serde(deserialize_with = "repr::width")]
        width: u32,
    },
}

impl Sensor {
    /// The sensor's point (a camera's pinhole).
    pub fn point(&self) -> DVec2 {
        match *self {
            Sensor::Radiance { point, .. } | Sensor::Irradiance { point, .. } => point,
            Sensor::Camera { position, .. } => position,
        }
    }
}

/// A validated scene, with its ray casters and medium nesting.
pub struct Scene {
    shapes: Vec<Shape>,
    parameters: Vec<Parameter>,
    /// Shape index of each parameter.
    parameter_shape: Vec<u32>,
    sensor: Sensor,
    segments: Vec<Segment>,
    /// Shape of each segment.
    owner: Vec<u32>,
    /// Unit normal of each segment, outward for closed shapes.
    normal: Vec<DVec2>,
    /// All segments.
    caster: Box<dyn RayCast>,
    /// Opaque segments only (for visibility), and the map from a segment's
    /// index to its index there.
    opaque: Box<dyn RayCast>,
    opaque_index: Vec<u32>,
    /// The opaque segments and their shapes, by opaque index.
    opaque_segments: Vec<Segment>,
    opaque_owner: Vec<u32>,
    /// The corners bucketed for triangle queries (many corners only).
    corner_tree: Option<CornerTree>,
    /// Emitting segments with their cumulative length (for next-event
    /// estimation), and the total length.
    emitters: Vec<(u32, f64)>,
    emitter_length: f64,
    /// Vertices of opaque shapes with their shape: where the integrand over
    /// directions seen from a point can jump.
    corners: Vec<(DVec2, u32)>,
    /// For each shape, the medium shape around it.
    parent: Vec<Option<u32>>,
    sensor_medium: Option<u32>,
    size: f64,
}

impl std::fmt::Debug for Scene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Scene")
            .field("shapes", &self.shapes)
            .field("parameters", &self.parameters)
            .field("sensor", &self.sensor)
            .finish_non_exhaustive()
    }
}

impl Clone for Scene {
    fn clone(&self) -> Scene {
        Scene::new(self.shapes.clone(), self.parameters.clone(), self.sensor)
            .expect("a valid scene stays valid")
    }
}

impl Scene {
    /// The same scene with parameter `j` changed by `delta` (its shape
    /// moved), validated again.
    pub fn displaced(&self, j: usize, delta: f64) -> Result<Scene, Error> {
        let p = crate::scene::parameter::displaced(&self.parameters, j, delta)?;
        let mut shapes = self.shapes.clone();
        let k = self.parameter_shape[j] as usize;
        for v in &mut shapes[k].vertices {
            *v = p.motion.apply(*v, delta);
        }
        Scene::new(shapes, self.parameters.clone(), self.sensor)
    }

    /// The shapes.
    pub fn shapes(&self) -> &[Shape] {
        &self.shapes
    }
    /// The parameters, pivots resolved.
    pub fn parameters(&self) -> &[Parameter] {
        &self.parameters
    }
    /// The sensor (its direction or normal normalised).
    pub fn sensor(&self) -> Sensor {
        self.sensor
    }
    /// Largest extent of the scene's bounding box.
    pub fn size(&self) -> f64 {
        self.size
    }
    /// All segments (in shape order).
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }
    /// The shape index of segment `i`.
    #[inline]
    pub fn owner(&self, i: u32) -> u32 {
        self.owner[i as usize]
    }
    /// Unit normal of segment `i` (outward for closed shapes).
    #[inline]
    pub fn normal(&self, i: u32) -> DVec2 {
        self.normal[i as usize]
    }
    /// The shape owning segment `i`.
    #[inline]
    pub fn shape_of(&self, i: u32) -> &Shape {
        &self.shapes[self.owner[i as usize] as usize]
    }
    /// Shape index moved by parameter `j`.
    #[inline]
    pub fn parameter_shape(&self, j: usize) -> u32 {
        self.parameter_shape[j]
    }
    /// Whether no opaque segment (other than `skip`) lies strictly between
    /// `from` and `to`.
    #[inline]
    pub fn visible(&self, from: DVec2, to: DVec2, skip: u32) -> bool {
        let d = to - from;
        let len = d.length();
        let skip = if skip == NO_SEGMENT {
            NO_SEGMENT
        } else {
            self.opaque_index[skip as usize]
        };
        !self.opaque.any_hit(
            from,
            d / len,
            len * (1.0 - crate::path::tolerance::SHORT_OF_END),
            skip,
        )
    }
    /// Whether corner `i` is seen from `from`: [`Self::visible`], except
    /// that the corner's own segments do not hide it. A ray aimed at a
    /// corner meets them only there, but a grazing one (an edge-on lamp's
    /// far end) finds them up to ~ε·|q|/γ short of it by rounding, which
    /// 500 sizes from the origin hid the corner (`path::Boundaries::holds`
    /// is the nested paths' twin).
    pub fn sees_corner(&self, from: DVec2, i: usize, skip: u32) -> bool {
        let q = self.corners[i].0;
        if self.visible(from, q, skip) {
            return true;
        }
        let d = q - from;
        let len = d.length();
        let w = d / len;
        let (mut x, mut left, mut skip, mut passes) = (from, len, skip, 0);
        loop {
            match self.cast(x, w, skip) {
                Some(h) if h.t < left * (1.0 - crate::path::tolerance::SHORT_OF_END) => {
                    let seg = self.segments[h.segment as usize];
                    let own = seg.a == q || seg.b == q;
                    let passes_left = passes < crate::path::walk::HOLDING_PASSES;
                    if self.shape_of(h.segment).surface.is_opaque() && !(own && passes_left) {
                        return false;
                    }
                    passes += own as u32;
                    x += w * h.t;
                    left -= h.t;
                    skip = h.segment;
                }
                _ => return true,
            }
        }
    }
    /// The first opaque segment along a ray (not `skip`): distance, the
    /// segment and its shape.
    #[inline]
    pub fn opaque_hit(&self, origin: DVec2, dir: DVec2, skip: u32) -> Option<(f64, Segment, u32)> {
        let skip = if skip == NO_SEGMENT {
            NO_SEGMENT
        } else {
            self.opaque_index[skip as usize]
        };
        self.opaque
            .closest_hit(origin, dir, f64::INFINITY, skip)
            .map(|h| {
                let i = h.segment as usize;
                (h.t, self.opaque_segments[i], self.opaque_owner[i])
            })
    }
    /// The corners bucketed for triangle queries, for scenes with more than
    /// [`CORNER_TREE_THRESHOLD`] corners.
    pub fn corner_tree(&self) -> Option<&CornerTree> {
        self.corner_tree.as_ref()
    }
    /// A point drawn uniformly (by length) on the emitting segments from a
    /// uniform number `u ∈ [0, 1)`: the point, its segment; `None` without
    /// emitters.
    #[inline]
    pub fn emitter_point(&self, u: f64) -> Option<(DVec2, u32)> {
        let (&(_, total), _) = self.emitters.split_last()?;
        let s = u * total;
        let i = self
            .emitters
            .partition_point(|e| e.1 <= s)
            .min(self.emitters.len() - 1);
        let (seg, end) = self.emitters[i];
        let segment = self.segments[seg as usize];
        let len = segment.length();
        let along = ((s - (end - len)) / len).clamp(0.0, 1.0);
        Some((segment.a + along * (segment.b - segment.a), seg))
    }
    /// Total length of the emitting segments.
    #[inline]
    pub fn emitter_length(&self) -> f64 {
        self.emitter_length
    }
    /// Vertices of opaque shapes, with their shape.
    pub fn corners(&self) -> &[(DVec2, u32)] {
        &self.corners
    }
    /// The medium shape enclosing shape `k` (tested at its first vertex:
    /// shapes do not cross).
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

/// Most corners the warp scans one by one; above, a [`CornerTree`].
pub const CORNER_TREE_THRESHOLD: usize = 64;

/// Most segments a scene traces by linear scan; above, a BVH.
pub const BVH_THRESHOLD: usize = 24;
