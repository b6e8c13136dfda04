//! The 3D estimators behind the crate's [`Estimator`] interface, the same
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
use super::scene::{Motion, Scene};
use super::space::Space;
use crate::error::Error;
use crate::estimator::{Estimator, Quantity};
use crate::fd::{
    CentralDifference, DEFAULT_STEP, Pair, check_step, invalid_displacement, thin_medium_caveat,
};
use crate::method::{Method, Problem};
use crate::path::deform::Slots;
use crate::path::estimator::{DerivativeEstimator, Scheme};
use crate::path::intensity::IntensityEstimator;
use crate::path::nested::Budget;
use crate::path::thin_media::chord_bound;
use std::f64::consts::{PI, TAU};
use std::sync::Arc;

impl Problem for Arc<Scene> {
    /// For [`Method::Fd`] the half step is `fd_step` times the scene's size
    /// for a translation, `fd_step` radians for a rotation and `fd_step` for
    /// a scale.
    fn estimator(&self, method: Method, fd_step: Option<f64>) -> Result<Box<dyn Estimator>, Error> {
        let scene = Arc::clone(self);
        let scheme = match method {
            Method::Intensity => {
                return Ok(Box::new(IntensityEstimator {
                    geometry: Space::new(scene),
                }));
            }
            Method::Fd => {
                let step = fd_step.map_or(Ok(DEFAULT_STEP), check_step)?;
                return Ok(Box::new(finite_difference(&scene, step)?));
            }
            Method::Expectation => {
                check_peaked_phase(&scene)?;
                Scheme::Expectation
            }
            Method::Rendering => Scheme::Rendering,
            Method::Transport => Scheme::Transport,
        };
        Ok(Box::new(derivative(scene, scheme)))
    }
}

/// Refuses the expectation method on a medium whose Henyey–Greenstein
/// phase function is more peaked than flatland's limit
/// ([`crate::flat::methods::MAX_EXPECTATION_G`], the same check): the warp turns scattered
/// directions relative to the incoming one, so the score carries `∂ ln p`
/// along the warp, of order `1/(1 − |g|)`.
fn check_peaked_phase(scene: &Scene) -> Result<(), Error> {
    for s in scene.shapes() {
        if let Some(m) = s.medium {
            crate::flat::methods::check_expectation_g("mesh", &s.name, m.g)?;
        }
    }
    Ok(())
}

/// The derivative estimator of `scheme` on `scene`.
pub fn derivative(scene: Arc<Scene>, scheme: Scheme) -> DerivativeEstimator<Space> {
    // The sensor position's gradient at a probe; a camera's images are of
    // the parameters only.
    let camera = matches!(scene.sensor(), super::Sensor::Camera(_));
    let gradient = scheme == Scheme::Transport && !camera;
    let mut names: Vec<Quantity> = scene
        .parameters()
        .iter()
        .map(|p| Quantity::sensitivity(&p.name))
        .collect();
    if gradient {
        for (axis, _) in AXES {
            names.push(Quantity::gradient(axis));
        }
    }
    let shapes = scene.shapes().len();
    let caveats = kinks(&scene);
    // Transport's twins serve moving reflectors only (elsewhere they would
    // be slots carried for nothing).
    let twins = scheme == Scheme::Transport
        && (0..scene.parameters().len()).any(|j| {
            let k = scene.parameter_shape(j) as usize;
            matches!(scene.shapes()[k].surface, super::Surface::Reflector { .. })
        });
    let geometry = Space::new(scene);
    let mut caveats = caveats;
    if gradient {
        caveats.extend(plane_kinks_of_the_gradient(geometry.scene()));
    }
    // Ties also kink the sensor's gradient (its motion off their plane),
    // where transport estimates it.
    for (q, why) in edge_ties(&geometry) {
        let wanted = gradient || matches!(q, Quantity::Sensitivity(_));
        if wanted && !caveats.iter().any(|c: &(Quantity, String)| c.0 == q) {
            caveats.push((q, why));
        }
    }
    let slots = Slots::new(&geometry, shapes, gradient, twins);
    DerivativeEstimator {
        geometry,
        slots,
        scheme,
        names,
        caveats,
        budget: Budget::default(),
    }
}

