//! Validating and building a [`Scene`]: [`Scene::new`] as a sequence of
//! named steps, each checking one thing a user can get wrong (with a message
//! naming the shape, its vertex or triangle, the parameter or the sensor at
//! fault) or building one of the scene's tables. The steps run in a fixed
//! order, so a scene with several faults always reports the first:
//!
//! 1. each shape as given: name, triangle indices, finite coordinates,
//!    surface and medium numbers ([`check_shape`]);
//! 2. welding by exact position, dropping unused vertices ([`weld`]);
//! 3. the scene's size ([`MIN_SIZE`](super::MIN_SIZE)..[`MAX_SIZE`](super::MAX_SIZE)) and
//!    its distance from the origin ([`MAX_OFFSET`](super::MAX_OFFSET));
//! 4. each mesh's triangles and edges: degenerate triangles, non-manifold
//!    edges, orientation, closedness ([`topology`]);
//! 5. meshes that cross or touch (`crossings`);
//! 6. closed meshes turned outward ([`orient`]);
//! 7. parameters, sensor, optical thickness, media nesting.
//!
//! Indices and coordinates are checked before welding (welding needs
//! indices in range, and the messages then name the user's indices);
//! welding keeps the triangles' order, so triangle indices in later
//! messages are the user's too. Vertex indices in later messages are those
//! of the welded mesh.
use super::crossings::{Aabb, check_crossings, check_self_crossings};
use super::geometry::{bounds, point_triangle_distance, signed_volume, winding_number};
use super::{Medium, Motion, Parameter, Scene, Sensor, Shape, Surface};
use crate::error::{Error, Num};
use crate::mesh::part::part_cell;
use crate::scene::config;
use crate::scene::limits::{check_extent, check_pivot};
use crate::scene::material::{Coefficients, check_material, check_thickness};
use crate::scene::parameter;
use glam::DVec3;
use std::collections::{HashMap, HashSet};

/// A triangle whose area is at most `DEGENERATE_AREA × d²`, with `d` the
/// diagonal of its mesh's bounding box, is degenerate (a sliver the tracer
/// could not give a normal to). The same factor times `d³` is the least
/// volume a closed mesh must enclose.
pub const DEGENERATE_AREA: f64 = crate::path::tolerance::DEGENERATE;

/// A sensor closer than `SENSOR_DISTANCE × size` to a triangle lies on it
/// (flatland's rule).
const SENSOR_DISTANCE: f64 = crate::path::tolerance::ON_SURFACE;

fn show(p: DVec3) -> String {
    format!("[{}, {}, {}]", Num(p.x), Num(p.y), Num(p.z))
}

fn finite(what: &str, p: DVec3) -> Result<(), Error> {
    if p.is_finite() {
        Ok(())
    } else {
        config(format!("{what} = {} is not finite", show(p)))
    }
}

fn unit(what: &str, v: DVec3) -> Result<DVec3, Error> {
    finite(what, v)?;
    // Scaled first, so that no length overflows.
    let m = v.abs().max_element();
    let u = if m > 0.0 { v / m } else { v };
    let n = u.length();
    if n > 0.0 && n.is_finite() {
        Ok(u / n)
    } else {
        config(format!("{what} = {} has no direction", show(v)))
    }
}

