//! Why a central difference along a parameter may not estimate the
//! derivative, beyond a change of the sensor's view ([`super::fd_view`]):
//! the step carries the mesh past the sensor, turns a face from facing the
//! sensor to facing away, or sweeps a shadow edge across most of a lamp.
//! Book: chapter "Reliability", section "Finite differences across a
//! change of visibility".
use crate::error::Num;
use crate::mesh::scene::geometry::point_triangle_distance;
use crate::mesh::scene::{Scene, bounds};
use crate::method::model::Step;

/// Why the central difference along parameter `j` (half step `h`) may not
/// estimate the derivative: as seen from the sensor, the half step turns a
/// vertex of the moved mesh by a quarter of an emitter's extent or more, so
/// one step may carry a shadow edge across most of the lamp (seen in a
/// random scene: a lamp 10⁻³ wide, the default step, fd 125.000
/// ± 7·10⁻⁹ marked reliable against the exact 500: the quotient had
/// saturated at the lamp's whole light over the step).
pub(crate) fn outruns_lamp(scene: &Scene, j: usize, h: f64) -> Option<String> {
    let p = &scene.parameters()[j];
    let k = scene.parameter_shape(j) as usize;
    let x = scene.sensor().point();
    let turn = scene.shapes()[k]
        .vertices
        .iter()
        .map(|&q| (p.motion.apply(q, h) - q).length() / (q - x).length())
        .fold(0.0, f64::max);
    scene
        .shapes()
        .iter()
        .filter(|s| matches!(s.surface, crate::path::Surface::Emitter { .. }))
        .find_map(|lamp| {
            let (lo, hi) = bounds(&lamp.vertices);
            let centre = 0.5 * (lo + hi);
            let extent = (hi - lo).length() / (centre - x).length();
            (turn >= 0.25 * extent).then(|| {
                format!(
                    "finite differences along {:?}: the half step turns mesh {:?} by {turn:.2e} \
                     rad as seen from the sensor, a quarter or more of emitter {:?} \
                     ({extent:.2e} rad across): a shadow edge may cross the lamp within the \
                     step; try a smaller --fd-step",
                    p.name,
                    scene.shapes()[k].name,
                    lamp.name,
                )
            })
        })
}

/// Why the central difference along parameter `j` (half step `h`) may not
/// estimate the derivative: the step moves the mesh by half its distance to
/// the sensor or more.
pub(crate) fn passes_sensor(scene: &Scene, j: usize, h: f64) -> Option<String> {
    let p = &scene.parameters()[j];
    let shape = &scene.shapes()[scene.parameter_shape(j) as usize];
    let x = scene.sensor().point();
    let travel = shape
        .vertices
        .iter()
        .map(|&q| (p.motion.apply(q, h) - q).length())
        .fold(0.0, f64::max);
    let distance = (0..shape.triangles.len())
        .map(|i| point_triangle_distance(x, shape.triangle(i)))
        .fold(f64::INFINITY, f64::min);
    (travel >= 0.5 * distance).then(|| {
        format!(
            "finite differences along {:?}: the step moves mesh {:?} by {} while it passes {} \
             from the sensor; try a smaller --fd-step",
            p.name,
            shape.name,
            Num(travel),
            Num(distance)
        )
    })
}

/// Why the central difference along parameter `j` (half step `h`) may not
/// estimate the derivative: a face of the moved mesh faces the sensor in
/// one displaced scene and turns its back on it in the other, so within
/// the step it is seen edge-on and the silhouette changes (a kink of `I`
/// inside the step: the quotient is neither one-sided derivative, with an
/// error bar that cannot see it). Seen in a random scene: a
/// tetrahedron whose face turned edge-on 10⁻⁴ rad from the nominal
/// rotation gave −0.0017 ± 0.0003 at the default step against the exact
/// −0.0054, marked reliable. Flatland's twin is its sensor-view test.
pub(crate) fn turns_face(scene: &Scene, step: &Step<'_, Scene>) -> Option<String> {
    let &Step { j, h, plus, minus } = step;
    let k = scene.parameter_shape(j) as usize;
    let x = scene.sensor().point();
    let facing = |s: &Scene, i: usize| {
        let t = s.shapes()[k].triangle(i);
        (t[1] - t[0]).cross(t[2] - t[0]).dot(x - t[0]) > 0.0
    };
    let shape = &scene.shapes()[k];
    let i = (0..shape.triangles.len()).find(|&i| facing(plus, i) != facing(minus, i))?;
    Some(format!(
        "finite differences along {:?}: triangle {i} of mesh {:?} turns from facing the sensor \
         to facing away between the scenes displaced by ±{}: it is seen edge-on within the step, \
         where the silhouette changes; try a smaller --fd-step",
        scene.parameters()[j].name,
        shape.name,
        Num(h)
    ))
}
