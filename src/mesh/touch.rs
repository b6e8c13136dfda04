//! A ray that meets a medium's closed boundary exactly on an edge or at a
//! vertex, where the watertight test ([`super::bvh`]) counts a hit, may
//! cross the surface there or only touch it (a radiance sensor's ray
//! grazing a tetrahedron's edge from outside, or a cube's corner). The walk
//! changes medium at every hit on a medium's boundary, so a touch must not
//! be reported as a hit: the ray would run on "inside" a medium it never
//! entered. Random rays meet an edge with probability zero; the fixed ray
//! of a radiance sensor can meet one every time.
//!
//! The test is the local degree of the surface's projection along the ray.
//! Seen along the ray, the faces holding the point (two at an edge, the fan
//! at a vertex) cover the directions around it; the line crosses the closed
//! surface there if and only if a generic direction `g` is covered an odd
//! number of times (once when the surface passes across the ray, zero or
//! twice when it folds back to the side it came from). At an edge this is
//! whether the two faces lie on opposite sides of the plane through the ray
//! and the edge. Book: chapter "Three dimensions", section "Triangle meshes".
use super::bvh::edge_functions;
use super::space::Space;
use crate::path::Prim;
use glam::DVec3;

/// A direction no shipped or plausible scene aligns an edge with, for the
/// vertex test's `g` (any direction off the fan's projected edges serves).
const GENERIC: DVec3 = DVec3::new(0.574_145_230_8, 0.219_374_818_2, 0.788_870_133_1);

// How near an edge function must be to 0, relative to the three's sum,
// for a hit to count as on the edge: the path core's `NEAR` (a hit this
// near an edge whose two faces lie on one side is passed only if the cast
// that follows misses the other).
use crate::path::tolerance::NEAR;

impl Space {
    /// Whether the ray from `x` along `w`, which hits triangle `prim` of a
    /// closed mesh at `x + t w`, meets it on an edge or at a vertex (up to
    /// rounding) and only touches the mesh there (see the [module
    /// docs](self)): the faces there lie on one side of the ray, and the
    /// cast that follows the hit finds none of them (a ray just inside the
    /// edge meets both, and both hits count). `false` for a hit inside the
    /// triangle, and where the test cannot decide (a face holding the ray's
    /// direction): the hit then counts, as before.
    pub(super) fn touches_only(&self, x: DVec3, w: DVec3, prim: Prim, t: f64) -> bool {
        let tri = self.tris[prim as usize];
        let f = edge_functions(&tri, x, w);
        let near = NEAR * (f[0].abs() + f[1].abs() + f[2].abs());
        let on = f.map(|e| e.abs() <= near);
        // w · (a × b): the orientation of a, b seen along the ray.
        let turn = |a: DVec3, b: DVec3| w.dot(a.cross(b));
        // The edge's or the vertex's corners, when the faces there fold back.
        let feature: [DVec3; 2] = match on.iter().filter(|&&o| o).count() {
            1 => {
                let i = on.iter().position(|&o| o).unwrap_or(0);
                let (a, b, c) = (tri[(i + 1) % 3], tri[(i + 2) % 3], tri[i]);
                let Some(d) = self.mesh_faces(prim).find_map(|q| {
                    let t = &self.tris[q];
                    (q != prim as usize && t.contains(&a) && t.contains(&b))
                        .then(|| t.iter().copied().find(|&v| v != a && v != b))
                        .flatten()
                }) else {
                    return false;
                };
                if turn(b - a, c - a) * turn(b - a, d - a) <= 0.0 {
                    return false;
                }
                [a, b]
            }
            2 => {
                let p = tri[on.iter().position(|&o| !o).unwrap_or(0)];
                let g = w.cross(GENERIC);
                if g.length_squared() < 1e-6 {
                    return false;
                }
                let mut covered = 0u32;
                for q in self.mesh_faces(prim) {
                    let t = &self.tris[q];
                    let Some(k) = t.iter().position(|&v| v == p) else {
                        continue;
                    };
                    let (b, c) = (t[(k + 1) % 3] - p, t[(k + 2) % 3] - p);
                    let (bc, bg, gc) = (turn(b, c), turn(b, g), turn(g, c));
                    if bc == 0.0 || bg == 0.0 || gc == 0.0 {
                        return false;
                    }
                    covered += u32::from(bg.signum() == bc.signum() && gc.signum() == bc.signum());
                }
                if covered % 2 == 1 {
                    return false;
                }
                [p, p]
            }
            _ => return false,
        };
        // Folded back: a touch unless the ray goes on to meet another face
        // of the mesh at this edge or vertex (a chord the caster resolves).
        let q = x + w * t;
        let k = self.owner[prim as usize];
        match self.caster.closest_hit(q, w, f64::INFINITY, prim) {
            Some((_, next)) if self.owner[next as usize] == k => {
                let t = &self.tris[next as usize];
                !(t.contains(&feature[0]) && t.contains(&feature[1]))
            }
            _ => true,
        }
    }

    /// The triangles of the mesh that holds `prim` (the meshes' triangles
    /// are consecutive in `tris`).
    fn mesh_faces(&self, prim: Prim) -> std::ops::Range<usize> {
        let k = self.owner[prim as usize];
        let lo = self.owner.partition_point(|&o| o < k);
        let hi = self.owner.partition_point(|&o| o <= k);
        lo..hi
    }
}
