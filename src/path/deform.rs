//! The deformation a derivative walk carries along its path: per derivative
//! slot `j` (a shape parameter, or an axis of the sensor's position), the
//! velocity `u_j = ∂x/∂π_j` of the current vertex, the velocity `η̇_j` of the
//! current direction (a vector tangent to the circle or sphere), the running
//! score `Λ_j` (the derivative of the log weight along the deformation) and
//! the boundary terms collected so far.
//!
//! The one formula every method uses: a ray from `x` along `η` meets a
//! boundary moving at `v` at distance `t_b`; the hit point stays on it,
//! `(u + ṫ_b η + t_b η̇ − v)·n = 0`, so
//! `ṫ_b = (v − u − t_b η̇)·n / (η·n)` (book: "Flatland: one deformation,
//! three estimators", *the hit point's velocity*), in the plane and in space.
use super::{Geometry, Hit, Vector};
use crate::estimator::within_rounding;

/// Most derivative slots a walk carries (shape parameters, the sensor's
/// gradient axes, and transport's twins of the parameters when they fit).
pub const MAX_SLOTS: usize = 256;

/// A set of derivative slots, as bits.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SlotSet([u64; MAX_SLOTS / 64]);

impl SlotSet {
    /// No slot.
    pub const EMPTY: SlotSet = SlotSet([0; MAX_SLOTS / 64]);

    /// The slots `0..n`.
    pub fn first(n: usize) -> SlotSet {
        let mut s = SlotSet::EMPTY;
        for j in 0..n.min(MAX_SLOTS) {
            s.insert(j);
        }
        s
    }

    /// Adds slot `j`.
    #[inline]
    pub fn insert(&mut self, j: usize) {
        self.0[j >> 6] |= 1 << (j & 63);
    }

    /// Whether slot `j` is in the set.
    #[inline]
    pub fn contains(&self, j: usize) -> bool {
        self.0[j >> 6] & (1 << (j & 63)) != 0
    }

    /// Whether the set is empty.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.0.iter().all(|&w| w == 0)
    }

    /// The union.
    #[inline]
    pub fn union(self, o: SlotSet) -> SlotSet {
        let mut s = self;
        for (a, b) in s.0.iter_mut().zip(o.0) {
            *a |= b;
        }
        s
    }

    /// The intersection.
    #[inline]
    pub fn and(self, o: SlotSet) -> SlotSet {
        let mut s = self;
        for (a, b) in s.0.iter_mut().zip(o.0) {
            *a &= b;
        }
        s
    }

    /// The slots of `self` not in `o`.
    #[inline]
    pub fn without(self, o: SlotSet) -> SlotSet {
        let mut s = self;
        for (a, b) in s.0.iter_mut().zip(o.0) {
            *a &= !b;
        }
        s
    }

    /// Number of slots in the set.
    #[inline]
    pub fn len(&self) -> usize {
        self.0.iter().map(|w| w.count_ones() as usize).sum()
    }

    /// The slots in the set, in increasing order.
    #[inline]
    pub fn iter(self) -> impl Iterator<Item = usize> {
        self.0.into_iter().enumerate().flat_map(|(w, mut bits)| {
            std::iter::from_fn(move || {
                (bits != 0).then(|| {
                    let j = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    (w << 6) + j
                })
            })
        })
    }
}

/// One slot's state.
#[derive(Debug, Clone, Copy)]
pub struct Slot<V: Vector> {
    /// Vertex velocity `u_j`.
    pub u: V,
    /// Direction velocity `η̇_j`.
    pub wd: V,
    /// Running score `Λ_j`.
    pub score: f64,
    /// Σ|terms| of the score: what its rounding error is relative to.
    pub score_scale: f64,
    /// Boundary terms collected so far (and, at the end, the derivative).
    pub boundary: f64,
    /// Σ|terms| of `boundary` (a term's own scale where it carries one):
    /// a derivative below [`ROUNDING`](crate::estimator::ROUNDING) times it is rounding, not signal.
    pub boundary_scale: f64,
    /// `ṫ_b` of the current segment.
    pub tb_dot: f64,
    /// Turn rate of the current vertex's frame (scratch for the methods).
    pub spin: V::Spin,
}

impl<V: Vector> Slot<V> {
    /// Adds `t` to the score.
    #[inline]
    pub fn add_score(&mut self, t: f64) {
        self.score += t;
        self.score_scale += t.abs();
    }

