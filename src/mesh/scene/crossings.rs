//! Meshes that cross or touch: a sweep-and-prune broad phase over the
//! meshes' boxes and then over their triangles, and the exact f64 test of
//! each close pair ([`triangles_within`]).
use super::Shape;
use super::geometry::triangles_within;
use super::validate::{TOUCH_DISTANCE, bounds, config};
use crate::error::Error;
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
/// pass over its triangles per neighbour.
pub(super) fn check_crossings(shapes: &[Shape], size: f64) -> Result<(), Error> {
    let tol = TOUCH_DISTANCE * size;
    let boxes: Vec<Aabb> = shapes.iter().map(|s| Aabb::of(&s.vertices)).collect();
    let mut order: Vec<usize> = (0..shapes.len()).collect();
    order.sort_by(|&i, &j| boxes[i].lo.x.total_cmp(&boxes[j].lo.x));
    for (n, &k) in order.iter().enumerate() {
        for &l in &order[n + 1..] {
            if boxes[l].lo.x > boxes[k].hi.x + tol {
                break;
            }
            if boxes[k].meets(&boxes[l], tol) {
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

/// Rejects a mesh with a medium whose triangles cross or touch one another
/// (two boxes given as one mesh): a path finds the medium by the parity of
/// the boundaries it crosses, which is wrong where the mesh overlaps
/// itself. The same sweep over x as [`check_pair`], within one mesh;
/// triangles that share a vertex are the mesh's own contact, not tested.
/// Flatland refuses a polygon that intersects itself likewise.
pub(super) fn check_self_crossings(shapes: &[Shape], size: f64) -> Result<(), Error> {
    let tol = TOUCH_DISTANCE * size;
    for s in shapes.iter().filter(|s| s.medium.is_some()) {
        let mut items: Vec<(Aabb, u32)> = (0..s.triangles.len())
            .map(|i| (Aabb::of(&s.triangle(i)), i as u32))
            .collect();
        items.sort_by(|a, b| a.0.lo.x.total_cmp(&b.0.lo.x));
        let mut active: Vec<(Aabb, u32)> = Vec::new();
        for &(b, i) in &items {
            active.retain(|(o, _)| o.hi.x + tol >= b.lo.x);
            let ti = s.triangles[i as usize];
            for &(o, j) in &active {
                let tj = s.triangles[j as usize];
                if !b.meets(&o, tol) || ti.iter().any(|v| tj.contains(v)) {
                    continue;
                }
                if triangles_within(s.triangle(i as usize), s.triangle(j as usize), tol) {
                    let (a, b) = (i.min(j), i.max(j));
                    return config(format!(
                        "shape {:?} crosses itself (triangles {a} and {b}): a mesh with a \
                         medium must bound one region",
                        s.name
                    ));
                }
            }
            active.push((b, i));
        }
    }
    Ok(())
}
