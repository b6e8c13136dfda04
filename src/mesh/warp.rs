//! The expectation method's warp on the sphere of directions: a family of
//! flatland warps along half great circles ("fibres") from a pole `p` to
//! `−p`.
//!
//! The field is `V(η) = Ω × η + α(η) e_θ(η)`: the frame's rotation `Ω`
//! plus a component along the fibre (`e_θ`, the direction of growing polar
//! angle θ from `p`). Along each fibre, `α` is piecewise linear in θ between
//! *knots*: the poles and the lobe's horizon (where `α = 0`: they move with
//! the frame) and the points where the fibre's plane (through the vertex
//! `x`, `p` and `η`) cuts a visible edge of an opaque mesh, with `α` the
//! rate at which that crossing slides along the fibre when the edge moves
//! relative to the frame. Only the knots nearest to η on either side are
//! needed, found by a scan of the edges and a shadow ray per candidate.
//!
//! Why this is a valid warp: the domain-deformation identity
//! `d/dπ ∫ f = ∫ (∇f·V + f div V)` needs `V·n` to equal the normal velocity
//! of every curve where `f` jumps, and `V·n` to be continuous elsewhere.
//! Every visible discontinuity that a fibre crosses is a knot of that fibre,
//! so `V·n` is right there. Where the set of knots changes from fibre to
//! fibre (an edge ends, a crossing is hidden), `V` jumps *across a fibre*,
//! but `V` is tangent to the fibres, so its normal component does not jump.
//! The divergence on the unit sphere is `∂α/∂θ + α cot θ`.
//!
//! The pole: for a translation's slots, the translation's direction (every
//! fibre plane then holds the velocity, so the two crossings of a
//! silhouette's vertex slide alike and no knots with different rates meet
//! there); for the other slots a pseudo-random direction fixed by the
//! vertex's position, so no edge of a scene lies along the fibres by
//! construction (an edge exactly on a fibre could not be moved by `V`;
//! nearly on one, `α` is large: one of the method's heavy tails). One field
//! per pole rule ([`PoleRule`]), each with its own knot search. Book: chapter "Three dimensions",
//! section "A warp on the sphere".
use super::lobe::SpaceLobe;
use super::space::{Edge, Space};
use crate::path::NO_PRIM;
use crate::path::walk::Vertex;
use glam::DVec3;
use std::f64::consts::PI;

/// A knot of a fibre: its polar angle (and cosine) and, for an edge
/// crossing, the crossing.
#[derive(Debug, Clone, Copy)]
pub struct FibreKnot {
    /// The cosine of its polar angle from the pole (the field is linear in
    /// it between knots, and the search compares cosines: no trigonometry).
    pub cos: f64,
    /// The edge crossing, or `None` for a knot moving with the frame.
    pub edge: Option<Crossing>,
}

/// Where a fibre's plane crosses an edge, with what every slot's rate
/// there needs.
#[derive(Debug, Clone, Copy)]
pub struct Crossing {
    /// The crossing point.
    pub q: DVec3,
    /// The edge's direction `b − a`.
    pub dir: DVec3,
    /// The mesh.
    pub shape: u32,
    /// `e_θ` at the crossing's direction, `1/r`, `1/(dir·m)`.
    e_theta: DVec3,
    inv_r: f64,
    inv_across: f64,
}

/// Most fibre families one warp builds (distinct poles): the motions use at
/// most four rules (the pseudo-random pole and the three axes); parameters
/// beyond would share the pseudo-random one. Small, because a warp is
/// copied per vertex.
pub const MAX_FIELDS: usize = 4;

/// How a parameter's fibres are laid out from a vertex `x`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PoleRule {
    /// A pseudo-random pole fixed by `x` (rotations).
    Hashed,
    /// A fixed pole (a translation's direction): every fibre plane holds
    /// the velocity, so crossings at a silhouette's vertex slide alike.
    Along(DVec3),
    /// The pole toward a point (a scale's pivot): every fibre plane holds
    /// `q − c`, the scale's velocity at each of its points.
    Toward(DVec3),
}