/// How many ulps of a face's largest coordinate (or the sensor's) the
/// sensor may lie off the face's plane and still see it edge-on for
/// [`kinks`]: within 70 sizes of the origin 10⁻⁹ of the size is larger.
pub const EDGE_ON_ULPS: f64 = 4096.0;

/// Where `I` may not be differentiable: the sensor lies in the plane of a
/// face of a moved mesh (within 10⁻⁹ of the scene's size, or
/// [`EDGE_ON_ULPS`] of the coordinates far from the origin) and the motion
/// moves the face across that plane, so the face, seen edge-on, turns to
/// face the sensor from one side or the other (a kink: the two one-sided
/// derivatives differ, and the boundary terms see the face edge-on). One
/// caveat per parameter of such a mesh.
pub fn kinks(scene: &Scene) -> Vec<(Quantity, String)> {
    let x = scene.sensor().point();
    let mut out = Vec::new();
    for (j, p) in scene.parameters().iter().enumerate() {
        let shape = &scene.shapes()[scene.parameter_shape(j) as usize];
        let edge_on = (0..shape.triangles.len()).find(|&i| {
            let t = shape.triangle(i);
            edge_on_plane(scene, x, &t)
                .is_some_and(|(n, _, _)| t.iter().any(|&q| crosses(p.motion.velocity(q), n)))
        });
        if let Some(i) = edge_on {
            out.push((
                Quantity::sensitivity(&p.name),
                format!(
                    "the sensor lies in the plane of triangle {i} of mesh {:?}: the face is seen \
                     edge-on, I may have a kink along {:?} (the one-sided derivatives differ) \
                     and the estimate is neither of them",
                    shape.name, p.name
                ),
            ));
        }
    }
    out
}

/// The unit normal of face `t`, the sensor's signed distance `off` from
/// its plane and the tolerance, when `x` lies in that plane: within 10⁻⁹
/// of the scene's size, or [`EDGE_ON_ULPS`] of the largest coordinate of
/// the face and `x`. Far from the origin a face's plane is known only to
/// the rounding of its coordinates: a lamp tilted 9 ulps of 9·10⁵ off
/// edge-on (10⁻⁹ rad) read I 54σ and ∂I/∂tz 350σ off, "reliable"
/// (campaign; the bias went as 1/ulps, 3σ at 1 024).
fn edge_on_plane(
    scene: &Scene,
    x: glam::DVec3,
    t: &[glam::DVec3; 3],
) -> Option<(glam::DVec3, f64, f64)> {
    let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
    let reach = t
        .iter()
        .map(|q| q.abs().max_element())
        .fold(x.abs().max_element(), f64::max);
    let tolerance = (1e-9 * scene.size()).max(EDGE_ON_ULPS * f64::EPSILON * reach);
    let off = n.dot(x - t[0]);
    (n != glam::DVec3::ZERO && off.abs() <= tolerance).then_some((n, off, tolerance))
}

/// Whether a motion at velocity `v` leaves the plane of unit normal `n`.
fn crosses(v: glam::DVec3, n: glam::DVec3) -> bool {
    v.dot(n).abs() > 1e-9 * v.length()
}

/// The sensor's axes, as transport's gradient names them.
pub(crate) const AXES: [(&str, glam::DVec3); 3] = [
    ("x", glam::DVec3::X),
    ("y", glam::DVec3::Y),
    ("z", glam::DVec3::Z),
];

