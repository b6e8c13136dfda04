//! A scene at offsets `θ` from its file's pose, written once for both
//! dimensions: the map the optimiser moves along, chosen so that the
//! derivative methods' `∂I/∂π_j` at the posed scene is exactly `∂I/∂θ_j`.
//! Book: chapter "Sensitivities at work", section "Moving the scene".
//!
//! Per shape, its rotation or scale (at most one) acts first, about its
//! pivot `p`, then its translations: `x ↦ R_θ(x₀) + t`. A translation's
//! velocity is then its axis, as the estimators assume; the rotation's (or
//! scale's) velocity at the posed point is the rotation's about `p + t`, so
//! the posed scene's parameters carry their pivot along with the
//! translation. A scale's velocity is relative to the posed size, so its
//! derivative takes the chain rule's factor `1/(1 + θ)`
//! ([`Pose::offset_rate`]). Two rotations of one shape would not compose this way
//! (their derivatives would be pushed through each other), and are refused.
use super::config;
use super::parameter::Parameter;
use crate::error::Error;
use std::ops::Add;

/// What posing needs of a motion.
pub trait Pose: Copy {
    /// The dimension's point.
    type V: Copy + Add<Output = Self::V>;
    /// `q` moved by the motion's parameter `delta`.
    fn apply(&self, q: Self::V, delta: f64) -> Self::V;
    /// The displacement of a translation by `delta`; `None` for a
    /// rotation or a scale.
    fn translation(&self, delta: f64) -> Option<Self::V>;
    /// Whether the motion is a translation.
    fn is_translation(&self) -> bool {
        self.translation(0.0).is_some()
    }
    /// The same motion with its pivot (if any) moved by `d`.
    fn pivot_moved(&self, d: Self::V) -> Self;
    /// `∂δ/∂θ`: how the motion's own parameter `δ` at the posed scene
    /// moves with the offset `θ`. 1 for a translation and a rotation
    /// (`R(θ + δ) = R(δ) R(θ)` about one pivot and axis); `1 + θ` for a
    /// scale, whose posed size is `(1 + θ)` times the file's, so that
    /// `(1 + δ)(1 + θ) = 1 + θ + δ (1 + θ)`: the estimators' `∂I/∂δ` is
    /// `(1 + θ) ∂I/∂θ`.
    fn offset_rate(&self, offset: f64) -> f64 {
        let _ = offset;
        1.0
    }
}

/// What posing needs of a shape.
pub trait Posable {
    /// The dimension's point.
    type V;
    /// The shape's vertices.
    fn vertices_mut(&mut self) -> &mut [Self::V];
}

/// Refuses a shape moved by more than one rotation or scale.
pub fn check_poseable<M: Pose>(
    parameters: &[Parameter<M>],
    parameter_shape: &[u32],
) -> Result<(), Error> {
    for (j, p) in parameters.iter().enumerate() {
        if p.motion.is_translation() {
            continue;
        }
        if let Some(i) = (0..j).find(|&i| {
            parameter_shape[i] == parameter_shape[j] && !parameters[i].motion.is_translation()
        }) {
            return config(format!(
                "parameters {:?} and {:?} both turn or scale shape {:?}: an optimisation \
                 moves each shape by translations and at most one rotation or scale",
                parameters[i].name, p.name, p.shape
            ));
        }
    }
    Ok(())
}

/// `shapes` and `parameters` (pivots resolved, at the file's pose) moved to
/// `offsets`: the posed shapes and the parameters with their pivots carried
/// along. The caller validates the result (a scene may become invalid).
pub fn pose<M: Pose, S: Posable<V = M::V> + Clone>(
    shapes: &[S],
    parameters: &[Parameter<M>],
    parameter_shape: &[u32],
    offsets: &[f64],
) -> Result<(Vec<S>, Vec<Parameter<M>>), Error> {
    check_poseable(parameters, parameter_shape)?;
    if offsets.len() != parameters.len() {
        return config(format!(
            "{} offsets for {} parameters",
            offsets.len(),
            parameters.len()
        ));
    }
    if let Some(d) = offsets.iter().find(|d| !d.is_finite()) {
        return config(format!("offset {d} is not finite"));
    }
    let mut shapes = shapes.to_vec();
    let mut posed = parameters.to_vec();
    // An offset of 0 leaves its shape as it is, bit for bit (a turn by 0
    // would round): an unmoved mesh keeps its tables.
    for (j, p) in parameters.iter().enumerate() {
        if !p.motion.is_translation() && offsets[j] != 0.0 {
            let k = parameter_shape[j] as usize;
            for v in shapes[k].vertices_mut() {
                *v = p.motion.apply(*v, offsets[j]);
            }
        }
    }
    for (j, p) in parameters.iter().enumerate() {
        let Some(d) = p
            .motion
            .translation(offsets[j])
            .filter(|_| offsets[j] != 0.0)
        else {
            continue;
        };
        let k = parameter_shape[j];
        for v in shapes[k as usize].vertices_mut() {
            *v = *v + d;
        }
        for (i, q) in posed.iter_mut().enumerate() {
            if parameter_shape[i] == k && !q.motion.is_translation() {
                q.motion = q.motion.pivot_moved(d);
            }
        }
    }
    Ok((shapes, posed))
}
