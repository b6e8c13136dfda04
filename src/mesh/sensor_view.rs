//! What the sensor's fixed point sees of the discontinuity edges, computed
//! once per scene: the edges that can be discontinuities from there (a
//! silhouette ring, a few of a large mesh's edges) in an edge tree of their
//! own, and, when affordable, the visible parts of each as parameter
//! intervals. The expectation method's warp at the sensor (an irradiance
//! or radiance probe, or a camera's pinhole: every path starts there) then
//! searches the small tree, and with the intervals finds its knots with no
//! shadow ray: a crossing of a fibre's plane with an edge is a knot when
//! its parameter lies in a visible interval. This is the 3D twin of
//! flatland's precomputed sensor knots (the sensor does not move). Book:
//! chapter "Three dimensions", section "A warp on the sphere".
//!
//! Why an edge's hidden part behind one triangle is one interval: with
//! `r(t) = a + t(b − a) − s` the sight line from the sensor `s` to the
//! edge's point at `t`, the point is behind the triangle when `r(t)` lies in
//! the triangle's cone from `s` (three half-spaces, each linear in `t`) and
//! the triangle's plane cuts the sight line before its end (`|r(t)·N| >
//! |(v₀ − s)·N|` with the same sign, linear in `t` too). An intersection of
//! half-lines is an interval; the visible parts are the complement of the
//! union over triangles. A triangle on the edge (its own faces) cannot hide
//! it and is skipped.
use super::edges::Edge;
use super::edges::{EdgeFacts, EdgeTree, is_discontinuity};
use crate::path::Prim;
use glam::DVec3;

/// Most edge × triangle pairs the visible intervals are computed from;
/// beyond, the warp keeps its shadow rays (a large mesh: the pairs would
/// cost more than the rays they save on a short run).
pub const MAX_PAIRS: usize = 20_000_000;

/// Up to this many edges, a scan of the list beats the tree's node tests.
pub const SCAN: usize = 64;

/// What one point sees of the discontinuity edges.
#[derive(Debug, Clone, Default)]
pub struct SensorView {
    /// The point.
    pub point: DVec3,
    /// The edges that can be discontinuities from the point (those with a
    /// visible part, when the parts are known), scanned when there are at
    /// most [`SCAN`].
    pub edges: Vec<u32>,
    /// Their tree.
    pub tree: EdgeTree,
    /// Their visible parts, if computed.
    pub visible: Option<Visible>,
    /// Per pole the warp uses at the point (fixed there: the scene's pole
    /// rules, a camera's right and up), the edges each fibre can cut.
    pub fibres: Vec<AzimuthBuckets>,
}

/// Azimuth bins around a fixed pole `p` at the sensor's point: the fibres
/// (half great circles from `p`) of one bin can only cut the edges listed
/// for it, so a fibre's knot search scans a few edges, not the ring.
///
/// Why this is exact: the fibre at azimuth `φ` is the half-plane through
/// the point bounded by the pole's line; it cuts an edge exactly when the
/// edge's projection on the plane across `p` crosses the ray at `φ`, that
/// is when `φ` lies on the short arc between its ends' azimuths (a segment
/// that does not pass through the origin subtends less than π). Each edge
/// is listed in every bin that arc meets, with a bin to spare on either
/// side against rounding; an edge passing (within rounding) through the
/// pole's line is listed everywhere.
#[derive(Debug, Clone, Default)]
pub struct AzimuthBuckets {
    /// The pole, and two unit vectors across it.
    pub p: DVec3,
    e1: DVec3,
    e2: DVec3,
    /// `items[start[b]..start[b + 1]]`: the edges of bin `b`.
    start: Vec<u32>,
    items: Vec<u32>,
}

/// Azimuth bins per pole.
const BINS: usize = 256;

/// A monotone stand-in for the angle of `(x, y)`, in `[0, 4)` (the
/// "diamond angle": a quarter turn per unit, antipodes 2 apart).
#[inline]
fn diamond(x: f64, y: f64) -> f64 {
    let a = if y >= 0.0 {
        if x >= 0.0 {
            y / (x + y)
        } else {
            1.0 - x / (y - x)
        }
    } else if x < 0.0 {
        2.0 - y / (-x - y)
    } else {
        3.0 + x / (x - y)
    };
    if a.is_finite() {
        a.rem_euclid(4.0)
    } else {
        0.0
    }
}

