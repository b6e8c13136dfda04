//! Where `I` or the sensor's gradient may have a kink because the sensor
//! lies in the plane of a face: [`kinks`] (a moved face seen edge-on) and
//! [`plane_kinks_of_the_gradient`] (the sensor moving across a face's
//! plane). Book: chapter "Choosing a method" (row 4).
use crate::estimator::Quantity;
use crate::mesh::scene::{AXES, Scene};

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
/// (seen in random scenes; the bias went as 1/ulps, 3σ at 1 024).
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
    let tolerance = (crate::path::tolerance::ON_SURFACE * scene.size())
        .max(EDGE_ON_ULPS * f64::EPSILON * reach);
    let off = n.dot(x - t[0]);
    (n != glam::DVec3::ZERO && off.abs() <= tolerance).then_some((n, off, tolerance))
}

/// Largest angle (rad) between a velocity and a plane at which the motion
/// stays in the plane (see [`crosses`]): wider than an alignment's
/// [`TIE`](crate::path::tolerance::TIE), for a rotation's velocity about a
/// pivot up to `MAX_OFFSET` sizes away keeps fewer digits than a
/// coordinate.
const IN_PLANE: f64 = 1e-9;

/// Whether a motion at velocity `v` leaves the plane of unit normal `n`.
pub(super) fn crosses(v: glam::DVec3, n: glam::DVec3) -> bool {
    v.dot(n).abs() > IN_PLANE * v.length()
}

/// Where the sensor's gradient may not exist: the sensor lies in the plane
/// of a face (within [`kinks`]'s tolerance) but off the face itself, so
/// moving it across that plane turns the face, seen edge-on, to face it
/// from one side or the other (a lamp seen edge-on: transport's `∇z` read
/// 0.400 at the origin and 0.417 at 9·10⁵, "reliable", in random scenes). A
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
