//! A hierarchy over the edges of opaque meshes that answers, from a point
//! `x`, which edges can be discontinuities of the integrand over directions
//! there: silhouettes (the edge's two faces face `x` differently), open
//! edges, and creases of reflectors. Each node bounds its edges' positions
//! (a box) and their faces' normals (a cone); when every face in the node
//! faces `x` the same way, the node holds no silhouette and is culled
//! (Sander et al. 2000's silhouette cones; redner's edge tree uses the same
//! idea in Hough space).
//!
//! Two queries, both `O(log n)`-ish on a mesh whose silhouette from `x` is a
//! thin band:
//!
//! - [`EdgeTree::sample`]: an edge drawn by descending the tree, each child
//!   chosen, unless it is culled, half the time in proportion to an
//!   estimate of its edges' contribution seen from `x` (their total weight,
//!   length × dihedral turn, over the squared distance to the node: an
//!   edge's boundary term is its arc on the sphere, ∝ length / distance,
//!   times the speed of that arc, ∝ 1 / distance; in a leaf each edge's
//!   weight over its squared distance) and half the time by weight alone,
//!   a defensive mixture; the probability of the edge drawn is the
//!   product of the choices, exact,
//!   so the boundary terms stay unbiased (a dead end, both children culled,
//!   draws nothing: only edges that cannot be discontinuities lose their
//!   share);
//! - [`EdgeTree::crossings`]: the discontinuity edges that cross a plane
//!   through `x` on one side of a line, for the fibre warp's knots.
//!
//! Book: chapter "Three dimensions", section "Silhouette edges".
use crate::path::{NO_PRIM, Prim};
use glam::DVec3;

/// An edge of an opaque mesh: where the integrand over directions seen from
/// a point can jump (a silhouette, an open edge, or a crease between two
/// faces of different normals).
#[derive(Debug, Clone, Copy)]
pub struct Edge {
    /// Its end points.
    pub a: DVec3,
    /// Second end.
    pub b: DVec3,
    /// The triangles (global primitive indices) on it; the second is
    /// [`NO_PRIM`] for an open edge.
    pub faces: [Prim; 2],
    /// The mesh it belongs to.
    pub shape: u32,
}

/// Most edges in a leaf.
const LEAF: usize = 4;

/// A node: the box and normal cone of its edges, their total weight, and
/// its children (`count == 0`) or its edges (`order[first..first+count]`).
#[derive(Debug, Clone, Copy)]
struct Node {
    lo: DVec3,
    hi: DVec3,
    /// Unit axis of the cone of face normals.
    axis: DVec3,
    /// Cosine and sine of its half-angle (≥ π/2: no bound).
    cos_half: f64,
    sin_half: f64,
    /// The half-angle is π/2 or more.
    unbounded: bool,
    /// Some edge inside is a discontinuity from everywhere (open edge, or
    /// crease of a reflector).
    always: bool,
    weight: f64,
    /// Left child (right = left + 1) or first edge.
    first: u32,
    count: u32,
}

/// An edge's estimated contribution seen from `x`, as a node's: its weight
/// over the squared distance to its midpoint (at least half its length).
#[inline]
fn edge_importance(e: &Edge, weight: f64, x: DVec3) -> f64 {
    let d2 = (0.5 * (e.a + e.b) - x)
        .length_squared()
        .max(0.25 * (e.b - e.a).length_squared());
    weight / d2
}

/// A leaf's edges' importances seen from `x`, by distance and by weight
/// (0 for an edge that is no discontinuity from `x`), and their totals: what
/// [`EdgeTree::sample`] draws a leaf's edge by.
#[inline]
#[allow(clippy::type_complexity)]
fn leaf_importances(
    ids: &[u32],
    edges: &[Edge],
    facts: &[EdgeFacts],
    weights: &[f64],
    x: DVec3,
) -> ([f64; LEAF], [f64; LEAF], f64, f64) {
    let (mut by_near, mut by_weight) = ([0.0; LEAF], [0.0; LEAF]);
    for (k, &e) in ids.iter().enumerate() {
        if is_discontinuity(&edges[e as usize], &facts[e as usize], x) {
            by_weight[k] = weights[e as usize];
            by_near[k] = edge_importance(&edges[e as usize], weights[e as usize], x);
        }
    }
    let (t_near, t_weight): (f64, f64) = (by_near.iter().sum(), by_weight.iter().sum());
    (by_near, by_weight, t_near, t_weight)
}

