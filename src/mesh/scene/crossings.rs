//! Meshes that cross or touch: a sweep-and-prune broad phase over the
//! meshes' boxes and then over their triangles, and the exact f64 test of
//! each close pair ([`triangles_within`]).
use super::geometry::{bounds, segment_triangle_distance, triangles_within};
use super::{Shape, TOUCH_DISTANCE};
use crate::error::Error;
use crate::scene::config;
use glam::DVec3;

/// An axis-aligned box, widened by a tolerance where compared.
#[derive(Clone, Copy)]
pub(super) struct Aabb {
    pub(super) lo: DVec3,
    pub(super) hi: DVec3,
}

impl Aabb {
    pub(super) fn of(points: &[DVec3]) -> Aabb {
        let (lo, hi) = bounds(points);
        Aabb { lo, hi }
    }
    pub(super) fn meets(&self, o: &Aabb, tol: f64) -> bool {
        (self.lo - tol).cmple(o.hi).all() && (o.lo - tol).cmple(self.hi).all()
    }
}

/// Rejects triangles of different meshes that cross or come within
/// [`TOUCH_DISTANCE`] × `size`. Broad phase: a sweep over x on the meshes'
/// boxes finds the pairs of meshes whose boxes meet; for each pair, the
/// triangles inside the other mesh's box are swept over x against each
/// other, and the pairs whose boxes meet get the exact test
/// ([`triangles_within`]). A large mesh beside small ones thus costs one
/// pass over its triangles per neighbour. With `only`, just the pairs that
/// hold a mesh it marks (the others are known to be apart).
pub(super) fn check_crossings(
    shapes: &[Shape],
    size: f64,
    only: Option<&[bool]>,
) -> Result<(), Error> {
    let asked = |k: usize, l: usize| only.is_none_or(|m| m[k] || m[l]);
    let tol = TOUCH_DISTANCE * size;
    let boxes: Vec<Aabb> = shapes.iter().map(|s| Aabb::of(&s.vertices)).collect();
    let mut order: Vec<usize> = (0..shapes.len()).collect();
    order.sort_by(|&i, &j| boxes[i].lo.x.total_cmp(&boxes[j].lo.x));
    for (n, &k) in order.iter().enumerate() {
        for &l in &order[n + 1..] {
            if boxes[l].lo.x > boxes[k].hi.x + tol {
                break;
            }
            if asked(k, l) && boxes[k].meets(&boxes[l], tol) {
                check_pair(shapes, k.min(l), k.max(l), &boxes, tol)?;
            }
        }
    }
    Ok(())
}

/// Rejects a triangle of shape `k` within `tol` of one of shape `l`.
fn check_pair(shapes: &[Shape], k: usize, l: usize, boxes: &[Aabb], tol: f64) -> Result<(), Error> {
    // Triangles of either mesh inside the other's box: (box, side, index).
    let mut items: Vec<(Aabb, usize, u32)> = Vec::new();
    for (side, (me, other)) in [(k, l), (l, k)].into_iter().enumerate() {
        let s = &shapes[me];
        for i in 0..s.triangles.len() {
            let b = Aabb::of(&s.triangle(i));
            if b.meets(&boxes[other], tol) {
                items.push((b, side, i as u32));
            }
        }
    }
    items.sort_by(|a, b| a.0.lo.x.total_cmp(&b.0.lo.x));
    let mut active: [Vec<(Aabb, u32)>; 2] = [Vec::new(), Vec::new()];
    for &(b, side, i) in &items {
        let other = 1 - side;
        active[other].retain(|(o, _)| o.hi.x + tol >= b.lo.x);
        for &(o, j) in &active[other] {
            if !b.meets(&o, tol) {
                continue;
            }
            let (ti, tj) = if side == 0 { (i, j) } else { (j, i) };
            let (sk, sl) = (&shapes[k], &shapes[l]);
            if triangles_within(sk.triangle(ti as usize), sl.triangle(tj as usize), tol) {
                return config(format!(
                    "shapes {:?} (triangle {ti}) and {:?} (triangle {tj}) touch or cross: \
                     shapes must be disjoint",
                    sk.name, sl.name
                ));
            }
        }
        active[side].push((b, i));
    }
    Ok(())
}