/// Where the sensor's gradient may not exist: the sensor lies in the plane
/// of a face (within [`kinks`]'s tolerance) but off the face itself, so
/// moving it across that plane turns the face, seen edge-on, to face it
/// from one side or the other (a lamp seen edge-on: transport's `∇z` read
/// 0.400 at the origin and 0.417 at 9·10⁵, "reliable", in a campaign). A
/// sensor on the face itself is not this (there the gradient along the
/// normal would be the one-sided derivative from the side it faces; the
/// scene checks refuse a sensor on an opaque face). One caveat per axis
/// that crosses such a plane.
pub fn plane_kinks_of_the_gradient(scene: &Scene) -> Vec<(Quantity, String)> {
    let x = scene.sensor().point();
    let mut out = Vec::new();
    for (axis, e) in AXES {
        let hit = scene.shapes().iter().find_map(|shape| {
            (0..shape.triangles.len()).find_map(|i| {
                let t = shape.triangle(i);
                let (n, off, tolerance) =
                    edge_on_plane(scene, x, &t).filter(|&(n, _, _)| crosses(e, n))?;
                // Barycentric signs of the sensor's projection.
                let p = x - n * off;
                let on_face = (0..3).all(|k| {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    (b - a).cross(p - a).dot(n) >= -tolerance * (b - a).length()
                });
                (!on_face).then_some((i, &shape.name))
            })
        });
        if let Some((i, name)) = hit {
            out.push((
                Quantity::gradient(axis),
                format!(
                    "the sensor lies in the plane of triangle {i} of mesh {name:?}, off the face: \
                     moving it along {axis} turns the face from edge-on, so I may have a kink \
                     there (the one-sided derivatives differ) and the estimate is neither of them"
                ),
            ));
        }
    }
    out
}

/// Central differences with common random numbers: `I` on the nominal
/// scene, then per parameter `j` the readings of the scene displaced by
/// `±h_j` (`h_j = step` × the scene's size for a translation, `step` for a
/// rotation or a scale). Errors if a displaced scene is invalid (meshes
/// crossing): the error names the parameter and the displacement. A step
/// that moves the mesh by half its distance to the sensor or more is
/// flagged as a caveat.
pub fn finite_difference(scene: &Arc<Scene>, step: f64) -> Result<CentralDifference, Error> {
    let step = crate::error::check("h", step, step > 0.0, "a finite number > 0")?;
    let mut caveats = Vec::new();
    let mut pairs = Vec::new();
    let outlines = super::fd_view::outlines(scene);
    for (j, p) in scene.parameters().iter().enumerate() {
        let (h, note) = match p.motion {
            Motion::TranslateX | Motion::TranslateY | Motion::TranslateZ => (
                step * scene.size(),
                format!(" (half step {step} × scene size {})", scene.size()),
            ),
            _ => (step, String::new()),
        };
        let displaced = |delta: f64| -> Result<Arc<Scene>, Error> {
            scene
                .displaced(j, delta)
                .map(Arc::new)
                .map_err(|e| invalid_displacement("scene", &p.name, delta, &note, e))
        };
        let (plus, minus) = (displaced(h)?, displaced(-h)?);
        if let Some(c) = passes_sensor(scene, j, h)
            .or_else(|| turns_face(scene, j, h, &plus, &minus))
            .or_else(|| outruns_lamp(scene, j, h))
            .or_else(|| super::fd_view::view_crossing(scene, j, h, &plus, &minus, &outlines))
            .or_else(|| thin_medium(scene, j))
        {
            caveats.push((p.name.clone(), c));
        }
        pairs.push(Pair {
            parameter: p.name.clone(),
            plus: Method::Intensity.estimator(plus)?,
            minus: Method::Intensity.estimator(minus)?,
            half_step: h,
        });
    }
    // The nominal scene's geometry serves the ties and then the nominal run.
    let nominal = Space::new(Arc::clone(scene));
    let ties = edge_ties(&nominal);
    for (q, why) in kinks(scene).into_iter().chain(ties) {
        if let Quantity::Sensitivity(name) = q
            && !caveats.iter().any(|c: &(String, String)| c.0 == name)
        {
            caveats.push((name, why));
        }
    }
    let nominal: Box<dyn Estimator> = Box::new(IntensityEstimator { geometry: nominal });
    let mut fd = CentralDifference::new(Some(nominal), pairs)?;
    for (parameter, why) in caveats {
        fd = fd.with_caveat(&parameter, why);
    }
    Ok(fd)
}

