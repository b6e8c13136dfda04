//! A bounding-box tree over the corners of opaque shapes, answering "which
//! corners lie inside this triangle": the expectation method's warp asks it
//! for the nearest visible corner on either side of a sampled direction in
//! scenes with many corners (book: chapter "Flatland", section "Where the
//! methods fail", *Many corners*).
//!
//! Why a triangle: from a vertex `x`, let the sampled direction first hit an
//! opaque segment at `p`, and let `e` be that segment's end on one side.
//! Turning from `x→p` toward `x→e`, the first visible corner is `e` itself
//! or the corner of smallest angle strictly inside the triangle `x p e`:
//! a segment blocking the sight line to a corner `c` in the triangle cannot
//! cross `x p` (the ray reaches `p` unobstructed) nor `p e` (segments do not
//! cross), nor `x c` twice, so one of its ends lies in the triangle at a
//! smaller angle than `c`. The smallest-angle corner there is thus visible,
//! and no shadow ray is needed.
//!
//! Why a tree and not a uniform grid: the corners of a scene lie on its
//! curves, not over its area. A grid sized by the area holds hundreds of
//! corners in each cell a curve crosses (the 10⁴-segment vault: about 70),
//! and the thin triangles of a warp query meet such cells at both ends. A
//! tree's boxes shrink with the corners they hold, so a query tests the few
//! leaves the triangle really meets: O(log n) boxes.
use super::geometry::cross;
use glam::DVec2;

/// Most corners in a leaf.
const LEAF: usize = 8;

/// Deepest tree a query's fixed stack holds: median splits halve the
/// corners, so 2⁶⁰ corners would be needed to exceed it.
const DEPTH: usize = 64;

/// Corners in a binary tree of boxes (median splits along the longer side),
/// for triangle queries.
#[derive(Debug, Clone)]
pub struct CornerTree {
    /// The corners' bounding box.
    lo: DVec2,
    hi: DVec2,
    /// Depth-first: a node's left child follows it.
    nodes: Vec<Node>,
    /// Corner indices, each leaf's a contiguous run.
    items: Vec<u32>,
}

#[derive(Debug, Clone, Copy)]
struct Node {
    /// The box of the node's corners, padded (see [`CornerTree::new`]).
    lo: DVec2,
    hi: DVec2,
    /// A leaf's run `items[start..end]`; an inner node's right child in
    /// `end` (`start == u32::MAX`).
    start: u32,
    end: u32,
}

impl CornerTree {
    /// The tree over `corners`.
    pub fn new(corners: &[DVec2]) -> CornerTree {
        let mut lo = DVec2::splat(f64::INFINITY);
        let mut hi = DVec2::splat(f64::NEG_INFINITY);
        for &c in corners {
            lo = lo.min(c);
            hi = hi.max(c);
        }
        // Boxes are padded far beyond the rounding of the separation tests
        // (cross products, relative error ~1e-16), so a corner inside a
        // triangle is never culled with its box.
        let pad = crate::path::tolerance::CULL_PAD
            * (hi - lo)
                .max_element()
                .max(lo.abs().max(hi.abs()).max_element());
        let mut tree = CornerTree {
            lo,
            hi,
            nodes: Vec::with_capacity(2 * corners.len() / LEAF + 1),
            items: (0..corners.len() as u32).collect(),
        };
        if !corners.is_empty() {
            tree.build(corners, 0, corners.len(), pad);
        }
        tree
    }

    fn build(&mut self, corners: &[DVec2], start: usize, end: usize, pad: f64) -> usize {
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for &i in &self.items[start..end] {
            lo = lo.min(corners[i as usize]);
            hi = hi.max(corners[i as usize]);
        }
        let at = self.nodes.len();
        self.nodes.push(Node {
            lo: lo - pad,
            hi: hi + pad,
            start: start as u32,
            end: end as u32,
        });
        if end - start > LEAF {
            let axis = usize::from(hi.y - lo.y > hi.x - lo.x);
            let mid = (start + end) / 2;
            self.items[start..end].select_nth_unstable_by(mid - start, |&a, &b| {
                corners[a as usize][axis].total_cmp(&corners[b as usize][axis])
            });
            self.build(corners, start, mid, pad);
            let right = self.build(corners, mid, end, pad);
            self.nodes[at].start = u32::MAX;
            self.nodes[at].end = right as u32;
        }
        at
    }

    /// The corners' bounding box.
    pub fn bounds(&self) -> (DVec2, DVec2) {
        (self.lo, self.hi)
    }

    /// Calls `f` with the index of every corner in the leaves whose boxes
    /// the triangle `a b c` meets (a superset of the corners strictly
    /// inside it; the caller tests).
    pub fn near_triangle(&self, a: DVec2, b: DVec2, c: DVec2, mut f: impl FnMut(u32)) {
        if self.nodes.is_empty() {
            return;
        }
        let query = Triangle::new(a, b, c);
        let mut stack = [0u32; DEPTH];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = self.nodes[stack[top] as usize];
            if query.misses(node.lo, node.hi) {
                continue;
            }
            if node.start == u32::MAX {
                let at = stack[top] as usize;
                stack[top] = node.end;
                stack[top + 1] = at as u32 + 1;
                top += 2;
            } else {
                for &i in &self.items[node.start as usize..node.end as usize] {
                    f(i);
                }
            }
        }
    }
}