impl AzimuthBuckets {
    /// The bins around `p` at `s` for the edges `seen`.
    pub fn new(s: DVec3, p: DVec3, edges: &[Edge], seen: &[u32]) -> AzimuthBuckets {
        let (e1, e2) = p.any_orthonormal_pair();
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); BINS];
        let bin = |a: f64| ((a * BINS as f64 / 4.0) as usize).min(BINS - 1);
        for &i in seen {
            let e = &edges[i as usize];
            let (a, b) = (e.a - s, e.b - s);
            let (ax, ay, bx, by) = (a.dot(e1), a.dot(e2), b.dot(e1), b.dot(e2));
            // The projection's distance to the origin, against its size.
            let (dx, dy) = (bx - ax, by - ay);
            let len2 = dx * dx + dy * dy;
            let t = if len2 > 0.0 {
                (-(ax * dx + ay * dy) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let (cx, cy) = (ax + t * dx, ay + t * dy);
            let size = (ax.hypot(ay)).max(bx.hypot(by));
            if cx.hypot(cy) <= crate::path::tolerance::NEAR * size || size == 0.0 {
                lists.iter_mut().for_each(|l| l.push(i));
                continue;
            }
            let (pa, pb) = (diamond(ax, ay), diamond(bx, by));
            let (from, to) = if (pb - pa).rem_euclid(4.0) <= 2.0 {
                (pa, pb)
            } else {
                (pb, pa)
            };
            let (first, last) = (bin(from), bin(to));
            let span = (last + BINS - first) % BINS;
            for k in 0..=span + 2 {
                lists[(first + BINS - 1 + k) % BINS].push(i);
            }
        }
        let mut start = vec![0u32];
        let mut items = Vec::new();
        for l in &lists {
            items.extend_from_slice(l);
            start.push(items.len() as u32);
        }
        AzimuthBuckets {
            p,
            e1,
            e2,
            start,
            items,
        }
    }

    /// The edges the fibre through the unit direction `u` (across `p`) can
    /// cut.
    #[inline]
    pub fn candidates(&self, u: DVec3) -> &[u32] {
        let b =
            ((diamond(u.dot(self.e1), u.dot(self.e2)) * BINS as f64 / 4.0) as usize).min(BINS - 1);
        &self.items[self.start[b] as usize..self.start[b + 1] as usize]
    }
}

/// The visible parts of some edges, as intervals of their parameter.
#[derive(Debug, Clone, Default)]
pub struct Visible {
    /// Per edge of the scene, its entry in `start` (`u32::MAX`: none seen).
    entry: Vec<u32>,
    /// Per entry, its intervals: `pieces[start[i]..start[i + 1]]`.
    start: Vec<u32>,
    pieces: Vec<[f64; 2]>,
}

impl SensorView {
    /// The view from `s` of the `edges` (with their `facts` and `weights`,
    /// for the tree), occluded by the `opaque` triangles (with their
    /// primitive indices); the intervals only below [`MAX_PAIRS`]
    /// edge-triangle tests.
    pub fn new(
        s: DVec3,
        edges: &[Edge],
        facts: &[EdgeFacts],
        weights: &[f64],
        opaque: &[(Prim, [DVec3; 3])],
    ) -> SensorView {
        let seen: Vec<u32> = (0..edges.len() as u32)
            .filter(|&i| is_discontinuity(&edges[i as usize], &facts[i as usize], s))
            .collect();
        let visible = (seen.len().saturating_mul(opaque.len()) <= MAX_PAIRS)
            .then(|| Visible::new(s, edges, &seen, opaque));
        let seen: Vec<u32> = match &visible {
            Some(v) => seen
                .into_iter()
                .filter(|&i| v.entry[i as usize] != u32::MAX)
                .collect(),
            None => seen,
        };
        SensorView {
            point: s,
            tree: EdgeTree::new(edges, facts, weights, seen.clone()),
            edges: seen,
            visible,
            fibres: Vec::new(),
        }
    }
}

impl SensorView {
    /// Adds the azimuth bins of the poles `poles` (skipped without visible
    /// parts or beyond [`SCAN`] edges: the tree serves those).
    pub fn with_fibres(mut self, edges: &[Edge], poles: impl IntoIterator<Item = DVec3>) -> Self {
        if self.visible.is_some() && self.edges.len() <= SCAN {
            for p in poles {
                if !self.fibres.iter().any(|f| f.p == p) {
                    self.fibres
                        .push(AzimuthBuckets::new(self.point, p, edges, &self.edges));
                }
            }
        }
        self
    }