/// Per edge, what the tree needs: its faces' normals and whether it is
/// always a discontinuity.
#[derive(Debug, Clone, Copy)]
pub struct EdgeFacts {
    /// The faces' unit normals (the second equals the first on an open
    /// edge).
    pub normals: [DVec3; 2],
    /// Open edge, or crease of a reflector.
    pub always: bool,
}

/// The hierarchy over a subset of a scene's edges.
#[derive(Debug, Clone, Default)]
pub struct EdgeTree {
    nodes: Vec<Node>,
    /// Edge indices in leaf order.
    order: Vec<u32>,
    /// Per edge index, its place in `order` (`u32::MAX`: not in the tree).
    place: Vec<u32>,
}

/// Whether edge `e` (with `facts`) can be a discontinuity seen from `x`.
#[inline]
pub fn is_discontinuity(e: &Edge, facts: &EdgeFacts, x: DVec3) -> bool {
    if facts.always || e.faces[1] == NO_PRIM {
        return true;
    }
    let r = x - e.a;
    let (s0, s1) = (facts.normals[0].dot(r), facts.normals[1].dot(r));
    // Grazing (a face's plane through x) counts: conservative.
    !((s0 > 0.0 && s1 > 0.0) || (s0 < 0.0 && s1 < 0.0))
}

/// The node over the edges `ids` (its box, normal cone and weight), as a
/// leaf holding them from place 0.
fn node_of(ids: &[u32], edges: &[Edge], facts: &[EdgeFacts], weights: &[f64]) -> Node {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    let mut sum = DVec3::ZERO;
    let mut always = false;
    let mut weight = 0.0;
    for &i in ids {
        let e = &edges[i as usize];
        lo = lo.min(e.a).min(e.b);
        hi = hi.max(e.a).max(e.b);
        let f = &facts[i as usize];
        sum += f.normals[0] + f.normals[1];
        always |= f.always || e.faces[1] == NO_PRIM;
        weight += weights[i as usize];
    }
    let axis = sum.normalize_or_zero();
    // The cone's half-angle by its cosine, the least n·axis (no acos per
    // normal: the build runs over every edge at every level).
    let cos_half = if axis == DVec3::ZERO {
        -1.0
    } else {
        ids.iter()
            .flat_map(|&i| facts[i as usize].normals)
            .map(|n| n.dot(axis).clamp(-1.0, 1.0))
            .fold(1.0, f64::min)
    };
    Node {
        lo,
        hi,
        axis,
        cos_half,
        sin_half: (1.0 - cos_half * cos_half).max(0.0).sqrt(),
        unbounded: cos_half <= 0.0,
        always,
        weight,
        first: 0,
        count: ids.len() as u32,
    }
}

impl EdgeTree {
    /// The tree over the edges `ids` of `edges`.
    pub fn new(edges: &[Edge], facts: &[EdgeFacts], weights: &[f64], ids: Vec<u32>) -> EdgeTree {
        let mut tree = EdgeTree {
            nodes: Vec::new(),
            order: ids,
            place: Vec::new(),
        };
        if tree.order.is_empty() {
            return tree;
        }
        tree.nodes.push(Node {
            lo: DVec3::ZERO,
            hi: DVec3::ZERO,
            axis: DVec3::Z,
            cos_half: 1.0,
            sin_half: 0.0,
            unbounded: false,
            always: false,
            weight: 0.0,
            first: 0,
            count: 0,
        });
        let n = tree.order.len();
        tree.build(0, 0, n, edges, facts, weights);
        tree.index_places();
        tree
    }

    /// Fills `place` from `order`.
    fn index_places(&mut self) {
        let last = self.order.iter().max().map_or(0, |&i| i as usize + 1);
        self.place = vec![u32::MAX; last];
        for (k, &i) in self.order.iter().enumerate() {
            self.place[i as usize] = k as u32;
        }
    }

    /// The edges in the tree, in leaf order.
    #[inline]
    pub fn edges(&self) -> &[u32] {
        &self.order
    }

