//! Ray casting against triangles: the `f64` ray–triangle test
//! [`intersect`], a bounding volume hierarchy [`TriangleBvh`] and the
//! brute-force [`LinearTriangles`], which answer every query alike, bit for
//! bit. The design is flatland's [`SegmentBvh`](crate::flat::bvh::SegmentBvh)
//! in one more dimension.
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
//! The boxes live in a *unit frame*: the scene translated and scaled by a
//! power of two (exact) so that it fits in `[−1, 1]³`; huge or tiny
//! coordinates (10³⁰, 10⁻³⁰) are then no concern of `f32`. Each box is
//! padded by [`PAD`] = 2⁻¹⁶ of the scene half-size, and so is each `f32`
//! distance bound: far more than the `f32` rounding of the ray (origin,
//! direction, slab arithmetic: below 10⁻⁶ inside the frame). The query
//! direction is scaled by a power of two to a largest component in
//! `[1, 2)`, so ray parameters are frame distances within a factor √3, and
//! obvhs's clamp of inverse directions at 1/ε (ε = 2⁻²³) only shortens
//! slabs to at least `PAD/ε` ≈ 128, beyond any parameter inside the frame
//! (≤ 2√3). A ray from outside the padded scene box first moves, in
//! `f64`, to where it enters it, so the `f32` ray starts in the frame
//! whatever the origin. Rays the frame cannot hold (origins farther than
//! 2³⁰ scene sizes, non-finite input, directions whose size over- or
//! underflows) fall back to a scan of all triangles, with the same answer.
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
//! No heap allocation per query: the traversal stack is a fixed array on
//! the call stack sized from the tree depth measured at construction (64 or
//! 256 entries; deeper trees, never seen, take a heap stack per query).
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
use std::time::Duration;

use glam::DVec3;
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::faststack::{FastStack, StackStack};
use obvhs::ray::{Ray, RayHit};

/// Smallest ray distance counted as a hit, relative to the longest edge of
/// the triangle hit (and to the size of the ray direction): as flatland's
/// [`geometry::T_MIN`](crate::flat::geometry::T_MIN), a ray leaving a
/// surface must not find the triangles around its origin, and the
/// threshold scales with the scene.
pub const T_MIN: f64 = 1e-12;

/// Pad of every box and every distance bound, in units of the scene's
/// half-size (the unit frame): 2⁻¹⁶ ≈ 1.5·10⁻⁵.
pub const PAD: f64 = 1.0 / 65536.0;

/// Below this many (finite) triangles, [`TriangleBvh`] scans them instead
/// of building a tree (see the [module docs](self#small-scenes)).
pub const LINEAR_BELOW: usize = 4;

/// Origins farther than this from the scene centre (in the unit frame) are
/// traced by a linear scan: beyond it, the `f64` clipping error would
/// approach [`PAD`].
const FAR: f64 = (1u64 << 30) as f64;

/// No triangle (the `skip` of a query that skips none).
const NONE: u32 = u32::MAX;

/// Distance `t` along the ray `origin + t dir` (`dir` need not be unit) to
/// the triangle, if the ray crosses it (edges and vertices included)
/// farther than [`T_MIN`] times the triangle's longest edge; `None` for rays
/// parallel to its plane and for degenerate triangles. Watertight: of two
/// triangles sharing an edge (the same two vertices, bit for bit), a ray
/// through the edge hits at least one; see the [module docs](self).
#[inline]
pub fn intersect(tri: &[DVec3; 3], origin: DVec3, dir: DVec3) -> Option<f64> {
    Shear::new(origin, dir).hit(tri)
}

/// A query ray prepared for [`intersect`]: the shear that takes it to the
/// `kz` axis from the origin, `kz` its largest direction component.
#[derive(Debug, Clone, Copy)]
struct Shear {
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

