//! Ray casting against triangles: the `f64` ray–triangle test
//! [`intersect`], a bounding volume hierarchy [`TriangleBvh`] and its
//! brute-force form [`TriangleBvh::linear`], which answer every query alike,
//! bit for bit. The tree, its unit frame and its traversal are shared with
//! flatland's [`SegmentBvh`](crate::flat::bvh::SegmentBvh) in
//! [`bvh_frame`](crate::bvh_frame); this module adds the triangle.
//!
//! # The triangle test
//!
//! [`intersect`] is the watertight test of Woop, Benthin and Wald (2013,
//! *Watertight ray/triangle intersection*, JCGT 2(1)) in `f64`: the vertices
//! are moved to the ray origin and sheared so that the ray runs along an
//! axis, and the ray crosses the triangle when the three 2D edge functions
//! `p × q` of its projected edges share a sign (zero included: edges and
//! vertices count as inside). A vertex's projection depends on the vertex
//! and the ray only, and an edge's function in the neighbouring triangle is
//! `q × p = −(p × q)` exactly in floating point, so two welded triangles
//! see their shared edge on opposite sides of the ray, whatever the
//! rounding: a ray through an edge or a vertex of a closed mesh never slips
//! through (tested on icospheres). Möller–Trumbore, as obvhs's `f32`
//! triangle, computes each triangle's barycentrics from its own edge
//! vectors and has no such guarantee. Hits nearer than [`T_MIN`] times the
//! triangle's longest edge are not counted: a ray leaving a surface must not
//! find the triangles around the point it leaves.
//!
//! # The hierarchy
//!
//! obvhs's binary BVH (PLOC, `medium_build`) is built over the triangles'
//! boxes only, in `f32`; every triangle it reaches is tested in `f64` by the
//! very test the linear scan makes, so a hit's distance and index are the
//! scan's bit for bit (ties, as where two triangles meet, go to the lowest
//! index in both). `f32` triangles would put hits off by 10⁻⁷ of the scene
//! size, far more than the sensitivities tolerate near silhouettes.
//!
//! ## Conservative culling
//!
//! The boxes live in the *unit frame* of [`bvh_frame`](crate::bvh_frame),
//! padded by [`PAD`]; the argument that the `f32` culling never loses a hit
//! (coordinates of 10³⁰ or 10⁻³⁰ included), and the fallback to a scan of
//! all triangles for rays the frame cannot hold, are stated there once for
//! both casters.
//!
//! ## Small scenes
//!
//! Below [`LINEAR_BELOW`] triangles, [`TriangleBvh::new`] builds no tree
//! and scans. Unlike flatland's segments, the tree won at every size
//! `cargo bench --bench mesh_raycast -- crossover` tried (n triangles
//! picked from a torus, rays from a box around it): 1.8 times faster than
//! the scan at 4 triangles, 3.2 at 16, 38 at 512, since the root box
//! alone turns away the many rays that miss. So the scan serves only
//! lists of fewer than 4 triangles, where a tree is pointless.
//!
//! # Cost
//!
//! No heap allocation per query (see [`bvh_frame`](crate::bvh_frame#cost)).
//! `cargo bench --bench mesh_raycast` (one core, an icosphere of 81 920
//! triangles around a torus of 24 576, 106 496 in all, rays from random
//! points in the box `[−1.1, 1.1]³` in random directions) measured
//! (medians over 1024 rays; 2 cores shared with other builds, so ±10 %):
//!
//! | query | `TriangleBvh` | obvhs alone (`f32`) | ratio |
//! |---|---|---|---|
//! | closest hit | 3.2 M rays/s (320 µs) | 4.6 M rays/s (224 µs) | 1.43 |
//! | any hit, `t_max = 0.5` | 6.5 M rays/s (157 µs) | 8.2 M rays/s (124 µs) | 1.26 |
//! | build | 50 ms | 38 ms | 1.30 |
//!
//! "obvhs alone" is `Bvh2::ray_traverse` / `ray_traverse_miss` with its
//! `f32` Möller–Trumbore `Triangle::intersect` over a tree built by
//! `build_bvh2_from_tris`: the `f64` watertight test, the padding and the
//! exact ties cost less than a factor 1.5. The tree is 22 levels deep.
use std::fmt;