impl Scene {
    /// Validates and builds a scene (steps in the module docs). Each mesh is
    /// welded by exact position (`−0.0 == 0.0`), unused vertices dropped,
    /// and a closed mesh whose signed volume is negative has every triangle
    /// flipped, so that normals `(b−a)×(c−a)` point out. Pivots default to
    /// the welded mesh's vertex centroid; axes, normals and directions are
    /// normalised.
    ///
    /// Errors ([`Error::Scene`]) name the shape, vertex, triangle, parameter
    /// or sensor at fault: no shapes, empty or repeated names, a mesh
    /// without triangles, indices out of range, non-finite coordinates,
    /// degenerate triangles ([`DEGENERATE_AREA`]), edges shared by more than
    /// two triangles, a watertight mesh whose triangles are not consistently
    /// oriented (refused, not repaired: a mesh's winding is the user's
    /// statement of its faces), a closed mesh enclosing no volume, a medium
    /// on an open or opaque mesh, a transparent mesh without a medium,
    /// coefficients out of range (κs < 0, κe < κs, |g| ≥ 1, radiance < 0,
    /// albedo ∉ `[0, 1]`), a medium too thick ([`MAX_OPTICAL_THICKNESS`](super::MAX_OPTICAL_THICKNESS)), a
    /// size outside [`MIN_SIZE`](super::MIN_SIZE)..[`MAX_SIZE`](super::MAX_SIZE) or
    /// too far from the origin ([`MAX_OFFSET`](super::MAX_OFFSET)), two meshes that cross or
    /// touch ([`TOUCH_DISTANCE`](super::TOUCH_DISTANCE)), a mesh that crosses, touches
    /// or folds onto itself (a T-junction, an unwelded seam),
    /// bad parameters (too many, empty or
    /// repeated names, unknown shapes, zero or non-finite axes and pivots),
    /// a non-finite sensor, a sensor on a surface or inside an opaque closed
    /// mesh that is no emitter and holds none.
    pub fn new(
        mut shapes: Vec<Shape>,
        parameters: Vec<Parameter>,
        sensor: Sensor,
    ) -> Result<Scene, Error> {
        if shapes.is_empty() {
            return config("a scene needs at least one shape".into());
        }
        let mut names = HashSet::with_capacity(shapes.len());
        for (k, s) in shapes.iter().enumerate() {
            let repeated = !names.insert(s.name.as_str());
            check_shape(k, s, repeated)?;
        }
        for s in &mut shapes {
            weld(s);
        }
        let size = scene_size(&shapes)?;
        let closed = shapes
            .iter()
            .map(topology)
            .collect::<Result<Vec<bool>, Error>>()?;
        for (s, &c) in shapes.iter().zip(&closed) {
            if s.medium.is_some() && !c {
                return config(format!(
                    "shape {:?} has a medium but is not closed (every edge must be shared \
                     by exactly two triangles, in opposite directions)",
                    s.name
                ));
            }
        }
        check_crossings(&shapes, size, None)?;
        // After `orient`, whose "encloses no volume" names a closed mesh
        // flattened onto itself more plainly than the fold it also is.
        let volume = orient(&mut shapes, &closed, None)?;
        check_self_crossings(&shapes, size, None)?;
        let parts = shapes.iter().map(|_| part_cell()).collect();
        let meshes = Meshes {
            shapes,
            closed,
            volume,
            parts,
            size,
        };
        meshes.scene(&parameters, sensor)
    }

    /// This scene's meshes posed anew: `shapes` are its own, some moved
    /// rigidly or scaled (the same triangles over moved vertices), with
    /// `parameters` resolved against them. Validated as [`Scene::new`]
    /// validates, but only where something moved: a moved mesh's own
    /// checks, and the pairs of meshes that hold a moved one (all pairs if
    /// the scene grew, since the touching distance grows with it). An
    /// unmoved mesh keeps its tables ([`MeshPart`](crate::mesh::part)): its
    /// caster and edges are not built again. Anything else (other meshes,
    /// other triangles) is built as [`Scene::new`] builds it.
    pub(crate) fn moved(
        &self,
        mut shapes: Vec<Shape>,
        parameters: Vec<Parameter>,
    ) -> Result<Scene, Error> {
        let rigid = shapes.len() == self.shapes.len()
            && shapes.iter().zip(&self.shapes).all(|(a, b)| {
                a.name == b.name
                    && a.triangles == b.triangles
                    && a.vertices.len() == b.vertices.len()
                    && a.surface == b.surface
                    && a.medium == b.medium
            });
        if !rigid {
            return Scene::new(shapes, parameters, self.sensor);
        }
        let moved: Vec<bool> = shapes
            .iter()
            .zip(&self.shapes)
            .map(|(a, b)| a.vertices != b.vertices)
            .collect();
        for (k, s) in shapes.iter().enumerate() {
            if moved[k] {
                check_shape(k, s, false)?;
                topology(s)?;
            }
        }
        let size = scene_size(&shapes)?;
        let only = (size <= self.size).then_some(&moved[..]);
        check_crossings(&shapes, size, only)?;
        let volume = orient(&mut shapes, &self.closed, Some((&moved, &self.volume)))?;
        check_self_crossings(&shapes, size, only)?;
        let parts = (0..shapes.len())
            .map(|k| {
                if moved[k] {
                    part_cell()
                } else {
                    self.parts[k].clone()
                }
            })
            .collect();
        let meshes = Meshes {
            shapes,
            closed: self.closed.clone(),
            volume,
            parts,
            size,
        };
        meshes.scene(&parameters, self.sensor)
    }