impl PoleRule {
    /// The rule for a parameter's motion.
    pub fn of(motion: &super::scene::Motion) -> PoleRule {
        use super::scene::Motion;
        match *motion {
            Motion::TranslateX => PoleRule::Along(DVec3::X),
            Motion::TranslateY => PoleRule::Along(DVec3::Y),
            Motion::TranslateZ => PoleRule::Along(DVec3::Z),
            // Toward the pivot would hold a scale's velocities in every
            // fibre plane too, but the pole then lies inside the mesh's
            // silhouette and the silhouette's crossings of static edges
            // (the lamp's) weigh more: measured on the closed-form scenes,
            // its error bars covered worse (tests/mesh_coverage.rs).
            Motion::Scale { .. } | Motion::Rotate { .. } => PoleRule::Hashed,
        }
    }

    /// The pole at `x`.
    #[inline]
    fn at(&self, x: DVec3) -> DVec3 {
        match *self {
            PoleRule::Hashed => pole(x),
            PoleRule::Along(d) => d,
            PoleRule::Toward(c) => (c - x).try_normalize().unwrap_or_else(|| pole(x)),
        }
    }
}

/// The warp at a vertex around a sampled direction: one fibre field per
/// pole rule the scene's parameters use.
#[derive(Debug, Clone, Copy)]
pub struct SpaceWarp {
    fields: [FibreField; MAX_FIELDS],
    count: usize,
}

/// The warp of one family of fibres.
#[derive(Debug, Clone, Copy)]
pub struct FibreField {
    /// The fibre's plane's unit normal `p × u`.
    m: DVec3,
    /// Cosine and sine of η's polar angle, and `e_θ` there.
    cos: f64,
    sin: f64,
    e_w: DVec3,
    /// Nearest knots below and above θ.
    lo: FibreKnot,
    hi: FibreKnot,
}