/// Why the central difference along parameter `j` (half step `h`) may not
/// estimate the derivative: as seen from the sensor, the half step turns a
/// vertex of the moved mesh by a quarter of an emitter's extent or more, so
/// one step may carry a shadow edge across most of the lamp (found by a
/// random-scene campaign: a lamp 10⁻³ wide, the default step, fd 125.000
/// ± 7·10⁻⁹ marked reliable against the exact 500: the quotient had
/// saturated at the lamp's whole light over the step).
fn outruns_lamp(scene: &Scene, j: usize, h: f64) -> Option<String> {
    let p = &scene.parameters()[j];
    let k = scene.parameter_shape(j) as usize;
    let x = scene.sensor().point();
    let turn = scene.shapes()[k]
        .vertices
        .iter()
        .map(|&q| (p.motion.apply(q, h) - q).length() / (q - x).length())
        .fold(0.0, f64::max);
    scene
        .shapes()
        .iter()
        .filter(|s| matches!(s.surface, crate::path::Surface::Emitter { .. }))
        .find_map(|lamp| {
            let (lo, hi) = super::scene::bounds(&lamp.vertices);
            let centre = 0.5 * (lo + hi);
            let extent = (hi - lo).length() / (centre - x).length();
            (turn >= 0.25 * extent).then(|| {
                format!(
                    "finite differences along {:?}: the half step turns mesh {:?} by {turn:.2e} \
                     rad as seen from the sensor, a quarter or more of emitter {:?} \
                     ({extent:.2e} rad across): a shadow edge may cross the lamp within the \
                     step; try a smaller --fd-step",
                    p.name,
                    scene.shapes()[k].name,
                    lamp.name,
                )
            })
        })
}

/// Why the central difference along parameter `j` (half step `h`) may not
/// estimate the derivative: the step moves the mesh by half its distance to
/// the sensor or more.
fn passes_sensor(scene: &Scene, j: usize, h: f64) -> Option<String> {
    let p = &scene.parameters()[j];
    let shape = &scene.shapes()[scene.parameter_shape(j) as usize];
    let x = scene.sensor().point();
    let travel = shape
        .vertices
        .iter()
        .map(|&q| (p.motion.apply(q, h) - q).length())
        .fold(0.0, f64::max);
    let distance = (0..shape.triangles.len())
        .map(|i| point_triangle_distance(x, &shape.triangle(i)))
        .fold(f64::INFINITY, f64::min);
    (travel >= 0.5 * distance).then(|| {
        format!(
            "finite differences along {:?}: the step moves mesh {:?} by {} while it passes {} \
             from the sensor; try a smaller --fd-step",
            p.name,
            shape.name,
            crate::error::Num(travel),
            crate::error::Num(distance)
        )
    })
}

/// Largest relative distance of an edge's ends from the plane through the
/// sensor and another edge that [`edge_ties`] takes for an alignment: the
/// rounding of an exact one.
pub const TIE: f64 = 1e-12;