    /// The place of edge `e` in [`EdgeTree::edges`], if it is in the tree.
    #[inline]
    pub fn place(&self, e: u32) -> Option<usize> {
        match self.place.get(e as usize) {
            Some(&k) if k != u32::MAX => Some(k as usize),
            _ => None,
        }
    }

    fn build(
        &mut self,
        node: usize,
        start: usize,
        end: usize,
        edges: &[Edge],
        facts: &[EdgeFacts],
        weights: &[f64],
    ) {
        let mut this = node_of(&self.order[start..end], edges, facts, weights);
        this.first = start as u32;
        if end - start > LEAF {
            // Median split on the longest axis of the midpoints' box.
            let k = (this.hi - this.lo).max_position();
            let mid = |i: &u32| {
                let e = &edges[*i as usize];
                (e.a + e.b)[k]
            };
            let half = (end - start) / 2;
            self.order[start..end].select_nth_unstable_by(half, |a, b| mid(a).total_cmp(&mid(b)));
            let left = self.nodes.len();
            this.first = left as u32;
            this.count = 0;
            self.nodes[node] = this;
            let blank = self.nodes[node];
            self.nodes.push(blank);
            self.nodes.push(blank);
            self.build(left, start, start + half, edges, facts, weights);
            self.build(left + 1, start + half, end, edges, facts, weights);
        } else {
            self.nodes[node] = this;
        }
    }

    /// The tree over the union of disjoint `parts`, each a tree built by
    /// [`EdgeTree::new`] over edges numbered from 0 and here shifted by its
    /// offset into `edges`: the parts' nodes are copied whole (one mesh's
    /// tree is built once and serves every scene that holds the mesh
    /// unmoved), under top nodes that split the parts at the median of their
    /// boxes' centres on the longest axis, as [`EdgeTree::new`] splits
    /// edges. One part gives exactly the tree [`EdgeTree::new`] builds over
    /// its shifted edges.
    pub fn join(
        parts: &[(&EdgeTree, u32)],
        edges: &[Edge],
        facts: &[EdgeFacts],
        weights: &[f64],
    ) -> EdgeTree {
        let parts: Vec<(&EdgeTree, u32)> = parts
            .iter()
            .copied()
            .filter(|(t, _)| !t.nodes.is_empty())
            .collect();
        let mut tree = EdgeTree::default();
        if parts.is_empty() {
            return tree;
        }
        tree.nodes.push(parts[0].0.nodes[0]);
        let mut chosen: Vec<usize> = (0..parts.len()).collect();
        tree.join_parts(0, &mut chosen, &parts, edges, facts, weights);
        tree.index_places();
        tree
    }

    /// Node `node` over the parts `chosen` (see [`EdgeTree::join`]).
    fn join_parts(
        &mut self,
        node: usize,
        chosen: &mut [usize],
        parts: &[(&EdgeTree, u32)],
        edges: &[Edge],
        facts: &[EdgeFacts],
        weights: &[f64],
    ) {
        if let [one] = chosen {
            let (part, offset) = parts[*one];
            let start = self.order.len() as u32;
            self.order.extend(part.order.iter().map(|&i| i + offset));
            // The part's node i ≥ 1 goes to base + i − 1, its root to `node`.
            let base = self.nodes.len() as u32;
            let shift = |n: Node| Node {
                first: if n.count > 0 {
                    n.first + start
                } else {
                    base + n.first - 1
                },
                ..n
            };
            self.nodes[node] = shift(part.nodes[0]);
            self.nodes.extend(part.nodes[1..].iter().map(|&n| shift(n)));
            return;
        }
        let ids: Vec<u32> = chosen
            .iter()
            .flat_map(|&p| parts[p].0.order.iter().map(move |&i| i + parts[p].1))
            .collect();
        let mut this = node_of(&ids, edges, facts, weights);
        let k = (this.hi - this.lo).max_position();
        let centre = |p: &usize| {
            let root = &parts[*p].0.nodes[0];
            (root.lo + root.hi)[k]
        };
        chosen.sort_by(|a, b| centre(a).total_cmp(&centre(b)).then(a.cmp(b)));
        let half = chosen.len() / 2;
        let left = self.nodes.len();
        this.first = left as u32;
        this.count = 0;
        self.nodes[node] = this;
        self.nodes.push(this);
        self.nodes.push(this);
        let (l, r) = chosen.split_at_mut(half);
        self.join_parts(left, l, parts, edges, facts, weights);
        self.join_parts(left + 1, r, parts, edges, facts, weights);
    }