    /// The test of [`intersect`].
    #[inline(always)]
    fn hit(&self, tri: &[DVec3; 3]) -> Option<f64> {
        let (ax, ay, az) = self.project(tri[0]);
        let (bx, by, bz) = self.project(tri[1]);
        let (cx, cy, cz) = self.project(tri[2]);
        // Edge functions, each the same number (up to sign) in every
        // triangle holding the edge.
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let inside = (u >= 0.0 && v >= 0.0 && w >= 0.0) || (u <= 0.0 && v <= 0.0 && w <= 0.0);
        if !inside {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None; // parallel ray or degenerate triangle
        }
        let t = (u * az + v * bz + w * cz) / det;
        let size2 = (tri[1] - tri[0])
            .length_squared()
            .max((tri[2] - tri[1]).length_squared())
            .max((tri[0] - tri[2]).length_squared());
        (t > 0.0 && t * t * self.len2 > T_MIN * T_MIN * size2).then_some(t)
    }
}

/// A finite triangle with its index in the caller's list.
#[derive(Debug, Clone, Copy)]
struct Prim {
    tri: [DVec3; 3],
    id: u32,
}

/// The finite triangles of `triangles`, with their indices.
fn finite_prims(triangles: Vec<[DVec3; 3]>) -> Vec<Prim> {
    triangles
        .into_iter()
        .enumerate()
        .filter(|(_, t)| t.iter().all(|v| v.is_finite()))
        .map(|(i, tri)| Prim { tri, id: i as u32 })
        .collect()
}

/// The closest of `prims` other than `skip` hit with `t < t_max`, ties to
/// the lowest index.
#[inline]
fn scan_closest(prims: &[Prim], ray: &Shear, t_max: f64, skip: u32) -> Option<(f64, u32)> {
    let mut best = (t_max, NONE);
    for p in prims {
        if p.id == skip {
            continue;
        }
        if let Some(t) = ray.hit(&p.tri)
            && (t < best.0 || (t == best.0 && p.id < best.1))
            && t < t_max
        {
            best = (t, p.id);
        }
    }
    (best.1 != NONE).then_some(best)
}

/// Whether any of `prims` other than `skip` is hit with `t < t_max`.
#[inline]
fn scan_any(prims: &[Prim], ray: &Shear, t_max: f64, skip: u32) -> bool {
    prims
        .iter()
        .any(|p| p.id != skip && ray.hit(&p.tri).is_some_and(|t| t < t_max))
}

/// Ray casting by testing every triangle: the reference [`TriangleBvh`] is
/// checked against, and the faster caster for a handful of triangles.
#[derive(Debug, Clone)]
pub struct LinearTriangles {
    /// The finite triangles, in list order.
    prims: Vec<Prim>,
    /// Length of the list given.
    count: usize,
}

impl LinearTriangles {
    /// A caster over `triangles` (index = position in the list); non-finite
    /// triangles are never hit.
    pub fn new(triangles: Vec<[DVec3; 3]>) -> LinearTriangles {
        let count = triangles.len();
        LinearTriangles {
            prims: finite_prims(triangles),
            count,
        }
    }

    /// The closest triangle other than `skip` (`u32::MAX`: none) crossed by
    /// `origin + t dir` with `t < t_max`, as `(t, index)`; ties go to the
    /// lowest index.
    pub fn closest_hit(
        &self,
        origin: DVec3,
        dir: DVec3,
        t_max: f64,
        skip: u32,
    ) -> Option<(f64, u32)> {
        scan_closest(&self.prims, &Shear::new(origin, dir), t_max, skip)
    }

    /// Whether any triangle other than `skip` (`u32::MAX`: none) is crossed
    /// by `origin + t dir` with `t < t_max`.
    pub fn any_hit(&self, origin: DVec3, dir: DVec3, t_max: f64, skip: u32) -> bool {
        scan_any(&self.prims, &Shear::new(origin, dir), t_max, skip)
    }

    /// Length of the list given (non-finite triangles included).
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether the list given was empty.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }
}

/// The map from scene coordinates to the unit frame, `p ↦ p s − c s`, with
/// `s` a power of two (so `p s` is exact).
#[derive(Debug, Clone, Copy)]
struct Frame {
    /// The centre times the scale.
    offset: DVec3,
    /// The scale, a power of two.
    scale: f64,
}

