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
//! needed, found by [`super::knots`].
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
//! there), at a vertex none of the family's slots moves; for the other
//! slots, and past a warped direction, a pseudo-random direction fixed by
//! the vertex's position, so no edge of a scene lies along the fibres by
//! construction (an edge exactly on a fibre could not be moved by `V`;
//! nearly on one, `α` is large: one of the method's heavy tails). One field
//! per pole rule ([`PoleRule`](super::poles::PoleRule)), each with its own knot search. Book: chapter "Three dimensions",
//! section "A warp on the sphere".
use super::lobe::SpaceLobe;
use super::poles::Sphere;
use super::poles::{MAX_FIELDS, pole};
use super::space::Space;
use crate::path::MovingVertex;
use crate::path::deform::SlotSet;
use crate::path::walk::Vertex;
use crate::path::{Hit, Warping};
use glam::DVec3;

/// A fibre of the warp at the vertex `x`: the half great circle of
/// directions from the pole `p` through the sampled direction η, in the
/// plane of unit normal `m = p × u`, `u` the unit vector of that plane
/// normal to `p` on η's side. What its knot search needs.
#[derive(Debug, Clone, Copy)]
pub(super) struct Fibre {
    /// The vertex.
    pub(super) x: DVec3,
    /// The pole.
    pub(super) p: DVec3,
    /// The unit vector normal to the pole in the fibre's plane, toward η.
    pub(super) u: DVec3,
    /// The plane's unit normal `p × u`.
    pub(super) m: DVec3,
    /// The cosine of η's polar angle θ from the pole.
    pub(super) cos_theta: f64,
}

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
    /// What turns a relative velocity `v` of the crossing's edge into the
    /// knot's rate `α = v·rate` (filled for the chosen knots only): the
    /// crossing stays in the fibre's fixed plane, so it slides along the
    /// edge by what takes it off the plane, `v − dir (v·m)/(dir·m)`, and
    /// that slide's component along `e_θ`, over `r`, is `α`. Linear in `v`:
    /// `rate = (e_θ − m (dir·e_θ)/(dir·m)) / r`.
    pub(super) rate: DVec3,
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

/// Whether the ball of radius `r` around `x + d` meets the fibre's
/// half-plane `{x + a p + b u : b ≥ 0}` (`m = p × u`): the rays from `x`
/// along the fibre sweep it.
#[inline]
fn meets_half_plane(d: DVec3, r: f64, u: DVec3, m: DVec3) -> bool {
    let (dm, du) = (d.dot(m), d.dot(u));
    let off = if du >= 0.0 {
        dm * dm
    } else {
        dm * dm + du * du
    };
    off <= r * r
}