/// A pseudo-random unit vector fixed by the bits of `x`.
fn pole(x: DVec3) -> DVec3 {
    let mut h: u64 = 0x9E37_79B9_7F4A_7C15;
    for c in [x.x, x.y, x.z] {
        h ^= (c + 0.0).to_bits();
        h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
        h ^= h >> 31;
    }
    let mut next = || {
        h = h.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = h;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let z = 2.0 * next() - 1.0;
    let phi = 2.0 * PI * next();
    let s = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(s * phi.cos(), s * phi.sin(), z)
}

impl Space {
    /// The warp at `v` around `w`: a field per pole rule.
    pub(super) fn fibre_warp(&self, v: &Vertex<Self>, w: DVec3) -> SpaceWarp {
        let still = FibreKnot {
            cos: 1.0,
            edge: None,
        };
        let blank = FibreField {
            m: DVec3::ZERO,
            cos: 1.0,
            sin: 0.0,
            e_w: DVec3::ZERO,
            lo: still,
            hi: still,
        };
        let mut warp = SpaceWarp {
            fields: [blank; MAX_FIELDS],
            count: self.pole_rules.len(),
        };
        if let SpaceLobe::Pixel { frame, rect, pixel } = v.lobe {
            // At a camera, one family for every slot: the image's rows
            // (pole on the camera's right axis) or its columns (pole up),
            // whichever the pixel's moving edges cross more steeply (a
            // crossing slides along its fibre at v_n / sin of the angle
            // between edge and fibre; chosen once per pixel when its edges
            // are cut, `PixelEdges::along_rows`). The stratum's sides
            // across the fibres are the ends; the other two are fibres. See
            // `super::camera`.
            let [f, r, u] = frame;
            let (pole, ends) = if self.pixel_edges().along_rows(pixel) {
                (r, [u.cross(f + r * rect[0]), u.cross(f + r * rect[1])])
            } else {
                (u, [r.cross(f + u * rect[2]), r.cross(f + u * rect[3])])
            };
            warp.count = 1;
            warp.fields[0] = self.fibre_field(v, w, pole, ends);
            return warp;
        }
        // A cosine lobe ends at its horizon.
        let ends = match v.lobe {
            SpaceLobe::Cosine { n, .. } => [n, DVec3::ZERO],
            _ => [DVec3::ZERO; 2],
        };
        for (f, rule) in warp.fields.iter_mut().zip(&self.pole_rules) {
            *f = self.fibre_field(v, w, rule.at(v.x), ends);
        }
        warp
    }

    // ANCHOR: fibre_warp
    /// The field of the fibres from the pole `p` at `v` around `w`; the
    /// lobe ends on the great circles of normals `ends` (zero: none), where
    /// the field moves with the frame.
    fn fibre_field(&self, v: &Vertex<Self>, w: DVec3, p: DVec3, ends: [DVec3; 2]) -> FibreField {
        let x = v.x;
        let c = w.dot(p).clamp(-1.0, 1.0);
        let perp = w - p * c;
        let s = perp.length();
        let still = |cos: f64| FibreKnot { cos, edge: None };
        if s < 1e-12 {
            // η at a pole: the field is the frame's there.
            return FibreField {
                m: DVec3::ZERO,
                cos: c,
                sin: s,
                e_w: DVec3::ZERO,
                lo: still(c),
                hi: still(c),
            };
        }
        let u = perp / s;
        let m = p.cross(u);
        // The poles, and the lobe's horizon on the fibre (knots moving with
        // the frame): the horizon meets the fibre's great circle at ±(n × m),
        // the fibre at the one on its side (u·h > 0).
        let (mut lo, mut hi) = (still(1.0), still(-1.0));
        for n in ends {
            let h = n.cross(m);
            let len = h.length();
            if len > 1e-12 {
                let h = if h.dot(u) < 0.0 { -h / len } else { h / len };
                let ch = h.dot(p);
                if ch > c && ch < lo.cos {
                    lo = still(ch);
                } else if ch < c && ch > hi.cos {
                    hi = still(ch);
                }
            }
        }
        let (lo, hi) = self.nearest_crossings(x, v.skip, p, u, m, c, lo, hi);
        // What the slots' rates need at the chosen crossings.
        let finish = |k: FibreKnot| -> FibreKnot {
            let Some(e) = k.edge else { return k };
            let d = e.q - x;
            let inv_r = 1.0 / d.length();
            let wq = d * inv_r;
            let across = e.dir.dot(m);
            FibreKnot {
                cos: k.cos,
                edge: Some(Crossing {
                    e_theta: u * wq.dot(p) - p * wq.dot(u),
                    inv_r,
                    inv_across: if across == 0.0 { 0.0 } else { 1.0 / across },
                    ..e
                }),
            }
        };
        FibreField {
            m,
            cos: c,
            sin: s,
            e_w: u * c - p * s,
            lo: finish(lo),
            hi: finish(hi),
        }
    }
    // ANCHOR_END: fibre_warp

    /// The visible edge crossings of the fibre nearest to θ on either side,
    /// within the knots `lo` and `hi` already found. At the sensor's point
    /// the search runs in the sensor's own edge tree, and where the visible
    /// parts of the edges are known
    /// ([`SensorView`](super::sensor_view::SensorView)) needs no shadow ray.
    #[allow(clippy::too_many_arguments)]
    fn nearest_crossings(
        &self,
        x: DVec3,
        skip: u32,
        p: DVec3,
        u: DVec3,
        m: DVec3,
        cos_theta: f64,
        lo: FibreKnot,
        hi: FibreKnot,
    ) -> (FibreKnot, FibreKnot) {
        let at_sensor = skip == NO_PRIM && self.sensor_view().point == x;
        self.nearest_crossings_by(at_sensor, x, skip, p, u, m, cos_theta, lo, hi)
    }

    /// [`Self::nearest_crossings`], by the sensor's view or by shadow rays.
    #[allow(clippy::too_many_arguments)]
    fn nearest_crossings_by(
        &self,
        at_sensor: bool,
        x: DVec3,
        skip: u32,
        p: DVec3,
        u: DVec3,
        m: DVec3,
        cos_theta: f64,
        mut lo: FibreKnot,
        mut hi: FibreKnot,
    ) -> (FibreKnot, FibreKnot) {
        let tables = self.edge_tables();
        let edges = &tables.edges;
        let (tree, list, visible) = if at_sensor {
            let view = self.sensor_view();
            (
                &view.tree,
                (view.edges.len() <= super::sensor_view::SCAN).then_some(&view.edges),
                view.visible.as_ref(),
            )
        } else {
            (&tables.all_edges, None, None)
        };
        if let Some(visible) = visible {
            // The visible parts known: one scan, the nearest seen crossing
            // on each side.
            match list {
                Some(list) => {
                    for &i in list {
                        let e = &edges[i as usize];
                        nearer_seen(e, i, x, p, u, m, cos_theta, visible, &mut lo, &mut hi);
                    }
                }
                None => tree.crossings(x, m, u, edges, &tables.edge_facts, |i| {
                    let e = &edges[i as usize];
                    nearer_seen(e, i, x, p, u, m, cos_theta, visible, &mut lo, &mut hi);
                }),
            }
            return (lo, hi);
        }
        // One scan keeps each side's nearest candidates in order; they are
        // tried nearest first, and only when all of a full list are hidden
        // does the side scan again past them. Angles are compared by their
        // cosines (θ ∈ [0, π] grows as cos θ falls); a side's key grows
        // away from θ.
        let (mut bound_lo, mut bound_hi) = (cos_theta, cos_theta);
        let (mut done_lo, mut done_hi) = (false, false);
        while !(done_lo && done_hi) {
            let (mut near_lo, mut near_hi) = (Nearest::new(), Nearest::new());
            let mut candidate = |i: u32| {
                let e = &edges[i as usize];
                let Some((cos, _, q)) = cut(e, x, p, u, m) else {
                    return;
                };
                let knot = crossing_knot(e, cos, q);
                if !done_lo && cos > bound_lo && cos < lo.cos {
                    near_lo.insert(cos, knot);
                }
                if !done_hi && cos < bound_hi && cos > hi.cos {
                    near_hi.insert(-cos, knot);
                }
            };
            match list {
                Some(list) => list.iter().for_each(|&i| candidate(i)),
                None => tree.crossings(x, m, u, edges, &tables.edge_facts, candidate),
            }
            let settle = |done: &mut bool, near: &Nearest, bound: &mut f64, k: &mut FibreKnot| {
                if *done {
                    return;
                }
                for b in near.sorted() {
                    let q = b.edge.map_or(x, |e| e.q);
                    if self.visible_point(x, q, skip) {
                        *k = *b;
                        *done = true;
                        return;
                    }
                }
                match near.sorted().last() {
                    // Every candidate hidden: done unless some were left out.
                    Some(last) if near.full() => *bound = last.cos,
                    _ => *done = true,
                }
            };
            settle(&mut done_lo, &near_lo, &mut bound_lo, &mut lo);
            settle(&mut done_hi, &near_hi, &mut bound_hi, &mut hi);
        }
        (lo, hi)
    }

    /// Whether the edge point `q` is seen from `x` (nothing opaque strictly
    /// between; the edge's own faces end at `q`).
    fn visible_point(&self, x: DVec3, q: DVec3, skip: u32) -> bool {
        use crate::path::Geometry;
        if skip == NO_PRIM {
            self.visible(x, q, NO_PRIM)
        } else {
            self.visible(x, q, skip)
        }
    }

    // ANCHOR: fibre_velocity
    /// One slot's direction velocity and divergence under the warp.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn fibre_velocity(
        &self,
        warp: &SpaceWarp,
        slot: usize,
        x: DVec3,
        w: DVec3,
        u: DVec3,
        spin: DVec3,
        velocity: impl Fn(DVec3, u32) -> DVec3,
    ) -> (DVec3, f64) {
        let rigid = spin.cross(w);
        let field = self.slot_field.get(slot).copied().unwrap_or(0) as usize;
        let warp = &warp.fields[field.min(warp.count.saturating_sub(1))];
        if warp.m == DVec3::ZERO {
            return (rigid, 0.0);
        }
        // α at a knot: the crossing's slide along the fibre, relative to
        // the frame (the vertex moves at u, the frame turns at Ω).
        let rate = |k: &FibreKnot| -> f64 {
            let Some(e) = k.edge else {
                return 0.0;
            };
            let v_rel = velocity(e.q, e.shape) - u - spin.cross(e.q - x);
            // The crossing stays in the fixed plane: it slides along the
            // edge by what takes it off the plane.
            let slide = v_rel - e.dir * (v_rel.dot(warp.m) * e.inv_across);
            slide.dot(e.e_theta) * e.inv_r
        };
        let (a_lo, a_hi) = (rate(&warp.lo), rate(&warp.hi));
        // α is linear in t = −cos θ between the knots: ∂α/∂θ = slope · sin θ.
        let span = warp.lo.cos - warp.hi.cos;
        if span <= 0.0 {
            return (rigid, 0.0);
        }
        let slope = (a_hi - a_lo) / span;
        let alpha = a_lo + slope * (warp.lo.cos - warp.cos);
        (
            rigid + warp.e_w * alpha,
            slope * warp.sin + alpha * warp.cos / warp.sin,
        )
    }
    // ANCHOR_END: fibre_velocity

    /// The meshes whose motion the warp follows.
    pub(super) fn fibre_shapes(&self, warp: &SpaceWarp, mut f: impl FnMut(u32)) {
        for field in &warp.fields[..warp.count] {
            for k in [field.lo, field.hi] {
                if let Some(e) = k.edge {
                    f(e.shape);
                }
            }
        }
    }
}