impl Frame {
    /// The frame in which `prims` fill about `[−1, 1]³`.
    fn new(prims: &[Prim]) -> Frame {
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for p in prims {
            for v in p.tri {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        if !(lo.is_finite() && hi.is_finite()) {
            return Frame {
                offset: DVec3::ZERO,
                scale: 1.0,
            };
        }
        // Halves first: `hi − lo` may overflow.
        let centre = 0.5 * lo + 0.5 * hi;
        let half = (0.5 * hi - 0.5 * lo).max_element();
        // 2^−e with 2^(e−1) < half ≤ 2^e, so the scene fits in [−1, 1]³; the
        // clamp keeps the scale a normal number (larger or smaller scenes
        // are still bounded conservatively, in a larger box or a speck).
        let e = if half > 0.0 {
            (half.log2().ceil() as i64).clamp(-1000, 1022)
        } else {
            0
        };
        let scale = f64::from_bits(((1023 - e) as u64) << 52);
        Frame {
            offset: centre * scale,
            scale,
        }
    }

    #[inline]
    fn map(&self, p: DVec3) -> DVec3 {
        p * self.scale - self.offset
    }
}

/// Where the `f32` ray of a query starts and how distances map onto it.
struct Clip {
    /// The `f32` ray: origin `o + s0 w`, direction `w`, where `o` is the
    /// query origin in the frame and `w = d / m` the query direction in the
    /// frame scaled by a power of two to a largest component in `[1, 2)`.
    ray: Ray,
    /// The power of two: query distance `t` is ray parameter `t m − s0`.
    m: f64,
    /// Ray parameter of the `f32` ray's origin from the query origin.
    s0: f64,
}

impl Clip {
    /// The `f32` bound for a hit at query distance `t`: boxes entered
    /// beyond it cannot hold a hit closer than `t`.
    #[inline]
    fn bound(&self, t: f64) -> f32 {
        ((t * self.m - self.s0) + PAD) as f32
    }
}

/// What a query needs: nothing (no hit possible), a linear scan (no tree,
/// or the frame cannot hold the ray), or a traversal.
enum Plan {
    Miss,
    Linear,
    Trace(Clip),
}

/// Runs `$body` with `$stack` bound to a traversal stack deep enough for a
/// tree of `$depth` levels: a fixed array when it fits, else a heap one.
macro_rules! with_stack {
    ($depth:expr, $stack:ident, $body:expr) => {
        // A push beyond a StackStack's last slot overwrites it silently: the
        // stack holds at most depth − 1 entries, and N − 1 fit.
        if $depth < 64 {
            let $stack = &mut StackStack::<u32, 64>::default();
            $body
        } else if $depth < 256 {
            let $stack = &mut StackStack::<u32, 256>::default();
            $body
        } else {
            let $stack = &mut Vec::<u32>::with_capacity($depth);
            $body
        }
    };
}

/// A BVH ray caster over a fixed list of triangles; see the [module
/// docs](self). Answers exactly as [`LinearTriangles`] over the same list.
#[derive(Clone)]
pub struct TriangleBvh {
    /// Empty below [`LINEAR_BELOW`] triangles.
    bvh: Bvh2,
    /// The finite triangles in BVH leaf order (list order without a tree).
    prims: Vec<Prim>,
    frame: Frame,
    /// The padded scene box in the frame; rays are clipped to it.
    lo: DVec3,
    hi: DVec3,
    /// Nodes on the longest root-to-leaf path (sizes the traversal stack).
    depth: usize,
    /// Length of the list given.
    count: usize,
}

impl fmt::Debug for TriangleBvh {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("TriangleBvh")
            .field("triangles", &self.count)
            .field("finite", &self.prims.len())
            .field("nodes", &self.bvh.nodes.len())
            .field("depth", &self.depth)
            .finish()
    }
}

impl TriangleBvh {
    /// A caster over `triangles` (index = position in the list). Any list
    /// is accepted: an empty one is never hit, and non-finite triangles,
    /// which [`LinearTriangles`] never reports either, are left out. Below
    /// [`LINEAR_BELOW`] finite triangles no tree is built.
    pub fn new(triangles: Vec<[DVec3; 3]>) -> TriangleBvh {
        TriangleBvh::with_linear_below(triangles, LINEAR_BELOW)
    }

