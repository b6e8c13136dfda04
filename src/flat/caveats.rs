//! Flatland's caveat detectors: where `I` may have a kink at the nominal
//! parameter ([`ties`]: corners aligned on a sight line from the sensor),
//! and where a central difference may straddle a change of visibility
//! (`view_change`). The estimators attach their messages to the
//! quantities concerned (`Estimator::caveats`). Book: chapter
//! "Choosing a method" (row 4, corners aligned) and chapter "When not to
//! trust a number", section "Finite differences across a change
//! of visibility".
use super::scene::Scene;
use crate::error::Num;
use crate::estimator::Quantity;
use crate::method::model::Step;

/// Largest angle (rad) between two corners' sight lines from the sensor
/// that [`ties`] takes for an alignment (the path core's, shared with 3D).
pub use crate::path::tolerance::TIE;

/// Where `I` may not be differentiable: two corners in front of an
/// irradiance sensor (or a camera) lie on one sight line, within [`TIE`]
/// (plus the rounding of their angles far from the origin),
/// the nearer visible and one of them on a moved shape (an occluder's end
/// exactly on a lamp end's sight line; a segment seen edge-on, its two
/// ends aligned). A corner of the moved shape then crosses the other's
/// sight line at the nominal parameter, and the one-sided derivatives
/// differ: each method returns one of them or neither, with an error bar
/// that cannot tell (seen in random scenes: rendering 1.009,
/// expectation 0, the two sides of the tie). One caveat per parameter of
/// such a shape. The 3D twin is [`crate::mesh::methods::kinks`].
pub fn ties(scene: &Scene) -> Vec<(Quantity, String)> {
    let Some((point, ahead)) = super::space::corners_ahead(scene) else {
        return Vec::new();
    };
    let corners = scene.corners();
    // Far from the origin a sight line's angle carries the rounding of
    // `q − point`: ~64 ulps of the coordinates over the distance (at 10⁸,
    // 2 850 away: 5·10⁻¹⁰ rad). An edge-on lamp 4·10⁻¹² rad wide there was
    // no tie by TIE alone, and expectation read −0.0015 against 0.0433,
    // "reliable" (seen in random scenes).
    let reach = corners
        .iter()
        .map(|c| c.0.abs().max_element())
        .fold(point.abs().max_element(), f64::max);
    let slack = |d: f64| 64.0 * f64::EPSILON * reach / d;
    let nearest = ahead.iter().map(|a| a.1).fold(f64::INFINITY, f64::min);
    let window = TIE + slack(nearest);
    let mut tied: Vec<(u32, u32)> = Vec::new();
    for (i, a) in ahead.iter().enumerate() {
        for b in ahead[i + 1..].iter().take_while(|b| b.0 - a.0 <= window) {
            if b.0 - a.0 > TIE + slack(a.1.min(b.1)) {
                continue;
            }
            let near = if a.1 <= b.1 { a.2 } else { b.2 };
            let (ka, kb) = (corners[a.2].1, corners[b.2].1);
            if scene.sees_corner(point, near, super::geometry::NO_SEGMENT) {
                tied.push((ka, kb));
            }
        }
    }
    let mut out = Vec::new();
    for (j, p) in scene.parameters().iter().enumerate() {
        let k = scene.parameter_shape(j);
        if let Some(&(ka, kb)) = tied.iter().find(|&&(a, b)| a == k || b == k) {
            let names = (
                &scene.shapes()[ka as usize].name,
                &scene.shapes()[kb as usize].name,
            );
            out.push((
                Quantity::sensitivity(&p.name),
                format!(
                    "corners of {:?} and {:?} lie on one sight line from the sensor: I may have \
                     a kink along {:?} (the one-sided derivatives differ) and the estimate is \
                     one of them or neither",
                    names.0, names.1, p.name
                ),
            ));
        }
    }
    out
}

/// Why the central difference along parameter `j` (half step `h`) may not
/// estimate the derivative, if it may not: the moved shape passes the
/// sensor within the step, or the sensor's view (the visible corners in
/// angular order, or what a radiance sensor's ray hits first) differs
/// between the two displaced scenes: the quotient then straddles a change of
/// visibility, and its error bar cannot see it.
pub(crate) fn view_change(scene: &Scene, step: &Step<'_, Scene>) -> Option<String> {
    let &Step { j, h, plus, minus } = step;
    let name = &scene.parameters()[j].name;
    let k = scene.parameter_shape(j) as usize;
    let shape = &scene.shapes()[k];
    let x = scene.sensor().point();
    let motion = scene.parameters()[j].motion;
    let travel = shape
        .vertices
        .iter()
        .map(|&q| (motion.apply(q, h) - q).length())
        .fold(0.0, f64::max);
    let distance = shape
        .segments()
        .map(|s| s.distance(x))
        .fold(f64::INFINITY, f64::min);
    if travel >= 0.5 * distance {
        return Some(format!(
            "finite differences along {name:?}: the step moves shape {:?} by {} while it \
             passes {} from the sensor; try a smaller --fd-step",
            shape.name,
            Num(round4(travel)),
            Num(round4(distance))
        ));
    }
    (sensor_view(plus) != sensor_view(minus)).then(|| {
        format!(
            "finite differences along {name:?}: the sensor's view (visible corners, their \
             order) differs between the scenes displaced by ±{}: the difference straddles a \
             change of visibility; try a smaller --fd-step",
            Num(round4(h))
        )
    })
}

/// `x` to 4 significant digits, for messages.
fn round4(x: f64) -> f64 {
    format!("{x:.3e}").parse().unwrap_or(x)
}

/// What the sensor sees, up to continuous motion: the corners visible from
/// an irradiance sensor or a camera in front of it, in angular order; the
/// shape a radiance sensor's ray meets first.
fn sensor_view(scene: &Scene) -> Vec<u32> {
    use super::Sensor;
    use super::geometry::NO_SEGMENT;
    match scene.sensor() {
        Sensor::Irradiance { .. } | Sensor::Camera { .. } => super::space::sensor_corners(scene)
            .into_iter()
            .map(|(_, i)| i as u32)
            .collect(),
        Sensor::Radiance { point, direction } => scene
            .opaque_hit(point, direction, NO_SEGMENT)
            .map(|h| h.2)
            .into_iter()
            .collect(),
    }
}