    /// The bins around the pole `p`, if built.
    #[inline]
    pub fn fibres(&self, p: DVec3) -> Option<&AzimuthBuckets> {
        self.fibres.iter().find(|f| f.p == p)
    }
}

impl Visible {
    fn new(s: DVec3, edges: &[Edge], seen: &[u32], opaque: &[(Prim, [DVec3; 3])]) -> Visible {
        let mut v = Visible {
            entry: vec![u32::MAX; edges.len()],
            start: vec![0],
            pieces: Vec::new(),
        };
        let mut hidden: Vec<[f64; 2]> = Vec::new();
        for &i in seen {
            let e = &edges[i as usize];
            hidden.clear();
            for (p, t) in opaque {
                if e.faces.contains(p) {
                    continue;
                }
                if let Some(h) = hidden_interval(s, e.a, e.b, t) {
                    hidden.push(h);
                }
            }
            hidden.sort_by(|x, y| x[0].total_cmp(&y[0]));
            let before = v.pieces.len();
            let mut from = 0.0;
            for h in &hidden {
                if h[0] > from {
                    v.pieces.push([from, h[0]]);
                }
                from = f64::max(from, h[1]);
            }
            if from < 1.0 {
                v.pieces.push([from, 1.0]);
            }
            if v.pieces.len() > before {
                v.entry[i as usize] = (v.start.len() - 1) as u32;
                v.start.push(v.pieces.len() as u32);
            }
        }
        v
    }

    /// Whether the point at parameter `t` of edge `edge` is seen.
    #[inline]
    pub fn sees(&self, edge: u32, t: f64) -> bool {
        let k = self.entry[edge as usize];
        if k == u32::MAX {
            return false;
        }
        self.pieces[self.start[k as usize] as usize..self.start[k as usize + 1] as usize]
            .iter()
            .any(|p| t >= p[0] && t <= p[1])
    }

    /// The visible intervals of edge `edge`.
    #[cfg(test)]
    fn pieces(&self, edge: u32) -> &[[f64; 2]] {
        let k = self.entry[edge as usize];
        if k == u32::MAX {
            return &[];
        }
        &self.pieces[self.start[k as usize] as usize..self.start[k as usize + 1] as usize]
    }
}