    /// The same meshes and parameters seen by `sensor`, validated as
    /// [`Scene::new`] validates a sensor; the meshes keep their tables.
    pub fn with_sensor(&self, sensor: Sensor) -> Result<Scene, Error> {
        self.clone().seen_from(sensor)
    }

    /// This scene with `sensor` checked and in place, and what depends on
    /// it: which closed meshes are solids, the media around the meshes and
    /// the sensor. Also rejects media too thick.
    fn seen_from(mut self, sensor: Sensor) -> Result<Scene, Error> {
        let sensor = check_sensor(sensor, &self.shapes, &self.closed, self.size)?;
        check_optical_thickness(&self.shapes, self.size)?;
        let (parent, sensor_medium) =
            nest_media(&self.shapes, &self.closed, &self.volume, sensor.point());
        self.solid = self
            .shapes
            .iter()
            .zip(&self.closed)
            .map(|(s, &c)| c && s.surface.is_opaque() && !inside(s, sensor.point()))
            .collect();
        self.sensor = sensor;
        self.parent = parent;
        self.sensor_medium = sensor_medium;
        Ok(self)
    }
}

/// Validated meshes with what was learnt of them: closedness, enclosed
/// volumes, their tables, the scene's size.
struct Meshes {
    shapes: Vec<Shape>,
    closed: Vec<bool>,
    volume: Vec<f64>,
    parts: Vec<crate::mesh::part::PartCell>,
    size: f64,
}

impl Meshes {
    /// The scene of these meshes with `parameters` resolved against them,
    /// seen by `sensor`.
    fn scene(self, parameters: &[Parameter], sensor: Sensor) -> Result<Scene, Error> {
        let (parameters, parameter_shape) =
            resolve_parameters(&self.shapes, parameters, self.size)?;
        Scene {
            shapes: self.shapes,
            parameters,
            parameter_shape,
            sensor,
            closed: self.closed,
            volume: self.volume,
            parts: self.parts,
            tables: Default::default(),
            solid: Vec::new(),
            parent: Vec::new(),
            sensor_medium: None,
            size: self.size,
        }
        .seen_from(sensor)
    }
}

/// Checks shape `k` as given: its name (`repeated`: an earlier shape has
/// it), its triangles' indices, its coordinates, its surface and medium.
fn check_shape(k: usize, s: &Shape, repeated: bool) -> Result<(), Error> {
    let name = &s.name;
    if name.is_empty() {
        return config(format!("shape {k} has an empty name"));
    }
    if repeated {
        return config(format!("two shapes are named {name:?}"));
    }
    if s.triangles.is_empty() {
        return config(format!("shape {name:?} has no triangles"));
    }
    let n = s.vertices.len();
    for (i, t) in s.triangles.iter().enumerate() {
        if let Some(&v) = t.iter().find(|&&v| v as usize >= n) {
            return config(format!(
                "shape {name:?}: triangle {i} uses vertex {v}, but the mesh has {n} vertices \
                 (indices start at 0)"
            ));
        }
    }
    for (i, &v) in s.vertices.iter().enumerate() {
        finite(&format!("shape {name:?} vertex {i}"), v)?;
    }
    // Closedness is the topology's to check, after welding.
    check_material(name, &s.surface, s.medium.map(coefficients), true)
}