    /// Whether node `i` may hold a discontinuity seen from `x` (false when
    /// every face in it faces `x` the same way).
    #[inline]
    fn open(&self, i: usize, x: DVec3) -> bool {
        let n = &self.nodes[i];
        if n.always || n.unbounded {
            return true;
        }
        let c = 0.5 * (n.lo + n.hi);
        let radius = 0.5 * (n.hi - n.lo).length();
        let r = x - c;
        let d = r.length();
        if d <= radius {
            return true;
        }
        // The spread s = asin(R/d) + half-angle; the angle φ between the
        // cone's axis and the direction to x. Every face faces x the same
        // way if φ + s < π/2 or φ − s > π/2, i.e. cos(φ + s) > 0 or
        // cos(φ − s) < 0 (s < π/2 keeps both in the range where that holds).
        let (sin_b, cos_b) = (radius / d, (1.0 - (radius / d).powi(2)).max(0.0).sqrt());
        let cos_s = cos_b * n.cos_half - sin_b * n.sin_half;
        if cos_s <= 0.0 {
            return true;
        }
        let sin_s = sin_b * n.cos_half + cos_b * n.sin_half;
        let cos_phi = (r / d).dot(n.axis).clamp(-1.0, 1.0);
        let sin_phi = (1.0 - cos_phi * cos_phi).max(0.0).sqrt();
        let margin = crate::path::tolerance::CULL_PAD;
        let front = cos_phi * cos_s - sin_phi * sin_s > margin;
        let back = cos_phi * cos_s + sin_phi * sin_s < -margin;
        !(front || back)
    }

    /// A node's estimated contribution seen from `x`: its edges' weight
    /// over the squared distance to its centre, the distance at least half
    /// its box's diagonal (inside or near the box the estimate is only
    /// bounded, not sharp: it stays positive and finite).
    #[inline]
    fn importance(&self, i: usize, x: DVec3) -> f64 {
        let n = &self.nodes[i];
        let centre = 0.5 * (n.lo + n.hi);
        let d2 = (x - centre)
            .length_squared()
            .max(0.25 * (n.hi - n.lo).length_squared());
        n.weight / d2
    }

    /// An edge drawn from `x` with `u ∈ [0, 1)`: its index, the probability
    /// it was drawn with, and the uniform number left over (for the point on
    /// it). `None` if the tree is culled away.
    #[inline]
    pub fn sample(
        &self,
        x: DVec3,
        mut u: f64,
        edges: &[Edge],
        facts: &[EdgeFacts],
        weights: &[f64],
    ) -> Option<(u32, f64, f64)> {
        if self.nodes.is_empty() || !self.open(0, x) {
            return None;
        }
        // Half the draws by the near estimate, half by weight alone (a
        // defensive mixture: no edge's probability falls below half what
        // weight alone gave it, so no parameter's variance more than
        // doubles where distance misleads); the probability is the
        // mixture's, both strategies' products along the one path to the
        // edge.
        let near = u < 0.5;
        u = if near { 2.0 * u } else { 2.0 * u - 1.0 }.min(1.0 - f64::EPSILON);
        let mut i = 0;
        let (mut p_near, mut p_weight) = (1.0, 1.0);
        loop {
            let n = self.nodes[i];
            if n.count > 0 {
                let ids = &self.order[n.first as usize..(n.first + n.count) as usize];
                let (by_near, by_weight, t_near, t_weight) =
                    leaf_importances(ids, edges, facts, weights, x);
                if !(t_near > 0.0 && t_near.is_finite() && t_weight > 0.0) {
                    return None;
                }
                let (chosen, total) = if near {
                    (&by_near, t_near)
                } else {
                    (&by_weight, t_weight)
                };
                let s = (u * total).min(total * (1.0 - f64::EPSILON));
                let mut acc = 0.0;
                for (k, &e) in ids.iter().enumerate() {
                    let w = chosen[k];
                    if w <= 0.0 {
                        continue;
                    }
                    if s < acc + w || acc + w >= total {
                        let rest = ((s - acc) / w).clamp(0.0, 1.0 - f64::EPSILON);
                        let p = 0.5
                            * (p_near * by_near[k] / t_near + p_weight * by_weight[k] / t_weight);
                        return Some((e, p, rest));
                    }
                    acc += w;
                }
                return None;
            }
            let (l, r) = (n.first as usize, n.first as usize + 1);
            let (near_l, weight_l) = self.left_shares(l, r, x)?;
            let pl = if near { near_l } else { weight_l };
            if u < pl {
                u /= pl;
                p_near *= near_l;
                p_weight *= weight_l;
                i = l;
            } else {
                u = ((u - pl) / (1.0 - pl)).min(1.0 - f64::EPSILON);
                p_near *= 1.0 - near_l;
                p_weight *= 1.0 - weight_l;
                i = r;
            }
        }
    }

