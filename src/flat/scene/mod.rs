//! A flatland scene: shapes (polylines and polygons) with a surface and
//! optionally a homogeneous medium inside, the shape parameters whose
//! sensitivities are wanted, and the sensor. [`Scene::new`] validates
//! everything a user can get wrong (the book's "Flatland" chapter lists the
//! rules); the path tracer then never meets a degenerate configuration.
use super::corners::CornerGrid;
use super::geometry::{
    LinearScan, NO_SEGMENT, RayCast, Segment, contains, cross, perp, signed_area,
};
use crate::error::Error;
use glam::DVec2;
use serde::{Deserialize, Serialize};

/// Largest extinction coefficient times scene size accepted: beyond it a
/// medium is opaque for every purpose and the weights underflow.
pub const MAX_OPTICAL_THICKNESS: f64 = 1e4;

/// Most parameters (plus the two sensor-gradient axes) one path carries.
pub const MAX_PARAMETERS: usize = 14;

/// What happens to light arriving at a shape's boundary.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(from = "repr::Surface", into = "repr::Surface")]
pub enum Surface {
    /// Two-sided Lambertian emitter of uniform radiance; absorbs what arrives.
    Emitter {
        /// Emitted radiance (≥ 0).
        radiance: f64,
    },
    /// Black: absorbs everything.
    Absorber,
    /// Two-sided Lambertian reflector.
    Reflector {
        /// Albedo in `[0, 1]`.
        albedo: f64,
    },
    /// An index-matched interface: the boundary of a medium.
    Transparent,
}

impl Surface {
    /// Whether the surface stops rays (all but [`Surface::Transparent`]).
    pub fn is_opaque(&self) -> bool {
        !matches!(self, Surface::Transparent)
    }
}

/// Angular distribution of scattering in a medium (normalised over the circle).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(from = "repr::Phase", into = "repr::Phase")]
pub enum Phase {
    /// `p(θ) = 1/2π`.
    #[default]
    Isotropic,
    /// The flatland Henyey–Greenstein function (the wrapped Cauchy law):
    /// `p(θ) = (1 − g²) / (2π (1 + g² − 2g cos θ))`.
    HenyeyGreenstein {
        /// Mean cosine, `|g| < 1`.
        g: f64,
    },
}

/// A homogeneous medium filling a closed shape.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
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

/// A shape parameter π whose sensitivity `∂I/∂π` is estimated.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Parameter {
    /// Unique name (the key of its sensitivity).
    pub name: String,
    /// Name of the shape it moves (with its medium).
    pub shape: String,
    /// How it moves it.
    pub motion: Motion,
}

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
    /// Irradiance `E = ∫ L(ω) (ω·n)⁺ dθ` at `point` with unit normal `n`.
    Irradiance {
        /// Where.
        #[serde(deserialize_with = "repr::point")]
        point: DVec2,
        /// Normal (normalised on construction).
        #[serde(deserialize_with = "repr::normal")]
        normal: DVec2,
    },
}