/// Rejects a mesh whose triangles touch or cross one another anywhere but
/// along the vertices and edges they share. With a medium, a path finds
/// the medium by the parity of the boundaries it crosses, wrong where the
/// mesh overlaps itself (two boxes given as one mesh). On any mesh, the
/// boundary terms count each silhouette edge once, so an edge lying on
/// another (a T-junction: a vertex in the middle of another triangle's
/// edge; a seam left unwelded on a face), or a triangle folded back onto
/// its neighbour, counted a silhouette twice or lost one: `rendering` and
/// `transport` read up to twice the derivative, "reliable". The test, by
/// what a pair of triangles shares (the same sweep over x as
/// [`check_pair`]):
/// - nothing: they must stay [`TOUCH_DISTANCE`] × `size` apart
///   ([`triangles_within`]);
/// - one vertex: each one's edge opposite that vertex must stay that far
///   from the other (two triangles that meet at a vertex overlap just when
///   one of those edges reaches the other triangle);
/// - an edge: they must not lie in one plane on the same side of it (a
///   fold; in one plane on either side is a flat face).
///
/// Flatland refuses a polygon that intersects itself likewise. With
/// `only`, just the meshes it marks.
pub(super) fn check_self_crossings(
    shapes: &[Shape],
    size: f64,
    only: Option<&[bool]>,
) -> Result<(), Error> {
    let tol = TOUCH_DISTANCE * size;
    for (k, s) in shapes.iter().enumerate() {
        if only.is_some_and(|m| !m[k]) {
            continue;
        }
        let mut items: Vec<(Aabb, u32)> = (0..s.triangles.len())
            .map(|i| (Aabb::of(&s.triangle(i)), i as u32))
            .collect();
        items.sort_by(|a, b| a.0.lo.x.total_cmp(&b.0.lo.x));
        let mut active: Vec<(Aabb, u32)> = Vec::new();
        for &(b, i) in &items {
            active.retain(|(o, _)| o.hi.x + tol >= b.lo.x);
            for &(o, j) in &active {
                if b.meets(&o, tol)
                    && let Some(why) = self_contact(s, i as usize, j as usize, tol)
                {
                    let (a, b) = (i.min(j), i.max(j));
                    let what = if s.medium.is_some() {
                        "a mesh with a medium must bound one region"
                    } else {
                        "a mesh's triangles may meet only at the vertices and edges they share \
                         (split the edge at the vertex on it, or weld the seam)"
                    };
                    return config(format!(
                        "shape {:?} {why} (triangles {a} and {b}): {what}",
                        s.name
                    ));
                }
            }
            active.push((b, i));
        }
    }
    Ok(())
}

/// How triangles `i` and `j` of `s` meet where they should not, if they
/// do (see [`check_self_crossings`]).
fn self_contact(s: &Shape, i: usize, j: usize, tol: f64) -> Option<&'static str> {
    let (ti, tj) = (s.triangles[i], s.triangles[j]);
    let (mut shared, mut n) = ([0usize; 3], 0);
    for (k, v) in ti.iter().enumerate() {
        if tj.contains(v) {
            shared[n] = k;
            n += 1;
        }
    }
    let (pi, pj) = (s.triangle(i), s.triangle(j));
    match shared[..n] {
        [] => triangles_within(pi, pj, tol).then_some("crosses itself"),
        [k] => {
            let v = ti[k];
            let opposite = |t: [u32; 3], p: [DVec3; 3]| {
                let m = t.iter().position(|&x| x == v).unwrap_or(0);
                (p[(m + 1) % 3], p[(m + 2) % 3])
            };
            let ((a, b), (c, d)) = (opposite(ti, pi), opposite(tj, pj));
            (segment_triangle_distance(a, b, pj) <= tol
                || segment_triangle_distance(c, d, pi) <= tol)
                .then_some("overlaps itself at a vertex")
        }
        [k, l] => {
            // The edge (a, b) and each triangle's third corner.
            let (a, b) = (pi[k], pi[l]);
            let ci = pi[3 - k - l];
            let m = (0..3).find(|&m| !ti.contains(&tj[m])).unwrap_or(0);
            let cj = pj[m];
            let n = (b - a).cross(ci - a);
            let off = n.dot(cj - a) / n.length();
            let same_side = n.dot((b - a).cross(cj - a)) > 0.0;
            (off.abs() <= tol && same_side).then_some("folds onto itself along an edge")
        }
        _ => None,
    }
}