/// Where the plane through `x` of normal `m` crosses the edge `e` on the
/// fibre's side (`u`): the cosine of its polar angle from `p`, the edge
/// parameter and the point.
#[inline(always)]
fn cut(e: &Edge, x: DVec3, p: DVec3, u: DVec3, m: DVec3) -> Option<(f64, f64, DVec3)> {
    let (sa, sb) = ((e.a - x).dot(m), (e.b - x).dot(m));
    if (sa > 0.0 && sb > 0.0) || (sa < 0.0 && sb < 0.0) || sa == sb {
        return None;
    }
    let t = sa / (sa - sb);
    let q = e.a + (e.b - e.a) * t;
    let d = q - x;
    let (dp, du) = (d.dot(p), d.dot(u));
    if du <= 0.0 {
        return None; // the other half of the great circle
    }
    Some((dp / d.length(), t, q))
}

/// The knot at a crossing of edge `e` (its rates' fields left to fill).
#[inline(always)]
fn crossing_knot(e: &Edge, cos: f64, q: DVec3) -> FibreKnot {
    FibreKnot {
        cos,
        edge: Some(Crossing {
            q,
            dir: e.b - e.a,
            shape: e.shape,
            e_theta: DVec3::ZERO,
            inv_r: 0.0,
            inv_across: 0.0,
        }),
    }
}

