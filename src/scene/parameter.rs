//! Shape parameters as data, whatever the dimension: a [`Parameter`] names
//! the shape it moves and carries the dimension's motion (flatland's
//! `flat::Motion`, 3D's `mesh::Motion`); `resolve_parameters` checks a
//! scene's list (how many, their names, their shapes) and lets the
//! dimension resolve each motion (pivots, axes). Book: chapter "Scene files:
//! a reference".
use super::config;
use super::limits::{MAX_PARAMETERS, check_parameter_name};
use crate::error::Error;
use serde::{Deserialize, Serialize};
use std::collections::HashSet;

/// A shape parameter π whose sensitivity `∂I/∂π` is estimated; `M` is the
/// dimension's motion.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Parameter<M> {
    /// Unique name (the key of its sensitivity).
    pub name: String,
    /// Name of the shape it moves (with its medium).
    pub shape: String,
    /// How it moves it.
    pub motion: M,
    /// For an optimisation, the interval its offset from the file's pose
    /// stays in (`[lo, hi]`, `lo ≤ 0 ≤ hi`); none: unbounded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bounds: Option<[f64; 2]>,
}

/// The parameters with their motions resolved by `resolve(parameter,
/// shape index)` (pivots, axes), and the index of the shape each moves;
/// rejects more than [`MAX_PARAMETERS`], empty or duplicate names, names
/// of the sensor gradient's `axes` or of the intensity, and unknown
/// shapes (`shapes`: the shapes' names, in order).
pub(crate) fn resolve_parameters<M>(
    shapes: &[&str],
    parameters: &[Parameter<M>],
    axes: &[&str],
    mut resolve: impl FnMut(&Parameter<M>, usize) -> Result<M, Error>,
) -> Result<(Vec<Parameter<M>>, Vec<u32>), Error> {
    if parameters.len() > MAX_PARAMETERS {
        return config(format!(
            "{} parameters: at most {MAX_PARAMETERS} are supported",
            parameters.len()
        ));
    }
    let mut parameter_shape = Vec::with_capacity(parameters.len());
    let mut resolved = Vec::with_capacity(parameters.len());
    let mut names = HashSet::with_capacity(parameters.len());
    for (j, p) in parameters.iter().enumerate() {
        check_parameter_name(j, &p.name, &p.shape, axes)?;
        if !names.insert(p.name.as_str()) {
            return config(format!("two parameters are named {:?}", p.name));
        }
        let Some(k) = shapes.iter().position(|&s| s == p.shape) else {
            return config(format!(
                "parameter {:?} moves shape {:?}, which does not exist",
                p.name, p.shape
            ));
        };
        if let Some(b) = p.bounds {
            super::objective::check_bounds(&p.name, b)?;
        }
        let motion = resolve(p, k)?;
        parameter_shape.push(k as u32);
        resolved.push(Parameter {
            name: p.name.clone(),
            shape: p.shape.clone(),
            motion,
            bounds: p.bounds,
        });
    }
    Ok((resolved, parameter_shape))
}

/// Parameter `j` of `parameters`, to be displaced by `delta`; refuses an
/// index out of range and a displacement that is not finite.
pub(crate) fn displaced<M>(
    parameters: &[Parameter<M>],
    j: usize,
    delta: f64,
) -> Result<&Parameter<M>, Error> {
    let Some(p) = parameters.get(j) else {
        return config(format!("no parameter {j}"));
    };
    if !delta.is_finite() {
        return config(format!("displacement {delta} is not finite"));
    }
    Ok(p)
}