    /// Adds `t` to the boundary terms, `scale` being the size of what `t`
    /// was computed from (`|t|` for a term of its own).
    #[inline]
    pub fn add_boundary(&mut self, t: f64, scale: f64) {
        self.boundary += t;
        self.boundary_scale += scale;
    }

    /// The derivative collected: `boundary`, or 0 where it is below the
    /// rounding of its terms ([`ROUNDING`](crate::estimator::ROUNDING)).
    #[inline]
    pub fn derivative(&self) -> f64 {
        if within_rounding(self.boundary, self.boundary_scale) {
            0.0
        } else {
            self.boundary
        }
    }

    const ZERO: Self = Slot {
        u: V::ZERO,
        wd: V::ZERO,
        score: 0.0,
        score_scale: 0.0,
        boundary: 0.0,
        boundary_scale: 0.0,
        tb_dot: 0.0,
        spin: V::STILL,
    };
}

/// The deformation state of one walk: every slot, and the set of slots whose
/// `u`, `η̇` or score may be non-zero (the others are skipped: their updates
/// would add exact zeros).
#[derive(Debug, Clone)]
pub struct Deform<V: Vector> {
    /// The slots.
    pub slots: Vec<Slot<V>>,
    /// Slots that may be non-zero.
    pub live: SlotSet,
}

impl<V: Vector> Deform<V> {
    /// `n` zero slots.
    pub fn new(n: usize) -> Deform<V> {
        Deform {
            slots: vec![Slot::ZERO; n],
            live: SlotSet::EMPTY,
        }
    }

    /// Number of slots.
    #[inline]
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// Whether there are no slots.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// Resets every slot to zero (no allocation).
    #[inline]
    pub fn clear(&mut self) {
        for j in self.live.iter() {
            self.slots[j] = Slot::ZERO;
        }
        for s in &mut self.slots {
            s.boundary = 0.0;
            s.boundary_scale = 0.0;
        }
        self.live = SlotSet::EMPTY;
    }

    /// Copies `o`'s state (same length; no allocation).
    #[inline]
    pub fn copy_from(&mut self, o: &Deform<V>) {
        self.slots.copy_from_slice(&o.slots);
        self.live = o.live;
    }

    /// Marks slot `j` live if its state is non-zero.
    #[inline]
    pub fn touch(&mut self, j: usize) {
        let s = &self.slots[j];
        if s.u != V::ZERO || s.wd != V::ZERO || s.score != 0.0 {
            self.live.insert(j);
        }
    }

    // ANCHOR: boundary_speed
    /// `ṫ_b` for every slot in `live ∪ moving` at the hit `h` of the ray
    /// from `x` along `w`: the hit point stays on the boundary, whose
    /// material points move at `v_j` for the slots in `moving` (those that
    /// move the hit shape; none in a frozen scene). Other slots get 0.
    #[inline]
    pub fn boundary_speed<G: Geometry<V = V>>(
        &mut self,
        g: &G,
        h: Hit,
        x: V,
        w: V,
        moving: SlotSet,
    ) {
        let y = x + w * h.t;
        let n = g.normal(h.prim, y);
        let wn = w.dot(n);
        for s in &mut self.slots {
            s.tb_dot = 0.0;
        }
        let k = g.shape(h.prim);
        for j in self.live.union(moving).iter() {
            let v = if moving.contains(j) && g.parameter_shape(j) == k {
                g.velocity(j, y)
            } else {
                V::ZERO
            };
            let s = &mut self.slots[j];
            let along = (v - s.u - s.wd * h.t).dot(n);
            // A boundary that moves with the vertex (a slab's far face, the
            // slab translated along its normal) leaves only the rounding of
            // the speeds subtracted: that is 0, not a tiny signal.
            let speeds = v.length() + s.u.length() + s.wd.length() * h.t;
            s.tb_dot = if within_rounding(along, speeds) {
                0.0
            } else {
                along / wn
            };
            if s.tb_dot != 0.0 {
                self.live.insert(j);
            }
        }
    }
    // ANCHOR_END: boundary_speed

    /// A fixed free path `ξ`: every live slot's vertex moves with its
    /// turning direction only, `u += ξ η̇`.
    #[inline]
    pub fn carry(&mut self, xi: f64) {
        for j in self.live.iter() {
            let s = &mut self.slots[j];
            s.u = s.u + s.wd * xi;
        }
    }

    /// Moves the vertex of every slot in `rule` onto the boundary at
    /// distance `t` along `w`: `u += ṫ_b η + t η̇`.
    #[inline]
    pub fn arrive(&mut self, rule: SlotSet, w: V, t: f64) {
        for j in self.live.and(rule).iter() {
            let s = &mut self.slots[j];
            s.u = s.u + w * s.tb_dot + s.wd * t;
        }
    }