/// One edge's crossing, if seen, as the nearer of it and the knots found
/// so far on its side.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn nearer_seen(
    e: &Edge,
    i: u32,
    x: DVec3,
    p: DVec3,
    u: DVec3,
    m: DVec3,
    cos_theta: f64,
    visible: &super::sensor_view::Visible,
    lo: &mut FibreKnot,
    hi: &mut FibreKnot,
) {
    let Some((cos, t, q)) = cut(e, x, p, u, m) else {
        return;
    };
    if cos > cos_theta && cos < lo.cos && visible.sees(i, t) {
        *lo = crossing_knot(e, cos, q);
    }
    if cos < cos_theta && cos > hi.cos && visible.sees(i, t) {
        *hi = crossing_knot(e, cos, q);
    }
}

/// How many candidate knots a side keeps per scan.
const NEAREST: usize = 8;

/// The candidate knots nearest to θ on one side, by a key growing away
/// from θ, in order (ties keep the scan's order).
struct Nearest {
    keys: [f64; NEAREST],
    knots: [FibreKnot; NEAREST],
    len: usize,
    /// Some candidate was dropped for lack of room.
    dropped: bool,
}

impl Nearest {
    #[inline]
    fn new() -> Nearest {
        Nearest {
            keys: [f64::INFINITY; NEAREST],
            knots: [FibreKnot {
                cos: 0.0,
                edge: None,
            }; NEAREST],
            len: 0,
            dropped: false,
        }
    }

    #[inline]
    fn insert(&mut self, key: f64, knot: FibreKnot) {
        let mut i = self.len;
        if i == NEAREST {
            if key >= self.keys[NEAREST - 1] {
                self.dropped = true;
                return;
            }
            self.dropped = true;
            i -= 1;
        } else {
            self.len += 1;
        }
        while i > 0 && self.keys[i - 1] > key {
            self.keys[i] = self.keys[i - 1];
            self.knots[i] = self.knots[i - 1];
            i -= 1;
        }
        self.keys[i] = key;
        self.knots[i] = knot;
    }

