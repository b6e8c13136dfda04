//! The limits a scene of either dimension is held to, and the checks of
//! what flatland's and 3D's parameters share: the scene's extent, a
//! pivot's distance, a parameter's name. Book: chapter "When not to
//! trust a number", sections "Scale" and "Runs that end".
use super::config;
use crate::error::Error;

/// A scene's size (the largest extent of its vertices' bounding box) within
/// [`MIN_SIZE`]..[`MAX_SIZE`], and `far`, its farthest coordinate from the
/// origin, within [`MAX_OFFSET`] times it; returns the size. Flatland's
/// and 3D's validation both.
pub(crate) fn check_extent(size: f64, far: f64) -> Result<f64, Error> {
    if !(MIN_SIZE..=MAX_SIZE).contains(&size) {
        return config(format!(
            "the scene's size (largest extent of its vertices' bounding box) is {size:e}: \
             sizes from {MIN_SIZE:e} to {MAX_SIZE:e} are supported; rescale the scene \
             (only κ × size and ratios of lengths matter)"
        ));
    }
    if far > MAX_OFFSET * size {
        return config(format!(
            "the scene lies {far:e} from the origin, {:.1e} times its size {size:e}: \
             at most {MAX_OFFSET:e} times is supported (farther, its coordinates keep \
             too few digits of its geometry); move the scene nearer the origin",
            far / size
        ));
    }
    Ok(size)
}

/// Refuses a pivot farther than [`MAX_OFFSET`] sizes from the shape it
/// turns or scales (`distance`, along the farthest axis: a length would
/// overflow): the motion's velocities grow with that
/// distance, and past it a rotation read 0 with no warning (pivot 10¹⁶⁰
/// away) or its diagnostics NaN (10¹⁰⁰). Flatland's and 3D's validation
/// both.
pub(crate) fn check_pivot(name: &str, distance: f64, size: f64) -> Result<(), Error> {
    if distance > MAX_OFFSET * size {
        return config(format!(
            "parameter {name:?}: its pivot lies {distance:e} from the shape it moves, {:.1e} \
             times the scene's size {size:e}: at most {MAX_OFFSET:e} times is supported \
             (such a rotation or scale is a translation of enormous speed)",
            distance / size
        ));
    }
    Ok(())
}

/// Smallest and largest scene size accepted: within them every squared
/// length and cross product the tracer forms is a normal float, and so is
/// the fourth power of a translation's weight (∝ 1/size) that the
/// variance-of-the-variance diagnostic sums (beyond ~10^±75 it overflows and
/// the reliability flag would read "no" on a right answer).
pub const MIN_SIZE: f64 = 1e-60;
/// See [`MIN_SIZE`].
pub const MAX_SIZE: f64 = 1e60;

/// Farthest a scene's vertices may lie from the origin, in units of its
/// size: at 10⁶ sizes a coordinate keeps about ten significant digits of
/// the geometry, enough for every offset the tracer takes (measured
/// exact there; at 10⁷ a moving fog's derivative drifted by 3σ, at 10⁸ by
/// 86σ).
pub const MAX_OFFSET: f64 = 1e6;

/// Largest extinction coefficient times scene size accepted: beyond it a
/// medium is opaque for every purpose and the weights underflow.
pub const MAX_OPTICAL_THICKNESS: f64 = 1e4;

/// Most scattering events a path is expected to need in one medium.
pub const MAX_SCATTERING_EVENTS: f64 = 1e5;

/// Most parameters one path carries (with room for the sensor gradient's
/// axes in 3D): 253.
pub const MAX_PARAMETERS: usize = crate::path::deform::MAX_SLOTS - 3;

/// Rejects the name of parameter `j` if it is empty or if its output would
/// be taken for another quantity's: a gradient axis of `axes` (its
/// `∂I/∂x` row would stand beside the sensor gradient's, which transport
/// prints under the same name) or `I` (a rendering's intensity image, keyed
/// `I` beside the parameters' images in Python).
pub(crate) fn check_parameter_name(
    j: usize,
    p: &str,
    shape: &str,
    axes: &[&str],
) -> Result<(), Error> {
    let clash = if p.is_empty() {
        return config(format!("parameter {j} has an empty name"));
    } else if axes.contains(&p) {
        format!(
            "an axis of the sensor gradient: its ∂I/∂{p} could not be told from the \
             gradient's"
        )
    } else if p == "I" {
        "the intensity: a rendering's images of the two would share the key \"I\"".to_owned()
    } else {
        return Ok(());
    };
    config(format!(
        "parameter {p:?} has the name of {clash}; rename it (for example {:?})",
        format!("{shape}_{p}")
    ))
}