/// A medium's coefficients for the shared checks.
fn coefficients(m: Medium) -> Coefficients {
    Coefficients {
        ks: m.ks,
        ke: m.ke,
        g: m.g,
    }
}

/// Merges the vertices at the same position (`−0.0` and `0.0` alike),
/// remaps the triangles and drops the vertices no triangle uses; vertices
/// are numbered in order of first use. Indices must be in range.
pub(super) fn weld(shape: &mut Shape) {
    let mut index: HashMap<[u64; 3], u32> = HashMap::with_capacity(shape.vertices.len());
    let mut vertices = Vec::with_capacity(shape.vertices.len());
    let mut map = vec![u32::MAX; shape.vertices.len()];
    for t in &mut shape.triangles {
        for i in t.iter_mut() {
            let old = *i as usize;
            if map[old] == u32::MAX {
                let v = shape.vertices[old];
                let key = [v.x, v.y, v.z].map(|c| (c + 0.0).to_bits());
                map[old] = *index.entry(key).or_insert_with(|| {
                    vertices.push(v);
                    (vertices.len() - 1) as u32
                });
            }
            *i = map[old];
        }
    }
    shape.vertices = vertices;
}

/// The largest extent of the vertices' bounding box, within
/// [`MIN_SIZE`](super::MIN_SIZE)..[`MAX_SIZE`](super::MAX_SIZE), no farther
/// from the origin than [`MAX_OFFSET`](super::MAX_OFFSET) times it.
fn scene_size(shapes: &[Shape]) -> Result<f64, Error> {
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for s in shapes {
        let (l, h) = bounds(&s.vertices);
        (lo, hi) = (lo.min(l), hi.max(h));
    }
    check_extent(
        (hi - lo).max_element(),
        lo.abs().max(hi.abs()).max_element(),
    )
}

/// The triangles using one edge (at most two: a third is an error).
#[derive(Clone, Copy)]
struct EdgeUse {
    count: u8,
    /// Triangle and whether it runs from the lower vertex index to the
    /// higher, for the first two users.
    by: [(u32, bool); 2],
}

/// Checks a welded mesh's triangles and edges and tells whether it is
/// closed: rejects degenerate triangles, edges shared by more than two
/// triangles and, on a watertight mesh (every edge shared by two
/// triangles), an edge both triangles run along in the same direction.
fn topology(s: &Shape) -> Result<bool, Error> {
    let name = &s.name;
    let (lo, hi) = bounds(&s.vertices);
    let diagonal2 = (hi - lo).length_squared();
    for (i, t) in s.triangles.iter().enumerate() {
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            return config(format!(
                "shape {name:?}: triangle {i} is degenerate: two of its corners are the same \
                 point"
            ));
        }
        let [a, b, c] = s.triangle(i);
        if (b - a).cross(c - a).length() / 2.0 <= DEGENERATE_AREA * diagonal2 {
            return config(format!(
                "shape {name:?}: triangle {i} is degenerate: its area is at most \
                 {DEGENERATE_AREA:e} × (its mesh's diagonal)²"
            ));
        }
    }
    let mut edges: HashMap<(u32, u32), EdgeUse> = HashMap::with_capacity(3 * s.triangles.len());
    for (i, t) in s.triangles.iter().enumerate() {
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            let use_ = (i as u32, a < b);
            let entry = edges.entry((a.min(b), a.max(b))).or_insert(EdgeUse {
                count: 0,
                by: [use_; 2],
            });
            if entry.count >= 2 {
                return config(format!(
                    "shape {name:?}: the edge between vertices {} and {} is shared by \
                     triangles {}, {} and {}: a mesh must be a manifold (at most two \
                     triangles per edge)",
                    a.min(b),
                    a.max(b),
                    entry.by[0].0,
                    entry.by[1].0,
                    i
                ));
            }
            entry.by[entry.count as usize] = use_;
            entry.count += 1;
        }
    }
    if edges.values().any(|e| e.count != 2) {
        return Ok(false);
    }
    // Watertight: report the first edge (by triangle) both neighbours run
    // along in the same direction.
    let mut bad: Option<(u32, u32, (u32, u32))> = None;
    for (&edge, e) in &edges {
        if e.by[0].1 == e.by[1].1 {
            let pair = (e.by[0].0.min(e.by[1].0), e.by[0].0.max(e.by[1].0));
            if bad.is_none_or(|b| (pair, edge) < ((b.0, b.1), b.2)) {
                bad = Some((pair.0, pair.1, edge));
            }
        }
    }
    if let Some((i, j, (a, b))) = bad {
        return config(format!(
            "shape {name:?}: triangles {i} and {j} both run from vertex {a} to vertex {b}: \
             a closed mesh must be oriented consistently (each edge traversed once in \
             each direction)"
        ));
    }
    Ok(true)
}