    #[inline]
    fn sorted(&self) -> &[FibreKnot] {
        &self.knots[..self.len]
    }

    /// Whether candidates beyond the kept ones exist.
    #[inline]
    fn full(&self) -> bool {
        self.dropped
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::scene::{Motion, Parameter, Scene, Surface};
    use rand::{RngExt, SeedableRng};
    use std::sync::Arc;

    /// At the sensor, the knots found through the precomputed view are the
    /// ones shadow rays find: a box partly hiding a square, both partly
    /// hiding the lamp, random fibres (no two edges in a plane through the
    /// sensor: there the two answers may differ by a rounding).
    #[test]
    fn the_sensor_view_finds_the_knots_shadow_rays_find() {
        let cases = crate::mesh::cases::cube_shape;
        let shapes = vec![
            crate::mesh::cases::lamp(),
            cases(
                "box",
                DVec3::new(0.13, 0.02, 1.1),
                0.29,
                Surface::Absorber,
                None,
            ),
            crate::mesh::cases::square_shape(
                "sq",
                DVec3::new(-0.113, 0.071, 1.6),
                0.337,
                Surface::Absorber,
            ),
        ];
        let parameters = vec![Parameter {
            name: "box_tx".into(),
            shape: "box".into(),
            motion: Motion::TranslateX,
        }];
        let scene = Scene::new(shapes, parameters, crate::mesh::cases::up()).unwrap();
        let space = Space::new(Arc::new(scene));
        let x = space.scene().sensor().point();
        assert!(space.sensor_view().visible.is_some());
        let mut rng = crate::rng::PathRng::seed_from_u64(11);
        let mut unit = || {
            let z: f64 = 2.0 * rng.random::<f64>() - 1.0;
            let phi = 2.0 * PI * rng.random::<f64>();
            let s = (1.0 - z * z).sqrt();
            DVec3::new(s * phi.cos(), s * phi.sin(), z)
        };
        let still = |cos: f64| FibreKnot { cos, edge: None };
        let (mut edges_found, mut hidden_seen) = (0, 0);
        for _ in 0..20_000 {
            let (p, mut w) = (unit(), unit());
            w.z = w.z.abs(); // up, where the lamp and the meshes are
            let c = w.dot(p);
            let perp = w - p * c;
            let u = perp / perp.length();
            let m = p.cross(u);
            let by_view =
                space.nearest_crossings_by(true, x, NO_PRIM, p, u, m, c, still(1.0), still(-1.0));
            let by_rays =
                space.nearest_crossings_by(false, x, NO_PRIM, p, u, m, c, still(1.0), still(-1.0));
            // The same knot, or (at a mesh corner, where two edges cross
            // the plane a rounding apart) one as near.
            for (a, b) in [(by_view.0, by_rays.0), (by_view.1, by_rays.1)] {
                assert!(
                    (a.cos - b.cos).abs() < 1e-12,
                    "knot along {w} from pole {p}"
                );
                let (qa, qb) = (a.edge.map(|e| e.q), b.edge.map(|e| e.q));
                assert!(
                    qa.zip(qb).map_or(qa.is_none() && qb.is_none(), |(qa, qb)| {
                        (qa - qb).length() < 1e-9
                    }),
                    "knot along {w} from pole {p}: {qa:?} {qb:?}"
                );
                edges_found += a.edge.is_some() as u32;
            }
            // Some fibres pass a crossing nearer than the knot that is no
            // knot (hidden, or on an edge that is no silhouette).
            let nearest_any = space
                .edges()
                .iter()
                .filter_map(|e| cut(e, x, p, u, m))
                .filter(|&(cos, _, _)| cos > c)
                .map(|(cos, _, _)| cos)
                .fold(f64::INFINITY, f64::min);
            if nearest_any < by_view.0.cos {
                hidden_seen += 1;
            }
        }
        assert!(edges_found > 2000, "{edges_found}");
        assert!(hidden_seen > 100, "{hidden_seen}");
    }
}