use glam::DVec3;

#[cfg(test)]
use crate::bvh_frame::NONE;
pub use crate::bvh_frame::PAD;
use crate::bvh_frame::{Primitive, Tree};

/// Smallest ray distance counted as a hit, relative to the longest edge of
/// the triangle hit (and to the size of the ray direction; the path
/// core's, shared with flatland): a ray leaving a surface must not find
/// the triangles around its origin, and the threshold scales with the
/// scene.
pub use crate::path::tolerance::T_MIN;

/// Ulps of a triangle's largest coordinate below which a hit is the
/// rounding of a point on it, not a hit ([`T_MIN`] for triangles far
/// from the origin).
pub const ROUNDING_ULPS: f64 = 64.0;

/// Below this many (finite) triangles, [`TriangleBvh`] scans them instead
/// of building a tree (see the [module docs](self#small-scenes)).
pub const LINEAR_BELOW: usize = 4;

/// Distance `t` along the ray `origin + t dir` (`dir` need not be unit) to
/// the triangle, if the ray crosses it (edges and vertices included)
/// farther than [`T_MIN`] times the triangle's longest edge; `None` for rays
/// parallel to its plane and for degenerate triangles. Watertight: of two
/// triangles sharing an edge (the same two vertices, bit for bit), a ray
/// through the edge hits at least one; see the [module docs](self).
#[inline]
pub fn intersect(tri: &[DVec3; 3], origin: DVec3, dir: DVec3) -> Option<f64> {
    Shear::new(origin, dir).hit(tri, nearest_hit2(tri))
}

/// The three edge functions of [`intersect`]'s test for the ray from
/// `origin` along `dir`, the numbers it compares with 0: the `i`-th
/// belongs to the edge opposite `tri[i]`. A hit with one of them exactly 0
/// lies on that edge, with two at the vertex they share.
pub fn edge_functions(tri: &[DVec3; 3], origin: DVec3, dir: DVec3) -> [f64; 3] {
    Shear::new(origin, dir).edges(tri).0
}

/// The square of the least distance (times `|dir|`) at which a ray hits
/// `tri`: [`T_MIN`] times its longest edge, and at least `ROUNDING_ULPS`
/// ulps of its largest coordinate (far from the origin the rounding of a
/// point on the triangle, an origin on its edge say, outgrows the first).
/// Fixed per triangle, so the casters keep it beside the triangle.
#[inline]
fn nearest_hit2(tri: &[DVec3; 3]) -> f64 {
    let size2 = (tri[1] - tri[0])
        .length_squared()
        .max((tri[2] - tri[1]).length_squared())
        .max((tri[0] - tri[2]).length_squared());
    let mag = tri[0]
        .abs()
        .max(tri[1].abs())
        .max(tri[2].abs())
        .max_element();
    let floor = ROUNDING_ULPS * f64::EPSILON * mag;
    (T_MIN * T_MIN * size2).max(floor * floor)
}

/// A query ray prepared for [`intersect`]: the shear that takes it to the
/// `kz` axis from the origin, `kz` its largest direction component.
#[derive(Debug, Clone, Copy)]
pub struct Shear {
    origin: DVec3,
    /// `e_kx − (d_kx / d_kz) e_kz` and `e_ky − (d_ky / d_kz) e_kz`, where
    /// `(kx, ky, kz)` is a cyclic permutation of the axes: their dot
    /// product with `p` is `p_kx − (d_kx / d_kz) p_kz` (the products by
    /// 1 and 0 are exact), without indexing by a run-time axis.
    ex: DVec3,
    ey: DVec3,
    /// `e_kz / d_kz`: the dot product with `p` is the ray parameter of
    /// `p`'s plane across the ray.
    ez: DVec3,
    /// `|d|²`, for the distance threshold.
    len2: f64,
}

