//! Where `I` may have a kink because two meshes' edges lie in one plane
//! through the sensor and overlap as seen from it: the 3D twin of
//! flatland's corner ties. Book: chapter "Choosing a method" (row 4).
use super::kinks::crosses;
use crate::estimator::Quantity;
use crate::mesh::edges::is_discontinuity;
use crate::mesh::scene::AXES;
use crate::mesh::space::Space;
use std::f64::consts::{PI, TAU};

/// Largest relative distance of an edge's ends from the plane through the
/// sensor and another edge that [`edge_ties`] takes for an alignment (the
/// path core's, shared with flatland).
pub use crate::path::tolerance::TIE;

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
    let mut moved_planes = 0;
    for &i in &seen {
        if let Some((n, slack)) = plane(i) {
            planes.push((n.dot(key_axis), i));
            widest = widest.max(slack);
            moved_planes += usize::from(moved(t.edges[i].shape));
        }
    }
    // Few moved edges among many (a small moving occluder beside a large
    // reflector, all of whose edges are seen): a scan of the keys per moved
    // edge costs less than sorting them all, and finds the same candidates
    // in the same order (sorted stably by key, as the whole list would be).
    let scan = moved_planes * 64 < planes.len();
    if !scan {
        planes.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
    let mut window: Vec<(f64, usize)> = Vec::new();
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
            let near = |p: &(f64, usize)| p.0 >= key - reach && p.0 <= key + reach;
            let candidates = if scan {
                window.clear();
                window.extend(planes.iter().copied().filter(near));
                window.sort_by(|a, b| a.0.total_cmp(&b.0));
                &window[..]
            } else {
                let from = planes.partition_point(|p| p.0 < key - reach);
                let to = from + planes[from..].partition_point(|p| p.0 <= key + reach);
                &planes[from..to]
            };
            for &(_, k) in candidates {
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
