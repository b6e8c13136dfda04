//! Validating and building a [`Scene`]: [`Scene::new`] as a sequence of named
//! steps, each checking one thing a user can get wrong (with a message naming
//! the shape, parameter or sensor at fault) or building one of the scene's
//! tables. The checks run in a fixed order (shapes, segments, crossings,
//! parameters, sensor, media), so a scene with several faults always reports
//! the first of them.
use super::{
    BVH_THRESHOLD, CORNER_TREE_THRESHOLD, GRADIENT_AXES, Medium, Motion, Parameter, Scene, Sensor,
    Shape, Surface,
};
use crate::error::{Error, Num};
use crate::flat::corners::CornerTree;
use crate::flat::geometry::{
    LinearScan, NO_SEGMENT, RayCast, Segment, contains, cross, signed_area,
};
use crate::scene::camera::view_problem;
use crate::scene::config;
use crate::scene::limits::{check_extent, check_pivot};
use crate::scene::material::{Coefficients, check_material, check_thickness};
use crate::scene::parameter;
use glam::DVec2;

impl Scene {
    /// Validates and builds a scene. Errors name the shape or parameter at
    /// fault: non-finite or too few vertices, zero-length or crossing
    /// segments (within a shape or between shapes), coefficients out of
    /// range (κs < 0, κe < κs, |g| ≥ 1, albedo ∉ `[0, 1]`, radiance < 0), a
    /// medium on an open or opaque shape, a transparent shape without a
    /// medium, parameters naming no shape, duplicate names, a sensor on a
    /// segment or inside an opaque closed shape other than an emitter.
    pub fn new(
        shapes: Vec<Shape>,
        parameters: Vec<Parameter>,
        sensor: Sensor,
    ) -> Result<Scene, Error> {
        let size = check_shapes(&shapes)?;
        let Outline {
            segments,
            owner,
            normal,
        } = outline(&shapes, size)?;
        check_crossings(&shapes, &segments, &owner)?;
        let (parameters, parameter_shape) = resolve_parameters(&shapes, &parameters, size)?;
        let sensor = check_sensor(sensor, &shapes, &segments, &owner, size)?;
        check_optical_thickness(&shapes, size)?;
        let (parent, sensor_medium) = nest_media(&shapes, sensor.point());
        let opaque = Opaque::new(&shapes, &segments, &owner);
        let corners = corners(&shapes);
        let corner_tree = (corners.len() > CORNER_TREE_THRESHOLD)
            .then(|| CornerTree::new(&corners.iter().map(|c| c.0).collect::<Vec<_>>()));
        let (emitters, emitter_length) = emitters(&shapes, &segments, &owner);
        Ok(Scene {
            emitters,
            emitter_length,
            caster: caster(segments.clone()),
            opaque: caster(opaque.segments.clone()),
            opaque_index: opaque.index,
            opaque_segments: opaque.segments,
            opaque_owner: opaque.owner,
            corner_tree,
            corners,
            shapes,
            parameters,
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
    // Scaled first, so that no length overflows (a normal [1e308, 1e308]
    // has a direction).
    let m = v.abs().max_element();
    let u = if m > 0.0 { v / m } else { v };
    let n = u.length();
    if n > 0.0 && n.is_finite() {
        Ok(u / n)
    } else {
        config(format!(
            "{what} = [{}, {}] has no direction",
            Num(v.x),
            Num(v.y)
        ))
    }
}

/// Checks every shape on its own ([`check_shape`]) and returns the scene's
/// size: the largest extent of the vertices' bounding box
/// ([`check_extent`]).
fn check_shapes(shapes: &[Shape]) -> Result<f64, Error> {
    if shapes.is_empty() {
        return config("a scene needs at least one shape".into());
    }
    // Names seen so far: a set, so 10⁵ shapes load in linear time.
    let mut names = std::collections::HashSet::with_capacity(shapes.len());
    for (k, s) in shapes.iter().enumerate() {
        let repeated = !names.insert(s.name.as_str());
        check_shape(k, s, repeated)?;
    }
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for &v in shapes.iter().flat_map(|s| &s.vertices) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    check_extent(
        (hi - lo).max_element(),
        lo.abs().max(hi.abs()).max_element(),
    )
}

/// Checks shape `k`: its name (`repeated`: an earlier shape has it), its
/// vertices, its surface and its medium.
fn check_shape(k: usize, s: &Shape, repeated: bool) -> Result<(), Error> {
    let name = &s.name;
    if name.is_empty() {
        return config(format!("shape {k} has an empty name"));
    }
    if repeated {
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
    }
    check_material(name, &s.surface, s.medium.map(coefficients), s.closed)
}

/// A medium's coefficients for the shared checks.
fn coefficients(m: Medium) -> Coefficients {
    Coefficients {
        ks: m.ks,
        ke: m.ke,
        g: m.phase.g(),
    }
}

/// Every segment of the scene, in shape order.
struct Outline {
    segments: Vec<Segment>,
    /// Shape of each segment.
    owner: Vec<u32>,
    /// Unit normal of each segment, outward for closed shapes.
    normal: Vec<DVec2>,
}

/// The scene's segments with their shapes and normals; rejects polygons
/// enclosing no area and segments of zero length (relative to `size`).
fn outline(shapes: &[Shape], size: f64) -> Result<Outline, Error> {
    let mut segments = Vec::new();
    let mut owner = Vec::new();
    let mut normal = Vec::new();
    for (k, s) in shapes.iter().enumerate() {
        let ccw = s.closed && signed_area(&s.vertices) > 0.0;
        if s.closed
            && signed_area(&s.vertices).abs() <= crate::path::tolerance::DEGENERATE * size * size
        {
            return config(format!("shape {:?} encloses no area", s.name));
        }
        for (i, seg) in s.segments().enumerate() {
            if seg.length() <= crate::path::tolerance::DEGENERATE * size {
                return config(format!("shape {:?}: segment {i} has zero length", s.name));
            }
            let left = seg.left_normal();
            // The left of a counter-clockwise polygon is its inside.
            normal.push(if ccw { -left } else { left });
            segments.push(seg);
            owner.push(k as u32);
        }
    }
    Ok(Outline {
        segments,
        owner,
        normal,
    })
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

/// The parameters with their pivots resolved (a shape's centroid where none
/// is given), and the index of the shape each moves; rejects what
/// [`crate::scene::parameter::resolve_parameters`] does and non-finite
/// pivots.
fn resolve_parameters(
    shapes: &[Shape],
    parameters: &[Parameter],
    size: f64,
) -> Result<(Vec<Parameter>, Vec<u32>), Error> {
    let names: Vec<&str> = shapes.iter().map(|s| s.name.as_str()).collect();
    parameter::resolve_parameters(&names, parameters, &GRADIENT_AXES, |p, k| {
        let pivot = |pivot: Option<DVec2>| -> Result<Option<DVec2>, Error> {
            let c = pivot.unwrap_or_else(|| shapes[k].centroid());
            finite(&format!("parameter {:?} pivot", p.name), c)?;
            let distance = (c - shapes[k].centroid()).abs().max_element();
            check_pivot(&p.name, distance, size)?;
            Ok(Some(c))
        };
        Ok(match p.motion {
            Motion::Rotate { pivot: c } => Motion::Rotate { pivot: pivot(c)? },
            Motion::Scale { pivot: c } => Motion::Scale { pivot: pivot(c)? },
            m => m,
        })
    })
}

/// The sensor with its direction or normal normalised; rejects a sensor
/// that is not finite, lies on a segment or inside an opaque closed shape
/// other than an emitter (directly: not in a box inside the emitter).
fn check_sensor(
    sensor: Sensor,
    shapes: &[Shape],
    segments: &[Segment],
    owner: &[u32],
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
        Sensor::Camera {
            position,
            direction,
            fov_deg,
            width,
        } => {
            finite("camera position", position)?;
            let view = [("width", width)];
            if let Some(why) = view_problem(fov_deg, "a field of view", &view) {
                return config(why);
            }
            Sensor::Camera {
                position,
                direction: unit("camera direction", direction)?,
                fov_deg,
                width,
            }
        }
    };
    let p = sensor.point();
    for (i, seg) in segments.iter().enumerate() {
        if seg.distance(p) <= crate::path::tolerance::ON_SURFACE * size {
            return config(format!(
                "the sensor at [{}, {}] lies on shape {:?}",
                Num(p.x),
                Num(p.y),
                shapes[owner[i] as usize].name
            ));
        }
    }
    // The closed opaque polygon nearest around the sensor (shapes do not
    // cross, so those around it nest: the least in area): an emitter is a
    // furnace, its inner faces emitting as the outer ones (two-sided); any
    // other is taken for a solid, which no path enters.
    let area = |s: &Shape| signed_area(&s.vertices).abs();
    let around = shapes
        .iter()
        .filter(|s| s.closed && s.surface.is_opaque() && contains(&s.vertices, p))
        .min_by(|a, b| area(a).total_cmp(&area(b)));
    if let Some(s) = around
        && !matches!(s.surface, Surface::Emitter { radiance } if radiance > 0.0)
    {
        return config(format!(
            "the sensor at [{}, {}] is inside the opaque shape {:?}",
            Num(p.x),
            Num(p.y),
            s.name
        ));
    }
    Ok(sensor)
}

/// Rejects a medium thicker than [`MAX_OPTICAL_THICKNESS`] across the scene.
fn check_optical_thickness(shapes: &[Shape], size: f64) -> Result<(), Error> {
    for s in shapes {
        if let Some(m) = s.medium {
            check_thickness(&s.name, coefficients(m), size)?;
        }
    }
    Ok(())
}

/// The medium shape around each shape (tested at its first vertex: shapes
/// do not cross), and the one around the sensor at `p`.
fn nest_media(shapes: &[Shape], p: DVec2) -> (Vec<Option<u32>>, Option<u32>) {
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
    // Only the media are candidates: every shape asks, so a scan of all
    // shapes per shape was quadratic (10⁵ shapes: 40 s).
    let media: Vec<usize> = (0..shapes.len())
        .filter(|&k| shapes[k].medium.is_some())
        .collect();
    let medium_at = |q: DVec2, except: Option<usize>| -> Option<u32> {
        media
            .iter()
            .copied()
            .filter(|&k| Some(k) != except && contains(&shapes[k].vertices, q))
            .min_by(|&a, &b| area[a].total_cmp(&area[b]))
            .map(|k| k as u32)
    };
    let parent = shapes
        .iter()
        .enumerate()
        .map(|(k, s)| medium_at(s.vertices[0], Some(k)))
        .collect();
    (parent, medium_at(p, None))
}

/// The opaque segments (those visibility tests see), by opaque index.
struct Opaque {
    segments: Vec<Segment>,
    /// Shape of each opaque segment.
    owner: Vec<u32>,
    /// Opaque index of each of the scene's segments ([`NO_SEGMENT`] for
    /// transparent ones).
    index: Vec<u32>,
}

impl Opaque {
    fn new(shapes: &[Shape], segments: &[Segment], owner: &[u32]) -> Opaque {
        let mut opaque = Opaque {
            segments: Vec::new(),
            owner: Vec::new(),
            index: Vec::with_capacity(segments.len()),
        };
        for (i, seg) in segments.iter().enumerate() {
            if shapes[owner[i] as usize].surface.is_opaque() {
                opaque.index.push(opaque.segments.len() as u32);
                opaque.segments.push(*seg);
                opaque.owner.push(owner[i]);
            } else {
                opaque.index.push(NO_SEGMENT);
            }
        }
        opaque
    }
}

/// Vertices of opaque shapes with their shape.
fn corners(shapes: &[Shape]) -> Vec<(DVec2, u32)> {
    shapes
        .iter()
        .enumerate()
        .filter(|(_, s)| s.surface.is_opaque())
        .flat_map(|(k, s)| s.vertices.iter().map(move |&v| (v, k as u32)))
        .collect()
}

/// Segments of emitters of positive radiance with their cumulative length,
/// and the total length.
fn emitters(shapes: &[Shape], segments: &[Segment], owner: &[u32]) -> (Vec<(u32, f64)>, f64) {
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
    (emitters, emitter_length)
}

/// The ray caster for a list of segments: a linear scan for a few, a BVH
/// beyond.
fn caster(segments: Vec<Segment>) -> Box<dyn RayCast> {
    // Measured crossover (`cargo bench --bench raycast`): the BVH's fixed
    // ~100 ns per ray pays off from 16–32 segments.
    if segments.len() <= BVH_THRESHOLD {
        Box::new(LinearScan::new(segments))
    } else {
        Box::new(crate::flat::bvh::SegmentBvh::new(segments))
    }
}