/// Turns each closed mesh outward (flips every triangle if its signed
/// volume is negative) and returns each mesh's enclosed volume (0 for open
/// meshes); rejects a closed mesh enclosing no volume.
/// With `prior` (which meshes moved, and every mesh's volume before), an
/// unmoved mesh keeps its volume and is known to face out.
fn orient(
    shapes: &mut [Shape],
    closed: &[bool],
    prior: Option<(&[bool], &[f64])>,
) -> Result<Vec<f64>, Error> {
    let mut volume = vec![0.0; shapes.len()];
    for (k, s) in shapes.iter_mut().enumerate() {
        if !closed[k] {
            continue;
        }
        if let Some((moved, before)) = prior
            && !moved[k]
        {
            volume[k] = before[k];
            continue;
        }
        let (lo, hi) = bounds(&s.vertices);
        let origin = (lo + hi) / 2.0;
        let v = signed_volume((0..s.triangles.len()).map(|i| s.triangle(i)), origin);
        if v.abs() <= DEGENERATE_AREA * (hi - lo).length().powi(3) {
            return config(format!(
                "shape {:?} is closed but encloses no volume",
                s.name
            ));
        }
        if v < 0.0 {
            for t in &mut s.triangles {
                t.swap(1, 2);
            }
        }
        volume[k] = v.abs();
    }
    Ok(volume)
}

/// The parameters with their pivots resolved (a mesh's vertex centroid
/// where none is given) and axes normalised, and the index of the shape
/// each moves; rejects what [`crate::scene::parameter::resolve_parameters`]
/// does, non-finite pivots, zero or non-finite axes.
fn resolve_parameters(
    shapes: &[Shape],
    parameters: &[Parameter],
    size: f64,
) -> Result<(Vec<Parameter>, Vec<u32>), Error> {
    let names: Vec<&str> = shapes.iter().map(|s| s.name.as_str()).collect();
    parameter::resolve_parameters(&names, parameters, &super::GRADIENT_AXES, |p, k| {
        let pivot = |pivot: Option<DVec3>| -> Result<Option<DVec3>, Error> {
            let c = pivot.unwrap_or_else(|| shapes[k].centroid());
            finite(&format!("parameter {:?} pivot", p.name), c)?;
            let distance = (c - shapes[k].centroid()).abs().max_element();
            check_pivot(&p.name, distance, size)?;
            Ok(Some(c))
        };
        Ok(match p.motion {
            Motion::Rotate { axis, pivot: c } => Motion::Rotate {
                axis: unit(&format!("parameter {:?} axis", p.name), axis)?,
                pivot: pivot(c)?,
            },
            Motion::Scale { pivot: c } => Motion::Scale { pivot: pivot(c)? },
            m => m,
        })
    })
}