impl Sensor {
    /// The sensor's point.
    pub fn point(&self) -> DVec2 {
        match *self {
            Sensor::Radiance { point, .. } | Sensor::Irradiance { point, .. } => point,
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
    corner_grid: Option<CornerGrid>,
    /// Emitting segments with their cumulative length (for next-event
    /// estimation), and the total length.
    emitters: Vec<(u32, f64)>,
    emitter_length: f64,
    /// Vertices of opaque shapes with their shape: where the integrand over
    /// directions seen from a point can jump.
    corners: Vec<(DVec2, u32)>,
    /// For each shape, the medium shape around it (media only).
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

fn config<T>(msg: String) -> Result<T, Error> {
    Err(Error::Scene(msg))
}

fn finite(what: &str, p: DVec2) -> Result<(), Error> {
    if p.is_finite() {
        Ok(())
    } else {
        config(format!("{what} = [{}, {}] is not finite", p.x, p.y))
    }
}

fn unit(what: &str, v: DVec2) -> Result<DVec2, Error> {
    finite(what, v)?;
    let n = v.length();
    if n > 0.0 && n.is_finite() {
        Ok(v / n)
    } else {
        config(format!("{what} = [{}, {}] has no direction", v.x, v.y))
    }
}

impl Scene {
    /// Validates and builds a scene. Errors name the shape or parameter at
    /// fault: non-finite or too few vertices, zero-length or crossing
    /// segments (within a shape or between shapes), coefficients out of
    /// range (κs < 0, κe < κs, |g| ≥ 1, albedo ∉ `[0, 1]`, radiance < 0), a
    /// medium on an open or opaque shape, a transparent shape without a
    /// medium, parameters naming no shape, duplicate names, a sensor on a
    /// segment or inside an opaque closed shape.
    pub fn new(
        shapes: Vec<Shape>,
        parameters: Vec<Parameter>,
        sensor: Sensor,
    ) -> Result<Scene, Error> {
        if shapes.is_empty() {
            return config("a scene needs at least one shape".into());
        }
        let mut lo = DVec2::splat(f64::INFINITY);
        let mut hi = DVec2::splat(f64::NEG_INFINITY);
        for (k, s) in shapes.iter().enumerate() {
            let name = &s.name;
            if name.is_empty() {
                return config(format!("shape {k} has an empty name"));
            }
            if shapes[..k].iter().any(|o| &o.name == name) {
                return config(format!("two shapes are named {name:?}"));
            }
            let least = if s.closed { 3 } else { 2 };
            if s.vertices.len() < least {
                return config(format!(
                    "shape {name:?} has {} vertices: a {} needs at least {least}",
                    s.vertices.len(),
                    if s.closed { "polygon" } else { "polyline" }
                ));
            }
            for (i, &v) in s.vertices.iter().enumerate() {
                finite(&format!("shape {name:?} vertex {i}"), v)?;
                lo = lo.min(v);
                hi = hi.max(v);
            }
            check_surface(name, &s.surface)?;
            match (&s.medium, s.surface) {
                (Some(m), Surface::Transparent) => {
                    if !s.closed {
                        return config(format!("shape {name:?} has a medium but is not closed"));
                    }
                    check_medium(name, m)?;
                }
                (Some(_), _) => {
                    return config(format!(
                        "shape {name:?} has a medium behind an opaque surface: \
                         make its surface transparent"
                    ));
                }
                (None, Surface::Transparent) => {
                    return config(format!(
                        "shape {name:?} is transparent but holds no medium: it would be invisible"
                    ));
                }
                (None, _) => {}
            }
        }
        let size = (hi - lo).max_element().max(f64::MIN_POSITIVE);
        let mut segments = Vec::new();
        let mut owner = Vec::new();
        let mut normal = Vec::new();
        for (k, s) in shapes.iter().enumerate() {
            let ccw = s.closed && signed_area(&s.vertices) > 0.0;
            if s.closed && signed_area(&s.vertices).abs() <= 1e-12 * size * size {
                return config(format!("shape {:?} encloses no area", s.name));
            }
            for (i, seg) in s.segments().enumerate() {
                if seg.length() <= 1e-12 * size {
                    return config(format!("shape {:?}: segment {i} has zero length", s.name));
                }
                let left = seg.left_normal();
                // The left of a counter-clockwise polygon is its inside.
                normal.push(if ccw { -left } else { left });
                segments.push(seg);
                owner.push(k as u32);
            }
        }
        check_crossings(&shapes, &segments, &owner)?;

        let mut parameter_shape = Vec::with_capacity(parameters.len());
        let mut resolved = Vec::with_capacity(parameters.len());
        if parameters.len() > MAX_PARAMETERS {
            return config(format!(
                "{} parameters: at most {MAX_PARAMETERS} are supported",
                parameters.len()
            ));
        }
        for (j, p) in parameters.iter().enumerate() {
            if p.name.is_empty() {
                return config(format!("parameter {j} has an empty name"));
            }
            if parameters[..j].iter().any(|o| o.name == p.name) {
                return config(format!("two parameters are named {:?}", p.name));
            }
            let Some(k) = shapes.iter().position(|s| s.name == p.shape) else {
                return config(format!(
                    "parameter {:?} moves shape {:?}, which does not exist",
                    p.name, p.shape
                ));
            };
            let motion = match p.motion {
                Motion::Rotate { pivot } => {
                    let c = pivot.unwrap_or_else(|| shapes[k].centroid());
                    finite(&format!("parameter {:?} pivot", p.name), c)?;
                    Motion::Rotate { pivot: Some(c) }
                }
                Motion::Scale { pivot } => {
                    let c = pivot.unwrap_or_else(|| shapes[k].centroid());
                    finite(&format!("parameter {:?} pivot", p.name), c)?;
                    Motion::Scale { pivot: Some(c) }
                }
                m => m,
            };
            parameter_shape.push(k as u32);
            resolved.push(Parameter {
                motion,
                ..p.clone()
            });
        }

        let sensor = match sensor {
            Sensor::Radiance { point, direction } => {
                finite("sensor point", point)?;
                Sensor::Radiance {
                    point,
                    direction: unit("sensor direction", direction)?,
                }
            }
            Sensor::Irradiance { point, normal } => {
                finite("sensor point", point)?;
                Sensor::Irradiance {
                    point,
                    normal: unit("sensor normal", normal)?,
                }
            }
        };
        let p = sensor.point();
        for (i, seg) in segments.iter().enumerate() {
            if seg.distance(p) <= 1e-9 * size {
                return config(format!(
                    "the sensor at [{}, {}] lies on shape {:?}",
                    p.x, p.y, shapes[owner[i] as usize].name
                ));
            }
        }
        for s in &shapes {
            if s.closed && s.surface.is_opaque() && contains(&s.vertices, p) {
                return config(format!(
                    "the sensor at [{}, {}] is inside the opaque shape {:?}",
                    p.x, p.y, s.name
                ));
            }
        }
        for s in &shapes {
            if let Some(m) = s.medium
                && m.ke * size > MAX_OPTICAL_THICKNESS
            {
                return config(format!(
                    "shape {:?}: κe × scene size = {} exceeds {MAX_OPTICAL_THICKNESS}",
                    s.name,
                    m.ke * size
                ));
            }
        }

        // The medium around a point: the smallest medium polygon holding it
        // (shapes do not cross, so media nest).
        let area: Vec<f64> = shapes
            .iter()
            .map(|s| {
                if s.closed {
                    signed_area(&s.vertices).abs()
                } else {
                    0.0
                }
            })
            .collect();
        let medium_at = |q: DVec2, except: Option<usize>| -> Option<u32> {
            shapes
                .iter()
                .enumerate()
                .filter(|&(k, s)| {
                    Some(k) != except && s.medium.is_some() && contains(&s.vertices, q)
                })
                .min_by(|a, b| area[a.0].total_cmp(&area[b.0]))
                .map(|(k, _)| k as u32)
        };
        let parent = shapes
            .iter()
            .enumerate()
            .map(|(k, s)| s.medium.and_then(|_| medium_at(s.vertices[0], Some(k))))
            .collect();
        let sensor_medium = medium_at(p, None);

        let mut opaque_segments = Vec::new();
        let mut opaque_owner = Vec::new();
        let mut opaque_index = Vec::with_capacity(segments.len());
        for (i, seg) in segments.iter().enumerate() {
            if shapes[owner[i] as usize].surface.is_opaque() {
                opaque_index.push(opaque_segments.len() as u32);
                opaque_segments.push(*seg);
                opaque_owner.push(owner[i]);
            } else {
                opaque_index.push(NO_SEGMENT);
            }
        }
        let corners = shapes
            .iter()
            .enumerate()
            .filter(|(_, s)| s.surface.is_opaque())
            .flat_map(|(k, s)| s.vertices.iter().map(move |&v| (v, k as u32)))
            .collect::<Vec<(DVec2, u32)>>();
        let corner_grid = (corners.len() > GRID_THRESHOLD)
            .then(|| CornerGrid::new(&corners.iter().map(|c| c.0).collect::<Vec<_>>()));
        let mut emitters = Vec::new();
        let mut emitter_length = 0.0;
        for (i, seg) in segments.iter().enumerate() {
            if let Surface::Emitter { radiance } = shapes[owner[i] as usize].surface
                && radiance > 0.0
            {
                emitter_length += seg.length();
                emitters.push((i as u32, emitter_length));
            }
        }
        Ok(Scene {
            emitters,
            emitter_length,
            caster: caster(segments.clone()),
            opaque: caster(opaque_segments.clone()),
            opaque_index,
            opaque_segments,
            opaque_owner,
            corner_grid,
            corners,
            shapes,
            parameters: resolved,
            parameter_shape,
            sensor,
            segments,
            owner,
            normal,
            parent,
            sensor_medium,
            size,
        })
    }

    /// The same scene with parameter `j` changed by `delta` (its shape
    /// moved), validated again.
    pub fn displaced(&self, j: usize, delta: f64) -> Result<Scene, Error> {
        let Some(p) = self.parameters.get(j) else {
            return config(format!("no parameter {j}"));
        };
        if !delta.is_finite() {
            return config(format!("displacement {delta} is not finite"));
        }
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
    /// Closest segment along a ray (any surface).
    #[inline]
    pub fn cast(&self, origin: DVec2, dir: DVec2, skip: u32) -> Option<super::geometry::Hit> {
        self.caster.closest_hit(origin, dir, f64::INFINITY, skip)
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
        !self.opaque.any_hit(from, d / len, len * (1.0 - 1e-9), skip)
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
    /// [`GRID_THRESHOLD`] corners.
    pub fn corner_grid(&self) -> Option<&CornerGrid> {
        self.corner_grid.as_ref()
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
    /// The medium shape enclosing shape `k` (for media).
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

/// The ray caster for a list of segments: a linear scan for a few, a BVH
/// beyond.
fn caster(segments: Vec<Segment>) -> Box<dyn RayCast> {
    // Measured crossover (`cargo bench --bench raycast`): the BVH's fixed
    // ~100 ns per ray pays off from 16–32 segments.
    if segments.len() <= BVH_THRESHOLD {
        Box::new(LinearScan::new(segments))
    } else {
        Box::new(super::bvh::SegmentBvh::new(segments))
    }
}

/// Most corners the warp scans one by one; above, a [`CornerGrid`].
pub const GRID_THRESHOLD: usize = 64;

/// Most segments a scene traces by linear scan; above, a BVH.
pub const BVH_THRESHOLD: usize = 24;

fn check_surface(name: &str, s: &Surface) -> Result<(), Error> {
    match *s {
        Surface::Emitter { radiance } if !(radiance >= 0.0 && radiance.is_finite()) => config(
            format!("shape {name:?}: radiance {radiance} is not a finite number ≥ 0"),
        ),
        Surface::Reflector { albedo } if !(0.0..=1.0).contains(&albedo) => {
            config(format!("shape {name:?}: albedo {albedo} is not in [0, 1]"))
        }
        _ => Ok(()),
    }
}

fn check_medium(name: &str, m: &Medium) -> Result<(), Error> {
    if !(m.ks >= 0.0 && m.ks.is_finite()) {
        return config(format!(
            "shape {name:?}: κs = {} is not finite and ≥ 0",
            m.ks
        ));
    }
    if !(m.ke >= m.ks && m.ke.is_finite()) {
        return config(format!(
            "shape {name:?}: κe = {} must be finite and ≥ κs = {}",
            m.ke, m.ks
        ));
    }
    if let Phase::HenyeyGreenstein { g } = m.phase
        && (g.abs() >= 1.0 || g.is_nan())
    {
        return config(format!(
            "shape {name:?}: Henyey–Greenstein g = {g} is not in (−1, 1)"
        ));
    }
    Ok(())
}

/// Rejects segments that touch, other than consecutive segments of one shape
/// at their shared vertex. A sweep over x keeps it near-linear for large
/// scenes.
fn check_crossings(shapes: &[Shape], segments: &[Segment], owner: &[u32]) -> Result<(), Error> {
    let mut order: Vec<usize> = (0..segments.len()).collect();
    let lo = |i: usize| segments[i].a.x.min(segments[i].b.x);
    let hi = |i: usize| segments[i].a.x.max(segments[i].b.x);
    order.sort_by(|&i, &j| lo(i).total_cmp(&lo(j)));
    // Index of each segment within its shape, for the adjacency test.
    let mut first = vec![0usize; shapes.len()];
    let mut count = 0;
    for (k, s) in shapes.iter().enumerate() {
        first[k] = count;
        count += if s.closed {
            s.vertices.len()
        } else {
            s.vertices.len() - 1
        };
    }
    for (n, &i) in order.iter().enumerate() {
        for &j in &order[n + 1..] {
            if lo(j) > hi(i) {
                break;
            }
            let (si, sj) = (&segments[i], &segments[j]);
            if !si.touches(sj) {
                continue;
            }
            let (ki, kj) = (owner[i] as usize, owner[j] as usize);
            if ki == kj {
                let s = &shapes[ki];
                let m = if s.closed {
                    s.vertices.len()
                } else {
                    s.vertices.len() - 1
                };
                let (a, b) = (i - first[ki], j - first[ki]);
                let adjacent = a.abs_diff(b) == 1 || (s.closed && a.abs_diff(b) == m - 1);
                // Neighbours share one vertex; they must not fold back on
                // each other.
                let folded = adjacent && {
                    let (ea, eb) = (si.b - si.a, sj.b - sj.a);
                    cross(ea, eb) == 0.0 && ea.dot(eb) < 0.0
                };
                if adjacent && !folded {
                    continue;
                }
                return config(format!("shape {:?} intersects itself", s.name));
            }
            return config(format!(
                "shapes {:?} and {:?} touch or cross: shapes must be disjoint",
                shapes[ki].name, shapes[kj].name
            ));
        }
    }
    Ok(())
}

/// The file forms of [`Surface`], [`Phase`] and [`Motion`]: internally tagged
/// (`kind = "absorber"`) with every variant a struct variant, because serde's
/// `deny_unknown_fields` lets unknown fields through on the unit variants of
/// an internally tagged enum (serde-rs/serde#2123): `{ kind = "absorber",
/// albedo = 0.5 }` would load as a black absorber without a word.
///
/// The fields of tagged enums are read through [`field`]: serde buffers a
/// tagged table before reading it, so the parser's position (TOML's span,
/// JSON's line and column) is the whole table's and its message alone ("invalid
/// type: string, expected f64") would not say which field is wrong.
mod repr {
    use glam::DVec2;
    use serde::de::Error as _;
    use serde::{Deserialize, Deserializer, Serialize};

    /// Deserializes a field, naming it in the error.
    fn field<'de, D: Deserializer<'de>, T: Deserialize<'de>>(
        name: &str,
        d: D,
    ) -> Result<T, D::Error> {
        T::deserialize(d).map_err(|e| D::Error::custom(format_args!("field `{name}`: {e}")))
    }

    macro_rules! fields {
        ($($name:ident: $t:ty),*) => {$(
            pub(super) fn $name<'de, D: Deserializer<'de>>(d: D) -> Result<$t, D::Error> {
                field(stringify!($name), d)
            }
        )*};
    }
    fields!(radiance: f64, albedo: f64, g: f64, pivot: Option<DVec2>,
        point: DVec2, direction: DVec2, normal: DVec2);

    #[derive(Clone, Copy, Serialize, Deserialize)]
    #[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
    pub enum Surface {
        Emitter {
            #[serde(deserialize_with = "radiance")]
            radiance: f64,
        },
        Absorber {},
        Reflector {
            #[serde(deserialize_with = "albedo")]
            albedo: f64,
        },
        Transparent {},
    }

    impl From<Surface> for super::Surface {
        fn from(s: Surface) -> Self {
            match s {
                Surface::Emitter { radiance } => Self::Emitter { radiance },
                Surface::Absorber {} => Self::Absorber,
                Surface::Reflector { albedo } => Self::Reflector { albedo },
                Surface::Transparent {} => Self::Transparent,
            }
        }
    }

    impl From<super::Surface> for Surface {
        fn from(s: super::Surface) -> Self {
            match s {
                super::Surface::Emitter { radiance } => Self::Emitter { radiance },
                super::Surface::Absorber => Self::Absorber {},
                super::Surface::Reflector { albedo } => Self::Reflector { albedo },
                super::Surface::Transparent => Self::Transparent {},
            }
        }
    }

    #[derive(Clone, Copy, Serialize, Deserialize)]
    #[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
    pub enum Phase {
        Isotropic {},
        HenyeyGreenstein {
            #[serde(deserialize_with = "g")]
            g: f64,
        },
    }

    impl From<Phase> for super::Phase {
        fn from(p: Phase) -> Self {
            match p {
                Phase::Isotropic {} => Self::Isotropic,
                Phase::HenyeyGreenstein { g } => Self::HenyeyGreenstein { g },
            }
        }
    }

    impl From<super::Phase> for Phase {
        fn from(p: super::Phase) -> Self {
            match p {
                super::Phase::Isotropic => Self::Isotropic {},
                super::Phase::HenyeyGreenstein { g } => Self::HenyeyGreenstein { g },
            }
        }
    }

    #[derive(Clone, Copy, Serialize, Deserialize)]
    #[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
    pub enum Motion {
        TranslateX {},
        TranslateY {},
        Rotate {
            #[serde(
                default,
                deserialize_with = "pivot",
                skip_serializing_if = "Option::is_none"
            )]
            pivot: Option<DVec2>,
        },
        Scale {
            #[serde(
                default,
                deserialize_with = "pivot",
                skip_serializing_if = "Option::is_none"
            )]
            pivot: Option<DVec2>,
        },
    }

    impl From<Motion> for super::Motion {
        fn from(m: Motion) -> Self {
            match m {
                Motion::TranslateX {} => Self::TranslateX,
                Motion::TranslateY {} => Self::TranslateY,
                Motion::Rotate { pivot } => Self::Rotate { pivot },
                Motion::Scale { pivot } => Self::Scale { pivot },
            }
        }
    }

    impl From<super::Motion> for Motion {
        fn from(m: super::Motion) -> Self {
            match m {
                super::Motion::TranslateX => Self::TranslateX {},
                super::Motion::TranslateY => Self::TranslateY {},
                super::Motion::Rotate { pivot } => Self::Rotate { pivot },
                super::Motion::Scale { pivot } => Self::Scale { pivot },
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(name: &str, c: DVec2, h: f64, surface: Surface) -> Shape {
        Shape {
            name: name.into(),
            vertices: vec![
                c + DVec2::new(-h, -h),
                c + DVec2::new(h, -h),
                c + DVec2::new(h, h),
                c + DVec2::new(-h, h),
            ],
            closed: true,
            surface,
            medium: None,
        }
    }

    fn irradiance() -> Sensor {
        Sensor::Irradiance {
            point: DVec2::ZERO,
            normal: DVec2::Y,
        }
    }

    #[test]
    fn a_valid_scene_resolves_pivots_and_normals() {
        let s = Scene::new(
            vec![square("box", DVec2::new(0.0, 3.0), 1.0, Surface::Absorber)],
            vec![Parameter {
                name: "spin".into(),
                shape: "box".into(),
                motion: Motion::Rotate { pivot: None },
            }],
            irradiance(),
        )
        .unwrap();
        assert_eq!(
            s.parameters()[0].motion,
            Motion::Rotate {
                pivot: Some(DVec2::new(0.0, 3.0))
            }
        );
        // Outward normal of the bottom edge points down.
        assert!((s.normal(0) - DVec2::new(0.0, -1.0)).length() < 1e-15);
        let moved = s.displaced(0, std::f64::consts::FRAC_PI_2).unwrap();
        assert!((moved.segments()[0].a - DVec2::new(1.0, 2.0)).length() < 1e-12);
    }

    #[test]
    fn bad_scenes_are_rejected_with_a_reason() {
        let ok = || square("a", DVec2::new(0.0, 3.0), 1.0, Surface::Absorber);
        let err = |shapes: Vec<Shape>, params: Vec<Parameter>, sensor: Sensor| {
            Scene::new(shapes, params, sensor).unwrap_err().to_string()
        };
        let mut bow = ok();
        bow.vertices.swap(2, 3);
        bow.vertices[3] = DVec2::new(2.0, 5.0); // a bow tie with non-zero area
        let e = err(vec![bow], vec![], irradiance());
        assert!(e.contains("intersects itself"), "{e}");
        let mut b = ok();
        b.name = "b".into();
        assert!(err(vec![ok(), b], vec![], irradiance()).contains("touch or cross"));
        let mut fog = ok();
        fog.surface = Surface::Transparent;
        fog.medium = Some(Medium {
            ks: 2.0,
            ke: 1.0,
            phase: Phase::Isotropic,
        });
        assert!(err(vec![fog], vec![], irradiance()).contains("κe"));
        let p = Parameter {
            name: "x".into(),
            shape: "nope".into(),
            motion: Motion::TranslateX,
        };
        assert!(err(vec![ok()], vec![p], irradiance()).contains("does not exist"));
        let inside = Sensor::Irradiance {
            point: DVec2::new(0.0, 3.0),
            normal: DVec2::Y,
        };
        assert!(err(vec![ok()], vec![], inside).contains("inside"));
        let on = Sensor::Irradiance {
            point: DVec2::new(0.0, 2.0),
            normal: DVec2::Y,
        };
        assert!(err(vec![ok()], vec![], on).contains("lies on"));
        let mut deg = ok();
        deg.vertices[1] = deg.vertices[0];
        assert!(err(vec![deg], vec![], irradiance()).contains("zero length"));
        let mut neg = ok();
        neg.surface = Surface::Reflector { albedo: 1.5 };
        assert!(err(vec![neg], vec![], irradiance()).contains("albedo"));
    }
}