/// Where `I` may not be differentiable: an edge of a moved mesh and an edge
/// of another mesh (both discontinuities seen from the sensor) lie in one
/// plane through the sensor, within [`TIE`], and overlap as seen from it
/// (an occluder's edge whose shadow falls exactly on the lamp's edge, say).
/// The motion then takes one across the other's sight lines at the nominal
/// parameter: the one-sided derivatives differ, and each method returns one
/// of them or neither (such a tie gave expectation 0.199, rendering 0.0226,
/// finite differences 0.119, all marked reliable). One caveat per parameter
/// of such a mesh; the flatland twin is `flat::methods::ties`. Two edges
/// of one mesh count when they share no vertex.
pub fn edge_ties(space: &Space) -> Vec<(Quantity, String)> {
    use super::edges::is_discontinuity;
    let scene = space.scene();
    let x = scene.sensor().point();
    let t = space.edge_tables();
    let seen: Vec<usize> = (0..t.edges.len())
        .filter(|&i| is_discontinuity(&t.edges[i], &t.edge_facts[i], x))
        .collect();
    let params = scene.parameters();
    let moved = |k: u32| !space.shape_params[k as usize].is_empty();
    // Each edge's plane through the sensor: its unit normal, and how far
    // that normal may turn while the edge's ends stay within TIE of the
    // plane (TIE over the sine of the angle the edge subtends). Two edges
    // in one plane have normals within the sum of their slacks, up to
    // sign: sorted by the normals' component along a direction no scene
    // lines up with, each moved edge meets only the few edges whose key is
    // that near its own, or its opposite's (a scan of every pair took
    // minutes on a mesh of 10⁶ triangles).
    let plane = |i: usize| {
        let e = &t.edges[i];
        let (ra, rb) = (e.a - x, e.b - x);
        let n = ra.cross(rb);
        let sine = n.length() / (ra.length() * rb.length());
        (sine > TIE).then(|| (n / n.length(), 4.0 * TIE / sine))
    };
    let key_axis = glam::DVec3::new(0.5773, 0.6181, -0.5331).normalize();
    let mut planes: Vec<(f64, usize)> = Vec::with_capacity(seen.len());
    let mut widest = 0.0f64;
    for &i in &seen {
        if let Some((n, slack)) = plane(i) {
            planes.push((n.dot(key_axis), i));
            widest = widest.max(slack);
        }
    }
    planes.sort_by(|a, b| a.0.total_cmp(&b.0));
    // (moved mesh, other mesh, the plane's unit normal, the moved edge's ends)
    let mut tied: Vec<(u32, u32, glam::DVec3, [glam::DVec3; 2])> = Vec::new();
    for &i in seen.iter().filter(|&&i| moved(t.edges[i].shape)) {
        let Some((unit, slack)) = plane(i) else {
            continue; // an edge pointing at the sensor: no plane
        };
        let a = &t.edges[i];
        let (ra, rb) = (a.a - x, a.b - x);
        let u = ra / ra.length();
        let angle = |r: glam::DVec3| unit.dot(u.cross(r)).atan2(u.dot(r));
        // Each edge's arc of sight lines in the plane: a start angle and a
        // length below π (a segment off the sensor subtends less); two arcs
        // overlap when either's start lies strictly inside the other. (As
        // min/max of angles in (−π, π], an arc across the back, a room's
        // corner edge behind the sensor, had spanned the whole circle and
        // tied with everything.)
        let arc = |p: glam::DVec3, q: glam::DVec3| {
            let (tp, tq) = (angle(p), angle(q));
            let sweep = (tq - tp + PI).rem_euclid(TAU) - PI;
            if sweep >= 0.0 {
                (tp, sweep)
            } else {
                (tq, -sweep)
            }
        };
        let inside = |start: f64, arc: (f64, f64)| (start - arc.0).rem_euclid(TAU) < arc.1;
        let arc_a = arc(ra, rb);
        let reach = slack + widest;
        for key in [unit.dot(key_axis), -unit.dot(key_axis)] {
            let from = planes.partition_point(|p| p.0 < key - reach);
            for &(_, k) in planes[from..].iter().take_while(|p| p.0 <= key + reach) {
                let b = &t.edges[k];
                // Within one mesh, edges that meet at a vertex are one
                // outline (a face seen edge-on is `kinks`'s); apart, they
                // tie as two meshes' edges do (two quads of one mesh, one
                // shadow edge on the other's: rendering 0.0049, finite
                // differences −0.074, the one-sided −0.148 and 0).
                let touching = [a.a, a.b].iter().any(|p| *p == b.a || *p == b.b);
                if (b.shape == a.shape && touching) || tied.len() >= MAX_TIES {
                    continue;
                }
                let (qa, qb) = (b.a - x, b.b - x);
                let off = |q: glam::DVec3| unit.dot(q).abs() <= TIE * q.length();
                if !(off(qa) && off(qb)) {
                    continue;
                }
                let arc_b = arc(qa, qb);
                if inside(arc_b.0, arc_a) || inside(arc_a.0, arc_b) {
                    tied.push((a.shape, b.shape, unit, [a.a, a.b]));
                }
            }
        }
    }
    // A motion that keeps the moved edge in the plane (a translation along
    // an edge-on face, say) slides it along the tie and crosses no kink,
    // as `kinks` spares it; the sensor's own motion likewise, axis by axis.
    let why = |ka: u32, kb: u32, along: String| {
        format!(
            "edges of {} lie in one plane through the sensor and overlap as seen from it: I \
             may have a kink along {along} (the one-sided derivatives differ) and the \
             estimate is one of them or neither",
            if ka == kb {
                format!("mesh {:?}", scene.shapes()[ka as usize].name)
            } else {
                format!(
                    "meshes {:?} and {:?}",
                    scene.shapes()[ka as usize].name,
                    scene.shapes()[kb as usize].name
                )
            }
        )
    };
    let mut out = Vec::new();
    for (j, p) in params.iter().enumerate() {
        let k = scene.parameter_shape(j);
        let crossing = tied.iter().find(|&&(ka, _, n, ends)| {
            ka == k && ends.iter().any(|&q| crosses(p.motion.velocity(q), n))
        });
        if let Some(&(ka, kb, _, _)) = crossing {
            out.push((
                Quantity::sensitivity(&p.name),
                why(ka, kb, format!("{:?}", p.name)),
            ));
        }
    }
    for (axis, e) in AXES {
        if let Some(&(ka, kb, _, _)) = tied.iter().find(|&&(_, _, n, _)| crosses(e, n)) {
            out.push((
                Quantity::gradient(axis),
                why(ka, kb, format!("the sensor's {axis}")),
            ));
        }
    }
    out
}

