//! The expectation method's knot search: along a fibre of the warp
//! ([`super::warp`]), the crossings of its plane with the discontinuity
//! edges seen from the vertex that lie nearest to the sampled direction on
//! either side. The edge hierarchy ([`super::edges`]) gives the edges that
//! cross the plane; off the sensor, shadow rays decide which crossings are
//! seen (the eight nearest candidates per side kept per scan, a new scan
//! only past eight hidden ones); at the sensor, its precomputed view
//! ([`super::sensor_view`]) does, with no ray. Book: chapter "Three
//! dimensions", section "A warp on the sphere".
use super::edges::Edge;
use super::space::Space;
use super::warp::{Crossing, Fibre, FibreKnot};
use crate::path::NO_PRIM;
use glam::DVec3;

impl Space {
    /// The visible edge crossings of the fibre nearest to θ on either side,
    /// within the knots `lo` and `hi` already found, seen from the fibre's
    /// vertex, which lies on the primitive `skip`. At the sensor's point
    /// the search runs in the sensor's own edge tree, and where the visible
    /// parts of the edges are known
    /// ([`SensorView`](super::sensor_view::SensorView)) needs no shadow ray.
    pub(super) fn nearest_crossings(
        &self,
        fibre: &Fibre,
        skip: u32,
        lo: FibreKnot,
        hi: FibreKnot,
    ) -> (FibreKnot, FibreKnot) {
        let at_sensor = skip == NO_PRIM && self.sensor_view().point == fibre.x;
        self.nearest_crossings_by(at_sensor, fibre, skip, lo, hi)
    }

    /// [`Self::nearest_crossings`], by the sensor's view or by shadow rays.
    fn nearest_crossings_by(
        &self,
        at_sensor: bool,
        fibre: &Fibre,
        skip: u32,
        mut lo: FibreKnot,
        mut hi: FibreKnot,
    ) -> (FibreKnot, FibreKnot) {
        let Fibre {
            x,
            p,
            u,
            m,
            cos_theta,
        } = *fibre;
        let tables = self.edge_tables();
        let edges = &tables.edges;
        let (tree, list, visible) = if at_sensor {
            let view = self.sensor_view();
            // The fibre's azimuth bin, where the pole is one of the view's.
            let list = match view.fibres(p) {
                Some(f) => Some(f.candidates(u)),
                None => (view.edges.len() <= super::sensor_view::SCAN).then_some(&view.edges[..]),
            };
            (&view.tree, list, view.visible.as_ref())
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
                        nearer_seen(e, i, fibre, visible, &mut lo, &mut hi);
                    }
                }
                None => tree.crossings(x, m, u, edges, &tables.edge_facts, |i| {
                    let e = &edges[i as usize];
                    nearer_seen(e, i, fibre, visible, &mut lo, &mut hi);
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
                let Some((cos, _, q)) = cut(e, fibre) else {
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
}

/// Where the fibre's plane (through `x`, of normal `m`) crosses the edge
/// `e` on the fibre's side (`u`): the cosine of its polar angle from `p`,
/// the edge parameter and the point.
#[inline(always)]
fn cut(e: &Edge, fibre: &Fibre) -> Option<(f64, f64, DVec3)> {
    let Fibre { x, p, u, m, .. } = *fibre;
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
            rate: DVec3::ZERO,
        }),
    }
}

/// One edge's crossing, if seen, as the nearer of it and the knots found
/// so far on its side.
#[inline(always)]
fn nearer_seen(
    e: &Edge,
    i: u32,
    fibre: &Fibre,
    visible: &super::sensor_view::Visible,
    lo: &mut FibreKnot,
    hi: &mut FibreKnot,
) {
    let cos_theta = fibre.cos_theta;
    let Some((cos, t, q)) = cut(e, fibre) else {
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
    use std::f64::consts::PI;
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
            bounds: None,
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
            let fibre = Fibre {
                x,
                p,
                u,
                m,
                cos_theta: c,
            };
            let by_view =
                space.nearest_crossings_by(true, &fibre, NO_PRIM, still(1.0), still(-1.0));
            let by_rays =
                space.nearest_crossings_by(false, &fibre, NO_PRIM, still(1.0), still(-1.0));
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
                .filter_map(|e| cut(e, &fibre))
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