/// A query triangle with what the box test needs: its bounding box, and
/// each edge with the side of it the triangle lies on.
#[derive(Debug, Clone, Copy)]
struct Triangle {
    lo: DVec2,
    hi: DVec2,
    edges: [(DVec2, DVec2, f64); 3],
}

impl Triangle {
    fn new(a: DVec2, b: DVec2, c: DVec2) -> Triangle {
        Triangle {
            lo: a.min(b).min(c),
            hi: a.max(b).max(c),
            edges: [(a, b - a, c), (b, c - b, a), (c, a - c, b)]
                .map(|(p, d, r)| (p, d, cross(d, r - p))),
        }
    }

    /// Whether the box `lo..hi` lies apart from the triangle: beyond its
    /// bounding box or wholly on the far side of one of its edge lines.
    #[inline]
    fn misses(&self, lo: DVec2, hi: DVec2) -> bool {
        if lo.x > self.hi.x || hi.x < self.lo.x || lo.y > self.hi.y || hi.y < self.lo.y {
            return true;
        }
        self.edges.iter().any(|&(p, d, side)| {
            // cross(d, q − p) is linear in q: its extremes over the box are
            // at the corners the signs of d pick.
            let (ylo, yhi) = if d.x >= 0.0 {
                (lo.y, hi.y)
            } else {
                (hi.y, lo.y)
            };
            let (xlo, xhi) = if d.y >= 0.0 {
                (hi.x, lo.x)
            } else {
                (lo.x, hi.x)
            };
            let max = d.x * (yhi - p.y) - d.y * (xhi - p.x);
            let min = d.x * (ylo - p.y) - d.y * (xlo - p.x);
            (side > 0.0 && max < 0.0) || (side < 0.0 && min > 0.0)
        })
    }
}

/// Whether `q` lies strictly inside the triangle `a b c` (either
/// orientation).
#[inline]
pub fn inside(a: DVec2, b: DVec2, c: DVec2, q: DVec2) -> bool {
    let d1 = cross(b - a, q - a);
    let d2 = cross(c - b, q - b);
    let d3 = cross(a - c, q - c);
    (d1 > 0.0 && d2 > 0.0 && d3 > 0.0) || (d1 < 0.0 && d2 < 0.0 && d3 < 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    #[test]
    fn triangle_queries_find_every_corner_inside() {
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(3);
        let corners: Vec<DVec2> = (0..5000)
            .map(|_| DVec2::new(rng.random::<f64>() * 4.0 - 1.0, rng.random::<f64>() * 2.0))
            .collect();
        let grid = CornerTree::new(&corners);
        for _ in 0..300 {
            let mut p = || {
                DVec2::new(
                    rng.random::<f64>() * 6.0 - 2.0,
                    rng.random::<f64>() * 3.0 - 0.5,
                )
            };
            let (a, b, c) = (p(), p(), p());
            agrees_with_brute_force(&grid, &corners, [a, b, c]);
        }
    }

    /// Corners on curves (the case the tree is for: a wavy arc of 10⁴
    /// corners, and a straight run whose boxes have no height) against thin
    /// triangles from a corner to far points, as the warp asks.
    #[test]
    fn thin_triangles_over_curves_find_every_corner_inside() {
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(5);
        let mut corners: Vec<DVec2> = (0..=10_000)
            .map(|i| {
                let a = 0.1 + (std::f64::consts::PI - 0.2) * i as f64 / 10_000.0;
                let r = 3.0 + 0.05 * (40.0 * a).sin();
                DVec2::new(r * a.cos(), r * a.sin())
            })
            .collect();
        corners.extend((0..500).map(|i| DVec2::new(-1.0 + i as f64 / 250.0, 1.0)));
        corners.push(corners[17]); // a repeated corner
        for scale in [1.0, 1e-40, 1e40] {
            let corners: Vec<DVec2> = corners.iter().map(|&c| c * scale).collect();
            let checked = thin_triangles(&corners, &mut rng);
            assert!(
                checked > 1000,
                "the triangles held {checked} corners at {scale}"
            );
        }
    }

    /// Brute force against the tree for 2000 thin triangles from a corner:
    /// how many corners they held.
    fn thin_triangles(corners: &[DVec2], rng: &mut rand_xoshiro::Xoshiro256PlusPlus) -> usize {
        let tree = CornerTree::new(corners);
        let size = corners
            .iter()
            .fold(0.0f64, |m, c| m.max(c.abs().max_element()));
        let mut checked = 0;
        for _ in 0..2000 {
            let a = corners[rng.random_range(0..corners.len())];
            let b = corners[rng.random_range(0..corners.len())];
            let spread = [1e-3, 1e-1, 1.0][rng.random_range(0..3)] * size / 3.0;
            let c = b + DVec2::new(rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5) * spread;
            checked += agrees_with_brute_force(&tree, corners, [a, b, c]);
        }
        checked
    }

    /// The corners the tree's query finds strictly inside the triangle are
    /// those a scan finds; how many.
    fn agrees_with_brute_force(
        tree: &CornerTree,
        corners: &[DVec2],
        [a, b, c]: [DVec2; 3],
    ) -> usize {
        let mut found = Vec::new();
        tree.near_triangle(a, b, c, |i| {
            if inside(a, b, c, corners[i as usize]) {
                found.push(i)
            }
        });
        found.sort();
        let all: Vec<u32> = (0..corners.len() as u32)
            .filter(|&i| inside(a, b, c, corners[i as usize]))
            .collect();
        assert_eq!(found, all, "triangle {a} {b} {c}");
        all.len()
    }
}