    /// The left child's share of a descent through the children `l` and
    /// `r` seen from `x`, under each half of the mixture (by distance, by
    /// weight), a culled child counting 0; `None` when both are culled or
    /// the estimates are degenerate (a dead end). What
    /// [`EdgeTree::sample`] chooses by.
    #[inline]
    fn left_shares(&self, l: usize, r: usize, x: DVec3) -> Option<(f64, f64)> {
        let (open_l, open_r) = (self.open(l, x), self.open(r, x));
        let pair = |f: &dyn Fn(usize) -> f64| {
            (
                if open_l { f(l) } else { 0.0 },
                if open_r { f(r) } else { 0.0 },
            )
        };
        let (nl, nr) = pair(&|c| self.importance(c, x));
        let (wl, wr) = pair(&|c| self.nodes[c].weight);
        let (t_near, t_weight) = (nl + nr, wl + wr);
        if !(t_near > 0.0 && t_near.is_finite() && t_weight > 0.0) {
            return None;
        }
        Some((nl / t_near, wl / t_weight))
    }

    /// Calls `f` with every discontinuity edge seen from `x` that may cross
    /// the plane through `x` with unit normal `m` where `(q − x)·side > 0`.
    #[inline]
    pub fn crossings(
        &self,
        x: DVec3,
        m: DVec3,
        side: DVec3,
        edges: &[Edge],
        facts: &[EdgeFacts],
        mut f: impl FnMut(u32),
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = [0u32; 128];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let i = stack[top] as usize;
            let n = &self.nodes[i];
            let c = 0.5 * (n.lo + n.hi);
            let h = 0.5 * (n.hi - n.lo);
            let reach = |v: DVec3| {
                (c - x).dot(v).abs()
                    <= h.dot(v.abs()) * (1.0 + crate::path::tolerance::COORDINATE_PAD) + 1e-300
            };
            let ahead = (c - x).dot(side) + h.dot(side.abs()) >= 0.0;
            if !reach(m) || !ahead || !self.open(i, x) {
                continue;
            }
            if n.count > 0 {
                for &e in &self.order[n.first as usize..(n.first + n.count) as usize] {
                    if is_discontinuity(&edges[e as usize], &facts[e as usize], x) {
                        f(e);
                    }
                }
            } else if top + 2 <= stack.len() {
                stack[top] = n.first;
                stack[top + 1] = n.first + 1;
                top += 2;
            } else {
                // Deeper than the stack (not seen: median splits give depth
                // log2(n/4)): visit the subtree's edges directly.
                self.leaves_under(i, &mut |e| {
                    if is_discontinuity(&edges[e as usize], &facts[e as usize], x) {
                        f(e);
                    }
                });
            }
        }
    }

    fn leaves_under(&self, i: usize, f: &mut impl FnMut(u32)) {
        let n = self.nodes[i];
        if n.count > 0 {
            for &e in &self.order[n.first as usize..(n.first + n.count) as usize] {
                f(e);
            }
        } else {
            self.leaves_under(n.first as usize, f);
            self.leaves_under(n.first as usize + 1, f);
        }
    }
}

#[cfg(test)]
pub(super) mod tests;