/// The open interval of `t ∈ [0, 1]` for which the triangle `tri` lies
/// strictly between `s` and `a + t(b − a)`, if not empty.
fn hidden_interval(s: DVec3, a: DVec3, b: DVec3, tri: &[DVec3; 3]) -> Option<[f64; 2]> {
    let (r0, d) = (a - s, b - a);
    let w = [tri[0] - s, tri[1] - s, tri[2] - s];
    let normal = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
    let depth = w[0].dot(normal);
    if depth == 0.0 {
        return None; // `s` in the triangle's plane: it hides nothing
    }
    let orient = w[0].dot(w[1].cross(w[2])).signum();
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    // Each constraint `c0 + t·c1 > 0` narrows (lo, hi).
    let mut keep = |c0: f64, c1: f64| {
        if c1 > 0.0 {
            lo = lo.max(-c0 / c1);
        } else if c1 < 0.0 {
            hi = hi.min(-c0 / c1);
        } else if c0 <= 0.0 {
            hi = f64::NEG_INFINITY;
        }
    };
    for i in 0..3 {
        let n = orient * w[(i + 1) % 3].cross(w[(i + 2) % 3]);
        keep(r0.dot(n), d.dot(n));
    }
    let sign = depth.signum();
    keep(sign * r0.dot(normal) - sign * depth, sign * d.dot(normal));
    (lo < hi).then_some([lo, hi])
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// Whether the point is hidden, by a brute-force segment test.
    fn hidden_by_rays(s: DVec3, q: DVec3, tris: &[(Prim, [DVec3; 3])], own: [Prim; 2]) -> bool {
        tris.iter().any(|(p, t)| {
            if own.contains(p) {
                return false;
            }
            let d = q - s;
            super::super::bvh::intersect(t, s, d).is_some_and(|l| l > 0.0 && l < 1.0)
        })
    }

    #[test]
    fn intervals_agree_with_shadow_rays() {
        let mut rng = crate::rng::PathRng::seed_from_u64(5);
        let mut p = |r: f64| {
            DVec3::new(
                rng.random::<f64>() * 2.0 * r - r,
                rng.random::<f64>() * 2.0 * r - r,
                rng.random::<f64>() * 2.0,
            )
        };
        let tris: Vec<(Prim, [DVec3; 3])> = (0..40)
            .map(|i| {
                // Near z = 0.5..1.5, edges beyond: many are partly hidden.
                let c = p(1.0) * DVec3::new(1.0, 1.0, 0.5) + DVec3::Z * 0.5;
                let mut corner = || c + p(0.5) * DVec3::new(1.0, 1.0, 0.1);
                (i, [corner(), corner(), corner()])
            })
            .collect();
        let edges: Vec<Edge> = (0..60)
            .map(|_| Edge {
                a: p(1.5) + DVec3::Z,
                b: p(1.5) + DVec3::Z,
                faces: [1000, crate::path::NO_PRIM],
                shape: 0,
            })
            .collect();
        let facts = vec![
            EdgeFacts {
                normals: [DVec3::Z; 2],
                always: true
            };
            edges.len()
        ];
        let s = DVec3::new(0.1, -0.2, -0.5);
        let weights = vec![1.0; edges.len()];
        let view = SensorView::new(s, &edges, &facts, &weights, &tris);
        let view = view.visible.as_ref().unwrap();
        let (mut seen, mut hidden) = (0, 0);
        for (i, e) in edges.iter().enumerate() {
            for step in 0..=200 {
                let t = step as f64 / 200.0;
                let q = e.a + (e.b - e.a) * t;
                let rays = hidden_by_rays(s, q, &tris, e.faces);
                // Off the intervals' ends, where rounding decides.
                let near_end = view
                    .pieces(i as u32)
                    .iter()
                    .any(|p| (t - p[0]).abs() < 1e-9 || (t - p[1]).abs() < 1e-9);
                if near_end {
                    continue;
                }
                let sees = view.sees(i as u32, t);
                assert_eq!(sees, !rays, "edge {i} at t = {t}");
                if rays { hidden += 1 } else { seen += 1 }
            }
        }
        assert!(seen > 1000 && hidden > 1000, "{seen} {hidden}");
    }

    /// Every edge a fibre's half-plane cuts is among its bin's candidates:
    /// random edges around the point (some passing over the pole's line,
    /// some along the pole), random poles and fibres, against the plane
    /// test itself.
    #[test]
    fn a_fibres_bin_holds_every_edge_it_cuts() {
        let mut rng = crate::rng::PathRng::seed_from_u64(8);
        let mut unit = || {
            let z = 2.0 * rng.random::<f64>() - 1.0;
            let phi = std::f64::consts::TAU * rng.random::<f64>();
            let r = (1.0 - z * z).sqrt();
            DVec3::new(r * phi.cos(), r * phi.sin(), z)
        };
        let s = DVec3::new(0.3, -0.1, 0.2);
        let mut cut = 0;
        for round in 0..20 {
            let p = unit();
            let mut edges: Vec<Edge> = (0..60)
                .map(|_| {
                    let a = s + unit() * 2.0;
                    Edge {
                        a,
                        b: a + unit() * 1.5,
                        faces: [0, crate::path::NO_PRIM],
                        shape: 0,
                    }
                })
                .collect();
            // Through the pole's line, and along the pole.
            let (c, d, v) = (s + p, unit() * 0.5, unit());
            for (a, b) in [(c + d, c - d), (s + v + p * 0.2, s + v + p * 0.7)] {
                edges.push(Edge {
                    a,
                    b,
                    faces: [0, crate::path::NO_PRIM],
                    shape: 0,
                });
            }
            let seen: Vec<u32> = (0..edges.len() as u32).collect();
            let bins = AzimuthBuckets::new(s, p, &edges, &seen);
            for _ in 0..500 {
                let w = unit();
                let perp = w - p * w.dot(p);
                if perp.length() < 1e-9 {
                    continue;
                }
                let u = perp.normalize();
                let m = p.cross(u);
                let candidates = bins.candidates(u);
                for (i, e) in edges.iter().enumerate() {
                    let (sa, sb) = ((e.a - s).dot(m), (e.b - s).dot(m));
                    if sa * sb >= 0.0 {
                        continue;
                    }
                    let t = sa / (sa - sb);
                    let q = e.a + (e.b - e.a) * t;
                    if (q - s).dot(u) <= 0.0 {
                        continue;
                    }
                    cut += 1;
                    assert!(
                        candidates.contains(&(i as u32)),
                        "round {round}: edge {i} is cut by the fibre {u} but not listed"
                    );
                }
            }
        }
        assert!(cut > 10_000, "{cut} cuts");
    }
}