impl Shear {
    #[inline]
    fn new(origin: DVec3, dir: DVec3) -> Shear {
        let a = dir.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
        let sz = 1.0 / dir[kz];
        let (mut ex, mut ey, mut ez) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
        ex[kx] = 1.0;
        ex[kz] = -(dir[kx] * sz);
        ey[ky] = 1.0;
        ey[kz] = -(dir[ky] * sz);
        ez[kz] = sz;
        Shear {
            origin,
            ex,
            ey,
            ez,
            len2: dir.length_squared(),
        }
    }

    /// Vertex `v` in ray space: sheared `(x, y)` and the ray parameter of
    /// its plane across the ray.
    #[inline(always)]
    fn project(&self, v: DVec3) -> (f64, f64, f64) {
        let p = v - self.origin;
        (p.dot(self.ex), p.dot(self.ey), p.dot(self.ez))
    }

    /// The edge functions of `tri` (see [`edge_functions`]) and the ray
    /// parameters of its vertices' planes across the ray.
    #[inline(always)]
    fn edges(&self, tri: &[DVec3; 3]) -> ([f64; 3], [f64; 3]) {
        let (ax, ay, az) = self.project(tri[0]);
        let (bx, by, bz) = self.project(tri[1]);
        let (cx, cy, cz) = self.project(tri[2]);
        // Edge functions, each the same number (up to sign) in every
        // triangle holding the edge.
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        ([u, v, w], [az, bz, cz])
    }

    /// The test of [`intersect`], `min2` the triangle's [`nearest_hit2`].
    #[inline(always)]
    fn hit(&self, tri: &[DVec3; 3], min2: f64) -> Option<f64> {
        let ([u, v, w], [az, bz, cz]) = self.edges(tri);
        let inside = (u >= 0.0 && v >= 0.0 && w >= 0.0) || (u <= 0.0 && v <= 0.0 && w <= 0.0);
        if !inside {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None; // parallel ray or degenerate triangle
        }
        let t = (u * az + v * bz + w * cz) / det;
        (t > 0.0 && t * t * self.len2 > min2).then_some(t)
    }
}

/// A ray in the form the triangle test takes, made once by
/// [`TriangleBvh::ray`] for several casters.
pub type CastRay = Shear;

/// A finite triangle with its index in the caller's list.
#[derive(Debug, Clone, Copy)]
struct Prim {
    tri: [DVec3; 3],
    /// [`nearest_hit2`] of `tri`.
    min2: f64,
    id: u32,
}

/// The finite triangles of `triangles`, with their indices.
fn finite_prims(triangles: Vec<[DVec3; 3]>) -> Vec<Prim> {
    triangles
        .into_iter()
        .enumerate()
        .filter(|(_, t)| t.iter().all(|v| v.is_finite()))
        .map(|(i, tri)| Prim {
            tri,
            min2: nearest_hit2(&tri),
            id: i as u32,
        })
        .collect()
}

impl Primitive for Prim {
    type Vector = DVec3;
    type Ray = Shear;

    #[inline(always)]
    fn ray(origin: DVec3, dir: DVec3) -> Shear {
        Shear::new(origin, dir)
    }

    #[inline(always)]
    fn hit(&self, ray: &Shear) -> Option<f64> {
        ray.hit(&self.tri, self.min2)
    }

    #[inline]
    fn bounds(&self) -> (DVec3, DVec3) {
        let [a, b, c] = self.tri;
        (a.min(b).min(c), a.max(b).max(c))
    }

    #[inline(always)]
    fn id(&self) -> u32 {
        self.id
    }
}