/// Most ties [`edge_ties`] keeps (a scene of many exactly aligned edges,
/// a grid seen along its rows, would otherwise keep them all).
const MAX_TIES: usize = 64;

/// Why the central difference along parameter `j` (half step `h`) may not
/// estimate the derivative: a face of the moved mesh faces the sensor in
/// one displaced scene and turns its back on it in the other, so within
/// the step it is seen edge-on and the silhouette changes (a kink of `I`
/// inside the step: the quotient is neither one-sided derivative, with an
/// error bar that cannot see it). Found by a random-scene campaign: a
/// tetrahedron whose face turned edge-on 10⁻⁴ rad from the nominal
/// rotation gave −0.0017 ± 0.0003 at the default step against the exact
/// −0.0054, marked reliable. Flatland's twin is its sensor-view test.
fn turns_face(scene: &Scene, j: usize, h: f64, plus: &Scene, minus: &Scene) -> Option<String> {
    let k = scene.parameter_shape(j) as usize;
    let x = scene.sensor().point();
    let facing = |s: &Scene, i: usize| {
        let t = s.shapes()[k].triangle(i);
        (t[1] - t[0]).cross(t[2] - t[0]).dot(x - t[0]) > 0.0
    };
    let shape = &scene.shapes()[k];
    let i = (0..shape.triangles.len()).find(|&i| facing(plus, i) != facing(minus, i))?;
    Some(format!(
        "finite differences along {:?}: triangle {i} of mesh {:?} turns from facing the sensor \
         to facing away between the scenes displaced by ±{}: it is seen edge-on within the step, \
         where the silhouette changes; try a smaller --fd-step",
        scene.parameters()[j].name,
        shape.name,
        crate::error::Num(h)
    ))
}

/// Distance from `p` to the triangle `t`.
pub fn point_triangle_distance(p: glam::DVec3, t: &[glam::DVec3; 3]) -> f64 {
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    let nn = n.length_squared();
    if nn > 0.0 {
        // Inside the prism over the triangle: the distance to its plane.
        let inside = (0..3).all(|i| {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            (b - a).cross(p - a).dot(n) >= 0.0
        });
        if inside {
            return (p - t[0]).dot(n).abs() / nn.sqrt();
        }
    }
    (0..3)
        .map(|i| {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            let d = b - a;
            let s = ((p - a).dot(d) / d.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
            (p - (a + d * s)).length()
        })
        .fold(f64::INFINITY, f64::min)
}

/// The thin-medium caveat of finite differences along parameter `j`
/// ([`thin_medium_caveat`]): the media of its shape and of the shape it
/// lies in.
fn thin_medium(scene: &Scene, j: usize) -> Option<String> {
    let k = scene.parameter_shape(j);
    let media = [Some(k), scene.parent_medium(k)]
        .into_iter()
        .flatten()
        .filter_map(|k| {
            let s = &scene.shapes()[k as usize];
            let m = s.medium.as_ref()?;
            Some((s.name.as_str(), m.ks, chord_bound(&s.vertices)))
        });
    thin_medium_caveat(media)
}