    /// The transmittance over the segment to the boundary, `e^{−κe t_b}`,
    /// differentiated for every slot in `rule`.
    #[inline]
    pub fn pass(&mut self, rule: SlotSet, ke: f64) {
        for j in self.live.and(rule).iter() {
            let s = &mut self.slots[j];
            s.add_score(-ke * s.tb_dot);
        }
    }

    /// An emission of `contribution` collected: every live slot's score
    /// times it is a derivative term.
    #[inline]
    pub fn collect(&mut self, contribution: f64) {
        for j in self.live.iter() {
            let s = &mut self.slots[j];
            s.add_boundary(contribution * s.score, (contribution * s.score_scale).abs());
        }
    }
}

/// What a derivative walk differentiates: the shape parameters, then
/// optionally the sensor position's axes (`∂I/∂x`, …), and which slots move
/// each shape.
#[derive(Debug, Clone)]
pub struct Slots {
    /// Number of shape parameters (slots `0..params`).
    pub params: usize,
    /// Number of gradient axes after them (0 or the space's dimension).
    pub axes: usize,
    /// Per shape, the slots that move it.
    pub shape_slots: Vec<SlotSet>,
    /// The shape-parameter slots.
    pub parameter_slots: SlotSet,
    /// The gradient slots.
    pub gradient_slots: SlotSet,
    /// Number of twin slots after the gradient axes: 0, or one per
    /// parameter (transport's frozen-scene continuations, see
    /// [`Slots::twin`]; when `2 params + axes` fits in [`MAX_SLOTS`]).
    pub twins: usize,
    /// The twin slots.
    pub twin_slots: SlotSet,
}

impl Slots {
    /// The slots of `g`'s parameters (at most [`MAX_SLOTS`] in all, with
    /// the gradient axes when `gradient`, and a twin per parameter when
    /// `twins`), over `shapes` shapes.
    pub fn new<G: Geometry>(g: &G, shapes: usize, gradient: bool, twins: bool) -> Slots {
        let params = g.parameters();
        let axes = if gradient { G::V::DIM } else { 0 };
        let mut shape_slots = vec![SlotSet::EMPTY; shapes];
        for j in 0..params {
            shape_slots[g.parameter_shape(j) as usize].insert(j);
        }
        let parameter_slots = SlotSet::first(params);
        let all = SlotSet::first(params + axes);
        let mut gradient_slots = SlotSet::EMPTY;
        for j in all.iter().filter(|&j| j >= params) {
            gradient_slots.insert(j);
        }
        // Twins only where they fit (up to 126 parameters): past that the
        // nested walks they stand for are walked.
        let twins = if twins && 2 * params + axes <= MAX_SLOTS {
            params
        } else {
            0
        };
        let mut twin_slots = SlotSet::EMPTY;
        for j in params + axes..params + axes + twins {
            twin_slots.insert(j);
        }
        Slots {
            params,
            axes,
            shape_slots,
            parameter_slots,
            gradient_slots,
            twins,
            twin_slots,
        }
    }

    /// Number of slots.
    #[inline]
    pub fn len(&self) -> usize {
        self.params + self.axes + self.twins
    }

    /// The twin of parameter slot `j`: a slot that no shape moves, whose
    /// state is a frozen-scene continuation of the path (transport's
    /// nested frozen walks, carried by the path itself: they are linear in
    /// their start states). Its derivative adds to slot `j`'s.
    #[inline]
    pub fn twin(&self, j: usize) -> usize {
        self.params + self.axes + j
    }

    /// Whether there is no slot.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Every slot.
    #[inline]
    pub fn all(&self) -> SlotSet {
        self.parameter_slots
            .union(self.gradient_slots)
            .union(self.twin_slots)
    }

    /// The slots that follow the path with the scene frozen (rendering's
    /// rules): the gradient axes and the twins.
    #[inline]
    pub fn frozen_scene(&self) -> SlotSet {
        self.gradient_slots.union(self.twin_slots)
    }

    /// The slots that move shape `k`.
    #[inline]
    pub fn moving(&self, k: u32) -> SlotSet {
        self.shape_slots[k as usize]
    }

    /// A zeroed state whose gradient slots start moving with the sensor
    /// (`u = e_axis`).
    pub fn start<V: Vector>(&self, d: &mut Deform<V>) {
        for j in self.gradient_slots.iter() {
            d.slots[j].u = V::axis(j - self.params);
            d.live.insert(j);
        }
    }
}