/// Whether `p` is inside the closed (outward-oriented) mesh `s`: its
/// generalized winding number is nearer 1 than 0.
pub(super) fn inside(s: &Shape, p: DVec3) -> bool {
    let b = Aabb::of(&s.vertices);
    b.meets(&Aabb { lo: p, hi: p }, 0.0)
        && winding_number((0..s.triangles.len()).map(|i| s.triangle(i)), p).abs() > 0.5
}

/// The sensor with its direction or normal normalised; rejects a sensor
/// that is not finite, lies on a triangle (closer than `SENSOR_DISTANCE` ×
/// `size`) or inside an opaque closed mesh that holds no emitter and is
/// none (inside one that does is a room).
fn check_sensor(
    sensor: Sensor,
    shapes: &[Shape],
    closed: &[bool],
    size: f64,
) -> Result<Sensor, Error> {
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
        Sensor::Camera(c) => {
            if let Some(why) = c.problem() {
                return config(why);
            }
            Sensor::Camera(c)
        }
    };
    let p = sensor.point();
    for s in shapes {
        for i in 0..s.triangles.len() {
            if point_triangle_distance(p, s.triangle(i)) <= SENSOR_DISTANCE * size {
                return config(format!(
                    "the sensor at {} lies on shape {:?} (triangle {i})",
                    show(p),
                    s.name
                ));
            }
        }
    }
    // Inside a closed opaque mesh is a room (two-sided surfaces: its inner
    // walls are as good as its outer ones), unless no emitter is inside
    // with the sensor: then it sees nothing, a mistake. A closed emitter
    // lights its own inside.
    let glows = |e: &Shape| matches!(e.surface, Surface::Emitter { radiance } if radiance > 0.0);
    for (k, s) in shapes.iter().enumerate() {
        if closed[k] && s.surface.is_opaque() && inside(s, p) {
            let lit = glows(s)
                || shapes.iter().enumerate().any(|(l, e)| {
                    l != k && glows(e) && e.vertices.first().is_some_and(|&v| inside(s, v))
                });
            if !lit {
                return config(format!(
                    "the sensor at {} is inside the opaque shape {:?}, which holds no \
                     emitter: it would see nothing",
                    show(p),
                    s.name
                ));
            }
        }
    }
    Ok(sensor)
}

/// Rejects a medium thicker than [`MAX_OPTICAL_THICKNESS`] across the
/// scene, or one in which a path would scatter more than
/// [`MAX_SCATTERING_EVENTS`] times (flatland's rules).
fn check_optical_thickness(shapes: &[Shape], size: f64) -> Result<(), Error> {
    for s in shapes {
        if let Some(m) = s.medium {
            check_thickness(&s.name, coefficients(m), size)?;
        }
    }
    Ok(())
}

/// The medium mesh around each mesh (tested at its first vertex: meshes do
/// not cross, so one vertex tells) and around the sensor at `p`: among the
/// closed medium meshes containing the point, the one of least volume.
fn nest_media(
    shapes: &[Shape],
    closed: &[bool],
    volume: &[f64],
    p: DVec3,
) -> (Vec<Option<u32>>, Option<u32>) {
    // Only the closed media are candidates: every mesh asks, so a scan of
    // all meshes per mesh was quadratic.
    let media: Vec<usize> = (0..shapes.len())
        .filter(|&k| shapes[k].medium.is_some() && closed[k])
        .collect();
    let medium_at = |q: DVec3, except: Option<usize>| -> Option<u32> {
        media
            .iter()
            .copied()
            .filter(|&k| Some(k) != except && inside(&shapes[k], q))
            .min_by(|&a, &b| volume[a].total_cmp(&volume[b]))
            .map(|k| k as u32)
    };
    let parent = shapes
        .iter()
        .enumerate()
        .map(|(k, s)| medium_at(s.vertices[0], Some(k)))
        .collect();
    (parent, medium_at(p, None))
}