    /// [`TriangleBvh::new`] with a tree from `linear_below` finite
    /// triangles up (for the crossover benchmark; answers are the same).
    #[doc(hidden)]
    pub fn with_linear_below(triangles: Vec<[DVec3; 3]>, linear_below: usize) -> TriangleBvh {
        let count = triangles.len();
        let finite = finite_prims(triangles);
        let frame = Frame::new(&finite);
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        let boxes: Vec<Aabb> = finite
            .iter()
            .map(|p| {
                let [a, b, c] = p.tri.map(|v| frame.map(v));
                let (min, max) = (a.min(b).min(c) - PAD, a.max(b).max(c) + PAD);
                lo = lo.min(min);
                hi = hi.max(max);
                Aabb::new(min.as_vec3a(), max.as_vec3a())
            })
            .collect();
        let (bvh, prims) = if boxes.is_empty() || boxes.len() < linear_below {
            (Bvh2::default(), finite)
        } else {
            let bvh = build_bvh2(
                &boxes,
                BvhBuildParams::medium_build(),
                &mut Duration::default(),
            );
            let prims = bvh
                .primitive_indices
                .iter()
                .map(|&k| finite[k as usize])
                .collect();
            (bvh, prims)
        };
        let depth = tree_depth(&bvh);
        TriangleBvh {
            bvh,
            prims,
            frame,
            lo: lo - PAD,
            hi: hi + PAD,
            depth,
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

    /// How to answer a query.
    #[inline]
    fn plan(&self, origin: DVec3, dir: DVec3, t_max: f64) -> Plan {
        if t_max.is_nan() || t_max <= 0.0 || self.prims.is_empty() {
            return Plan::Miss;
        }
        if self.bvh.nodes.is_empty() {
            return Plan::Linear;
        }
        let o = self.frame.map(origin);
        let d = dir * self.frame.scale;
        let a = d.abs().max_element();
        if !(o.is_finite() && a > 0.0 && a.is_finite()) || o.abs().max_element() > FAR {
            return Plan::Linear;
        }
        // m = 2^⌊log₂ a⌋ and w = d / m, both exact, without a division.
        let e = a.to_bits() >> 52; // a > 0: the biased exponent
        if !a.is_normal() || e >= 2045 {
            return Plan::Linear;
        }
        let m = f64::from_bits(e << 52);
        let w = d * f64::from_bits((2046 - e) << 52);
        // An origin outside the padded scene box moves to where the ray
        // enters it, at parameter s0.
        let mut s0 = 0.0_f64;
        if o.cmplt(self.lo).any() || o.cmpgt(self.hi).any() {
            let mut s1 = f64::INFINITY;
            for i in 0..3 {
                if w[i] == 0.0 {
                    if o[i] < self.lo[i] || o[i] > self.hi[i] {
                        return Plan::Miss;
                    }
                } else {
                    let inv = 1.0 / w[i];
                    let (ta, tb) = ((self.lo[i] - o[i]) * inv, (self.hi[i] - o[i]) * inv);
                    s0 = s0.max(ta.min(tb));
                    s1 = s1.min(ta.max(tb));
                }
            }
            if s0 > s1 || s0 > t_max * m + PAD {
                return Plan::Miss;
            }
        }
        let p = o + s0 * w;
        let mut clip = Clip {
            ray: Ray::new(p.as_vec3a(), w.as_vec3a(), 0.0, f32::INFINITY),
            m,
            s0,
        };
        clip.ray.tmax = clip.bound(t_max);
        Plan::Trace(clip)
    }

    /// The closest hit by traversal, with `stack` as the traversal stack.
    #[inline(always)]
    fn closest_with<S: FastStack<u32>>(
        &self,
        stack: &mut S,
        clip: &Clip,
        ray: &Shear,
        t_max: f64,
        skip: u32,
    ) -> Option<(f64, u32)> {
        let mut best = (t_max, NONE);
        let mut leaf = |node: &obvhs::bvh2::node::Bvh2Node, r: &mut Ray, _: &mut RayHit| {
            let first = node.first_index as usize;
            for p in &self.prims[first..first + node.prim_count as usize] {
                if p.id == skip {
                    continue;
                }
                if let Some(t) = ray.hit(&p.tri)
                    && t < t_max
                    && (t < best.0 || (t == best.0 && p.id < best.1))
                {
                    best = (t, p.id);
                    // Padded: a later equal-t, lower-index hit is still reached.
                    r.tmax = r.tmax.min(clip.bound(t));
                }
            }
            true
        };
        self.bvh
            .ray_traverse_dynamic(stack, clip.ray, &mut RayHit::none(), &mut leaf);
        (best.1 != NONE).then_some(best)
    }

    /// Whether any triangle is hit, by traversal with `stack`.
    #[inline(always)]
    fn any_with<S: FastStack<u32>>(
        &self,
        stack: &mut S,
        clip: &Clip,
        ray: &Shear,
        t_max: f64,
        skip: u32,
    ) -> bool {
        let mut found = false;
        let mut leaf = |node: &obvhs::bvh2::node::Bvh2Node, _: &mut Ray, _: &mut RayHit| {
            let first = node.first_index as usize;
            found = scan_any(
                &self.prims[first..first + node.prim_count as usize],
                ray,
                t_max,
                skip,
            );
            !found // false halts the traversal
        };
        self.bvh
            .ray_traverse_dynamic(stack, clip.ray, &mut RayHit::none(), &mut leaf);
        found
    }

    /// The closest triangle other than `skip` (`u32::MAX`: none) crossed by
    /// `origin + t dir` with `t < t_max`, as `(t, index)`; exactly
    /// [`LinearTriangles::closest_hit`]'s answer (ties to the lowest index).
    pub fn closest_hit(
        &self,
        origin: DVec3,
        dir: DVec3,
        t_max: f64,
        skip: u32,
    ) -> Option<(f64, u32)> {
        match self.plan(origin, dir, t_max) {
            Plan::Miss => None,
            Plan::Linear => scan_closest(&self.prims, &Shear::new(origin, dir), t_max, skip),
            Plan::Trace(clip) => {
                let ray = Shear::new(origin, dir);
                with_stack!(
                    self.depth,
                    stack,
                    self.closest_with(stack, &clip, &ray, t_max, skip)
                )
            }
        }
    }

    /// Whether any triangle other than `skip` (`u32::MAX`: none) is crossed
    /// by `origin + t dir` with `t < t_max`; exactly
    /// [`LinearTriangles::any_hit`]'s answer.
    pub fn any_hit(&self, origin: DVec3, dir: DVec3, t_max: f64, skip: u32) -> bool {
        match self.plan(origin, dir, t_max) {
            Plan::Miss => false,
            Plan::Linear => scan_any(&self.prims, &Shear::new(origin, dir), t_max, skip),
            Plan::Trace(clip) => {
                let ray = Shear::new(origin, dir);
                with_stack!(
                    self.depth,
                    stack,
                    self.any_with(stack, &clip, &ray, t_max, skip)
                )
            }
        }
    }
}

/// Nodes on the longest root-to-leaf path of `bvh` (0 if empty), without
/// recursion.
fn tree_depth(bvh: &Bvh2) -> usize {
    if bvh.nodes.is_empty() {
        return 0;
    }
    let mut deepest = 0;
    let mut todo = vec![(0usize, 1usize)];
    while let Some((i, d)) = todo.pop() {
        let node = &bvh.nodes[i];
        if node.is_leaf() {
            deepest = deepest.max(d);
        } else {
            let c = node.first_index as usize;
            todo.push((c, d + 1));
            todo.push((c + 1, d + 1));
        }
    }
    deepest
}

#[cfg(test)]
mod tests;
