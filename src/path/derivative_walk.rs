//! A derivative walk's state in one place ([`DerivativeWalk`]): what it
//! differentiates, whether its scene moves ([`SceneMotion`]), its
//! deformation and the scratch states and work its connections and nested
//! walks take. Each method's hooks hold one; the terms the methods share
//! are its methods (here the boundary speed of a segment; next-event
//! estimation, `connect`, beside rendering's hooks, which follow its
//! connections). Book: chapter "Flatland: one deformation, three
//! estimators", section "Next-event estimation in the derivative walks".
use super::deform::{Deform, SlotSet, Slots};
use super::nested::Scratch;
use super::{Geometry, Hit};

/// Whether a derivative walk's shapes move with their parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SceneMotion {
    /// They do: a path's own walk.
    Moving,
    /// They stand still, and only the velocities the walk starts with are
    /// differentiated: transport's frozen walks, which estimate a gradient
    /// of the radiance.
    Frozen,
}

/// A derivative walk's state, which each method's hooks hold: what it
/// differentiates and whether its scene moves, its deformation, and the
/// states and work its connections and nested walks take. The terms the
/// methods share (connections, rendering's Leibniz and corner terms) are
/// its methods.
pub struct DerivativeWalk<'a, G: Geometry> {
    /// What is differentiated.
    pub slots: &'a Slots,
    /// Whether the shapes move.
    pub scene: SceneMotion,
    /// States for connections and nested walks, and the path's work.
    pub scratch: &'a mut Scratch<G::V>,
    /// The walk's deformation.
    pub d: Deform<G::V>,
}

impl<G: Geometry> DerivativeWalk<'_, G> {
    /// The slots whose material points move on shape `k` (none in a frozen
    /// scene).
    #[inline]
    pub fn movers(&self, k: u32) -> SlotSet {
        match self.scene {
            SceneMotion::Moving => self.slots.moving(k),
            SceneMotion::Frozen => SlotSet::EMPTY,
        }
    }

    /// [`Deform::boundary_speed`] for the segment from `x` along `w` ending
    /// at `hit`, the hit shape moving for its [`movers`](Self::movers);
    /// every `ṫ_b` is 0 when the segment escapes.
    #[inline]
    pub fn segment(&mut self, g: &G, x: G::V, w: G::V, hit: Option<Hit>) {
        match hit {
            Some(h) => {
                let moving = self.movers(g.shape(h.prim));
                self.d.boundary_speed(g, h, x, w, moving);
            }
            None => self.d.slots.iter_mut().for_each(|s| s.tb_dot = 0.0),
        }
    }
}