/// A BVH ray caster over a fixed list of triangles; see the [module
/// docs](self). Answers exactly as [`TriangleBvh::linear`] over the same list.
#[derive(Clone)]
pub struct TriangleBvh {
    /// The finite triangles (no tree below [`LINEAR_BELOW`]).
    tree: Tree<Prim>,
    /// Length of the list given.
    count: usize,
}

impl fmt::Debug for TriangleBvh {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("TriangleBvh")
            .field("triangles", &self.count)
            .field("finite", &self.tree.prims().len())
            .field("nodes", &self.tree.nodes())
            .field("depth", &self.tree.depth())
            .finish()
    }
}

impl TriangleBvh {
    /// A caster over `triangles` (index = position in the list). Any list
    /// is accepted: an empty one is never hit, and non-finite triangles,
    /// which a linear scan never reports either, are left out. Below
    /// [`LINEAR_BELOW`] finite triangles no tree is built.
    pub fn new(triangles: Vec<[DVec3; 3]>) -> TriangleBvh {
        TriangleBvh::with_linear_below(triangles, LINEAR_BELOW)
    }

    /// Ray casting by testing every triangle in list order, no tree: the
    /// reference the tree is checked against (the tree's own traversal is
    /// not used, only the scan its leaves make).
    pub fn linear(triangles: Vec<[DVec3; 3]>) -> TriangleBvh {
        TriangleBvh::with_linear_below(triangles, usize::MAX)
    }

    /// [`TriangleBvh::new`] with a tree from `linear_below` finite
    /// triangles up (for the crossover benchmark; answers are the same).
    #[doc(hidden)]
    pub fn with_linear_below(triangles: Vec<[DVec3; 3]>, linear_below: usize) -> TriangleBvh {
        let count = triangles.len();
        TriangleBvh {
            tree: Tree::new(finite_prims(triangles), linear_below),
            count,
        }
    }

    /// Length of the list given (non-finite triangles included).
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether the list given was empty.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The closest triangle other than `skip` (`u32::MAX`: none) crossed by
    /// `origin + t dir` with `t < t_max`, as `(t, index)`; exactly
    /// the linear scan's answer (ties to the lowest index).
    pub fn closest_hit(
        &self,
        origin: DVec3,
        dir: DVec3,
        t_max: f64,
        skip: u32,
    ) -> Option<(f64, u32)> {
        self.tree.closest_hit(origin, dir, t_max, skip)
    }

    /// `origin + t dir` in the form [`TriangleBvh::closest_hit_along`] and
    /// [`TriangleBvh::any_hit_along`] take.
    #[inline]
    pub fn ray(origin: DVec3, dir: DVec3) -> CastRay {
        Shear::new(origin, dir)
    }

    /// [`TriangleBvh::closest_hit`] with `ray` made by [`TriangleBvh::ray`]
    /// of the same `origin` and `dir` (a caller asking several casters
    /// makes it once).
    #[inline]
    pub fn closest_hit_along(
        &self,
        ray: &CastRay,
        origin: DVec3,
        dir: DVec3,
        t_max: f64,
        skip: u32,
    ) -> Option<(f64, u32)> {
        self.tree.closest_hit_along(ray, origin, dir, t_max, skip)
    }

    /// [`TriangleBvh::any_hit`] with `ray` made by [`TriangleBvh::ray`].
    #[inline]
    pub fn any_hit_along(
        &self,
        ray: &CastRay,
        origin: DVec3,
        dir: DVec3,
        t_max: f64,
        skip: u32,
    ) -> bool {
        self.tree.any_hit_along(ray, origin, dir, t_max, skip)
    }

    /// Whether any triangle other than `skip` (`u32::MAX`: none) is crossed
    /// by `origin + t dir` with `t < t_max`; exactly
    /// the linear scan's answer.
    pub fn any_hit(&self, origin: DVec3, dir: DVec3, t_max: f64, skip: u32) -> bool {
        self.tree.any_hit(origin, dir, t_max, skip)
    }
}

#[cfg(test)]
mod tests;
