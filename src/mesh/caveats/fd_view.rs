//! Whether the sensor's view changes within a central difference's step:
//! the 3D twin of flatland's `view_change`. Seen from the sensor, the
//! irradiance is a smooth function of a parameter while the meshes'
//! outlines keep their arrangement. A vertex of one outline crossing a
//! generic edge of another leaves it differentiable, but an edge of one
//! reaching the line of an edge of another (an occluder's shadow edge
//! reaching the lamp's edge) is a kink: the derivative drops to 0 there. A
//! central difference whose step straddles it measures the quotient across
//! the kink, not the derivative (a shadow edge 10⁻⁴ inside a lamp's edge,
//! at the default step: −0.1477 ± 0.0069 against the exact −0.0206, marked
//! reliable). So the two displaced scenes are compared: an outline edge of
//! the moved mesh and one of another opaque mesh, with overlapping arcs
//! seen from the sensor, where both ends of one cross the other's plane
//! through the sensor between the two scenes. Hidden edges count too (a
//! caveat where none was needed, not a wrong number). Book: chapter
//! "Reliability", section "Finite differences across a change of
//! visibility".
use crate::mesh::scene::{Scene, Shape};
use crate::method::model::Step;
use crate::path::Surface;
use glam::DVec3;
use std::collections::HashMap;

/// Most (edge, vertex) pairs the comparison tests per parameter; beyond,
/// it is left out (a step that crosses such an arrangement is then not
/// caught), so that setting up finite differences stays quick.
const MAX_PAIRS: usize = 20_000_000;

/// The outline of an opaque mesh seen from `x`: its edges that can be
/// discontinuities there (open, or between a face turned to `x` and one
/// turned away), as vertex index pairs.
fn outline(shape: &Shape, x: DVec3) -> Vec<[u32; 2]> {
    let mut faces: HashMap<[u32; 2], Vec<usize>> = HashMap::new();
    for (i, t) in shape.triangles.iter().enumerate() {
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            faces.entry([a.min(b), a.max(b)]).or_default().push(i);
        }
    }
    let facing = |i: usize| {
        let t = shape.triangle(i);
        (t[1] - t[0]).cross(t[2] - t[0]).dot(x - t[0]) > 0.0
    };
    let mut out: Vec<[u32; 2]> = faces
        .into_iter()
        .filter(|(_, f)| f.len() == 1 || (f.len() == 2 && facing(f[0]) != facing(f[1])))
        .map(|(e, _)| e)
        .collect();
    out.sort_unstable();
    out
}

/// Whether direction `v` (from the sensor) lies strictly inside the wedge
/// of the arc from `a` to `b`.
#[inline]
fn within(a: DVec3, b: DVec3, v: DVec3) -> bool {
    let n = a.cross(b);
    a.cross(v).dot(n) > 0.0 && v.cross(b).dot(n) > 0.0
}

/// The outlines seen from the sensor of `scene`'s opaque meshes, by mesh
/// (empty for a transparent one): [`view_crossing`]'s other meshes, found
/// once for every parameter.
pub fn outlines(scene: &Scene) -> Vec<Vec<[u32; 2]>> {
    let x = scene.sensor().point();
    scene
        .shapes()
        .iter()
        .map(|s| {
            if s.surface == Surface::Transparent {
                Vec::new()
            } else {
                outline(s, x)
            }
        })
        .collect()
}

/// `±1` (or 0) as `v` lies on either side of the plane through the sensor
/// and the directions `a`, `b`.
#[inline]
fn side(a: DVec3, b: DVec3, v: DVec3) -> f64 {
    a.cross(b).dot(v).signum()
}

/// Why the central difference of `step` on `scene` (`outlines` the
/// nominal scene's, from [`outlines`]) may straddle a kink: an outline edge of the
/// moved mesh sweeps across the line of an outline edge of another opaque
/// mesh, or the reverse, between the two displaced scenes, as seen from
/// the sensor, their arcs overlapping.
pub fn view_crossing(
    scene: &Scene,
    step: &Step<'_, Scene>,
    outlines: &[Vec<[u32; 2]>],
) -> Option<String> {
    let &Step { j, h, plus, minus } = step;
    let k = scene.parameter_shape(j) as usize;
    let x = scene.sensor().point();
    let (mp, mm) = (&plus.shapes()[k], &minus.shapes()[k]);
    let (own_p, own_m) = (outline(mp, x), outline(mm, x));
    let others: Vec<(&Shape, &[[u32; 2]])> = scene
        .shapes()
        .iter()
        .zip(outlines)
        .enumerate()
        .filter(|&(i, (_, o))| i != k && !o.is_empty())
        .map(|(_, (s, o))| (s, o.as_slice()))
        .collect();
    let other_edges: usize = others.iter().map(|o| o.1.len()).sum();
    let pairs = own_p.len() * 2 * other_edges * 3;
    // A changed outline is `turns_face`'s caveat (a face turns edge-on).
    if pairs > MAX_PAIRS || own_p != own_m {
        return None;
    }
    let dir = |p: DVec3| p - x;
    let ends = |m: &Shape, e: &[u32; 2]| {
        (
            dir(m.vertices[e[0] as usize]),
            dir(m.vertices[e[1] as usize]),
        )
    };
    for (s, edges) in &others {
        for e in *edges {
            let (c, d) = ends(s, e);
            for f in &own_p {
                let ((ap, bp), (am, bm)) = (ends(mp, f), ends(mm, f));
                // The moved edge's ends both cross the other's plane, or
                // the other's ends both cross the moved edge's plane
                // (a rotation about the sensor's line), within overlapping
                // arcs.
                let swept = (side(c, d, ap) != side(c, d, am) && side(c, d, bp) != side(c, d, bm))
                    || (side(ap, bp, c) != side(am, bm, c) && side(ap, bp, d) != side(am, bm, d));
                let overlap = |a: DVec3, b: DVec3| {
                    within(c, d, a) || within(c, d, b) || within(a, b, c) || within(a, b, d)
                };
                if swept && (overlap(ap, bp) || overlap(am, bm)) {
                    return Some(message(scene, j, h, &s.name));
                }
            }
        }
    }
    None
}

fn message(scene: &Scene, j: usize, h: f64, mesh: &str) -> String {
    format!(
        "finite differences along {:?}: between the scenes displaced by ±{}, an edge of mesh \
         {:?}'s outline sweeps across the line of an edge of mesh {mesh:?}'s, as seen from the \
         sensor (a kink of I within the step: a shadow edge reaching a lamp's, say); try a \
         smaller --fd-step",
        scene.parameters()[j].name,
        crate::error::Num(h),
        scene.shapes()[scene.parameter_shape(j) as usize].name,
    )
}