impl Space {
    // ANCHOR: fibre_warp
    /// The field of the fibres from the pole `p` at `v` around `w`; the
    /// lobe ends on the great circles of normals `ends` (zero: none), where
    /// the field moves with the frame. `quiet`, for a family whose slots'
    /// vertex and frame are still, holds the bounding spheres of the meshes
    /// they move: a fibre that meets none crosses no moving edge, every
    /// knot's rate is zero, and so is the field (returned as at a pole).
    fn fibre_field(
        &self,
        v: &Vertex<Self>,
        w: DVec3,
        p: DVec3,
        ends: [DVec3; 2],
        quiet: Option<&[Sphere]>,
    ) -> FibreField {
        let x = v.x;
        let c = w.dot(p).clamp(-1.0, 1.0);
        let perp = w - p * c;
        let s = perp.length();
        let still = |cos: f64| FibreKnot { cos, edge: None };
        if s < crate::path::tolerance::TIE {
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
        if let Some(spheres) = quiet
            && !spheres
                .iter()
                .any(|&(c, r)| meets_half_plane(c - x, r, u, m))
        {
            return FibreField {
                m: DVec3::ZERO,
                cos: c,
                sin: s,
                e_w: DVec3::ZERO,
                lo: still(1.0),
                hi: still(-1.0),
            };
        }
        // The poles, and the lobe's horizon on the fibre (knots moving with
        // the frame): the horizon meets the fibre's great circle at ±(n × m),
        // the fibre at the one on its side (u·h > 0).
        let (mut lo, mut hi) = (still(1.0), still(-1.0));
        for n in ends {
            let h = n.cross(m);
            let len = h.length();
            if len > crate::path::tolerance::TIE {
                let h = if h.dot(u) < 0.0 { -h / len } else { h / len };
                let ch = h.dot(p);
                if ch > c && ch < lo.cos {
                    lo = still(ch);
                } else if ch < c && ch > hi.cos {
                    hi = still(ch);
                }
            }
        }
        let fibre = Fibre {
            x,
            p,
            u,
            m,
            cos_theta: c,
        };
        let (lo, hi) = self.nearest_crossings(&fibre, v.skip, lo, hi);
        // What the slots' rates need at the chosen crossings.
        let finish = |k: FibreKnot| -> FibreKnot {
            let Some(e) = k.edge else { return k };
            let d = e.q - x;
            let inv_r = 1.0 / d.length();
            let wq = d * inv_r;
            let e_theta = u * wq.dot(p) - p * wq.dot(u);
            let across = e.dir.dot(m);
            let off = if across == 0.0 {
                DVec3::ZERO
            } else {
                m * (e.dir.dot(e_theta) / across)
            };
            FibreKnot {
                cos: k.cos,
                edge: Some(Crossing {
                    rate: (e_theta - off) * inv_r,
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
}

/// The fibre warp.
impl Warping for Space {
    type Warp = SpaceWarp;

    /// The warp at `v` around `w`: a field per pole rule. A family none of
    /// whose slots is in `frame` (vertex and frame still) is zero unless its
    /// fibre meets a mesh its slots move: it is left zero there, unsearched.
    fn warp(
        &self,
        v: &Vertex<Self>,
        w: DVec3,
        _ahead: Option<Option<Hit>>,
        frame: SlotSet,
    ) -> SpaceWarp {
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
            count: self.poles.rules.len(),
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
            let quiet = frame
                .is_empty()
                .then(|| &self.poles.field_bounds[self.poles.rules.len()][..]);
            warp.fields[0] = self.fibre_field(v, w, pole, ends, quiet);
            return warp;
        }
        // A cosine lobe ends at its horizon.
        let ends = match v.lobe {
            SpaceLobe::Cosine { n, .. } => [n, DVec3::ZERO],
            _ => [DVec3::ZERO; 2],
        };
        let mut busy = [false; MAX_FIELDS];
        for j in frame.iter() {
            busy[self.poles.slot_field.get(j).copied().unwrap_or(0) as usize] = true;
        }
        // A fixed pole lays the edges parallel to it along fibres, where V
        // cannot move them across: right while their motion relative to the
        // vertex and its frame is along the pole (a translation seen from a
        // still vertex). Once a slot of a family moves the vertex or turns
        // the frame (past a warped direction), the family takes the
        // vertex's own pole (a box's vertical edges, sliding sideways as
        // seen from a scattering vertex that had moved, made expectation's
        // ∂I/∂tz 3–6 % off in fog); those families share one field,
        // searched once.
        let mut own: Option<FibreField> = None;
        for (i, (f, rule)) in warp.fields.iter_mut().zip(&self.poles.rules).enumerate() {
            *f = if busy[i] {
                *own.get_or_insert_with(|| self.fibre_field(v, w, pole(v.x), ends, None))
            } else {
                self.fibre_field(
                    v,
                    w,
                    rule.at(v.x),
                    ends,
                    Some(&self.poles.field_bounds[i][..]),
                )
            };
        }
        warp
    }

    // ANCHOR: fibre_velocity
    /// One slot's direction velocity and divergence under the warp, the
    /// vertex as the slot moves it.
    fn warp_velocity(
        &self,
        warp: &SpaceWarp,
        slot: usize,
        vertex: MovingVertex<DVec3>,
        w: DVec3,
        velocity: impl Fn(DVec3, u32) -> DVec3,
    ) -> (DVec3, f64) {
        let MovingVertex { x, u, spin } = vertex;
        let rigid = spin.cross(w);
        let field = self.poles.slot_field.get(slot).copied().unwrap_or(0) as usize;
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
            (velocity(e.q, e.shape) - u - spin.cross(e.q - x)).dot(e.rate)
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
    fn warp_shapes(&self, warp: &SpaceWarp, mut f: impl FnMut(u32)) {
        for field in &warp.fields[..warp.count] {
            for k in [field.lo, field.hi] {
                if let Some(e) = k.edge {
                    f(e.shape);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::cases::{cube_shape, lamp, up};
    use crate::mesh::scene::{Motion, Parameter, Scene, Surface};
    use crate::path::walk::Frame;
    use crate::path::{Geometry, NO_PRIM};
    use rand::{RngExt, SeedableRng};
    use std::sync::Arc;

    /// A family left unsearched because its fibre meets no moving mesh
    /// gives every slot whose vertex and frame are still the velocity the
    /// searched family gives: the skip loses nothing. Checked at the
    /// sensor and at a point off it, on fibres that do and do not pass
    /// the moving cubes.
    #[test]
    fn a_quiet_family_moves_as_the_searched_one() {
        let cube = |name: &str, c: DVec3| cube_shape(name, c, 0.1, Surface::Absorber, None);
        let p = |name: &str, shape: &str, motion| Parameter {
            name: name.into(),
            shape: shape.into(),
            motion,
            bounds: None,
        };
        let scene = Scene::new(
            vec![
                lamp(),
                cube("a", DVec3::new(0.3, 0.1, 1.0)),
                cube("b", DVec3::new(-0.4, -0.2, 1.3)),
            ],
            vec![
                p("a_x", "a", Motion::TranslateX),
                p("a_z", "a", Motion::TranslateZ),
                p(
                    "b_rot",
                    "b",
                    Motion::Rotate {
                        axis: DVec3::new(0.3, 0.2, 1.0).normalize(),
                        pivot: Some(DVec3::new(-0.4, -0.2, 1.3)),
                    },
                ),
            ],
            up(),
        )
        .unwrap();
        let space = Space::new(Arc::new(scene));
        let slots = space.parameters();
        let mut rng = rand::rngs::SmallRng::seed_from_u64(7);
        let (mut skipped, mut moving) = (0, 0);
        for x in [DVec3::ZERO, DVec3::new(0.2, -0.3, 0.4)] {
            let v = Vertex::<Space> {
                x,
                medium: space.sensor_medium(),
                skip: NO_PRIM,
                lobe: SpaceLobe::Cosine {
                    n: DVec3::Z,
                    c: 1.0,
                },
                frame: Frame::Sensor,
                w_in: DVec3::Z,
                beta: 1.0,
                at_sensor: x == DVec3::ZERO,
                mixed: false,
            };
            for _ in 0..4000 {
                let w = DVec3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(0.05..1.0),
                )
                .normalize();
                // Every family about its rule's pole, each searched in
                // full or allowed to skip (a busy family takes the
                // vertex's own pole instead, another field).
                let ends = [DVec3::Z, DVec3::ZERO];
                let field = |quiet: bool| {
                    let mut warp = space.warp(&v, w, None, SlotSet::EMPTY);
                    for (i, rule) in space.poles.rules.iter().enumerate() {
                        let bounds = quiet.then(|| &space.poles.field_bounds[i][..]);
                        warp.fields[i] = space.fibre_field(&v, w, rule.at(x), ends, bounds);
                    }
                    warp
                };
                let (quiet, searched) = (field(true), field(false));
                for j in 0..slots {
                    let velocity = |q: DVec3, k: u32| {
                        if space.parameter_shape(j) == k {
                            space.velocity(j, q)
                        } else {
                            DVec3::ZERO
                        }
                    };
                    let still = MovingVertex {
                        x,
                        u: DVec3::ZERO,
                        spin: DVec3::ZERO,
                    };
                    let f = |warp| space.warp_velocity(&warp, j, still, w, velocity);
                    let (a, b) = (f(quiet), f(searched));
                    assert_eq!(a, b, "slot {j} at {x} along {w}");
                    let field = space.poles.slot_field[j] as usize;
                    if quiet.fields[field].m == DVec3::ZERO
                        && searched.fields[field].m != DVec3::ZERO
                    {
                        skipped += 1;
                    }
                    if b.1 != 0.0 {
                        moving += 1;
                    }
                }
            }
        }
        // Both kinds of fibre were met often enough to matter.
        assert!(
            skipped > 5000 && moving > 1000,
            "{skipped} skipped, {moving} moving"
        );
    }
}
