//! The flatland estimators behind the crate's [`Estimator`] interface: one
//! call samples one path (with its nested paths) and writes `I` then
//! `∂I/∂π_j` for every declared parameter, in declaration order.
//!
//! - [`Method::Intensity`]: backward path tracing, the path core's loop
//!   with no hooks ([`crate::path::walk`]);
//! - [`Method::Rendering`], [`Method::Expectation`], [`Method::Transport`]:
//!   the same loop with each method's hooks ([`crate::path::rendering`],
//!   [`crate::path::expectation`], [`crate::path::transport`]) over the
//!   plane's geometry ([`Plane`]);
//! - [`Method::Fd`]: central differences with common random numbers, one
//!   pair of displaced scenes per parameter ([`finite_difference`], built on
//!   [`crate::fd`]).
use super::scene::Scene;
use super::space::Plane;
use crate::error::{Error, check};
use crate::estimator::{Estimator, Quantity};
use crate::fd::{
    CentralDifference, DEFAULT_STEP, Pair, check_step, invalid_displacement, thin_medium_caveat,
};
use crate::method::Problem;
use crate::path::deform::Slots;
use crate::path::estimator::{DerivativeEstimator, Scheme};
use crate::path::intensity::IntensityEstimator;
use crate::path::nested::Budget;
use crate::path::thin_media::chord_bound;
use std::sync::Arc;

/// The methods: every [`Method`] runs on a flatland scene
/// (`method.estimator(scene)` with `scene: Arc<Scene>`).
pub use crate::method::Method;

impl Problem for Arc<Scene> {
    /// For [`Method::Fd`] the half step is `fd_step` times the scene's size
    /// for a translation, `fd_step` radians for a rotation and `fd_step` for a
    /// scale.
    fn estimator(&self, method: Method, fd_step: Option<f64>) -> Result<Box<dyn Estimator>, Error> {
        let scene = Arc::clone(self);
        let scheme = match method {
            Method::Intensity => {
                return Ok(Box::new(IntensityEstimator {
                    geometry: Plane::new(scene),
                }));
            }
            Method::Fd => {
                let step = fd_step.map_or(Ok(DEFAULT_STEP), check_step)?;
                return Ok(Box::new(finite_difference(&scene, step)?));
            }
            Method::Expectation => {
                check_peaked_phase(&scene)?;
                Scheme::Expectation
            }
            Method::Rendering => Scheme::Rendering,
            Method::Transport => Scheme::Transport,
        };
        Ok(Box::new(derivative(scene, scheme)))
    }
}

/// Largest `|g|` of a Henyey–Greenstein medium the expectation method
/// accepts. Its warp turns scattered directions relative to the incoming
/// one, so its score carries `∂ ln p` along the warp, of order `1/(1 − |g|)`:
/// measured on scenes/fog.toml, its σ is 1.2× rendering's at g = 0.9, 4× at
/// 0.99 and 44× at 0.999 (and ~10⁶× at 0.99999999, where no error bar of a
/// feasible run means anything).
pub const MAX_EXPECTATION_G: f64 = 0.99;

/// Refuses the expectation method on a medium whose phase function is too
/// peaked for it (see [`MAX_EXPECTATION_G`]).
fn check_peaked_phase(scene: &Scene) -> Result<(), Error> {
    for s in scene.shapes() {
        if let Some(super::Medium {
            phase: super::Phase::HenyeyGreenstein { g },
            ..
        }) = s.medium
        {
            check_expectation_g("shape", &s.name, g)?;
        }
    }
    Ok(())
}

/// Refuses a Henyey–Greenstein `g` beyond [`MAX_EXPECTATION_G`] for the
/// expectation method, naming the `kind` ("shape", "mesh") `name` holding
/// it; flatland and 3D share it.
pub(crate) fn check_expectation_g(kind: &str, name: &str, g: f64) -> Result<(), Error> {
    if g.abs() > MAX_EXPECTATION_G {
        return Err(Error::Scene(format!(
            "{kind} {name:?}: Henyey–Greenstein g = {g} is too peaked for the expectation \
             method (|g| ≤ {MAX_EXPECTATION_G}: its variance grows as 1/(1 − |g|)²); \
             use rendering or transport"
        )));
    }
    Ok(())
}

/// The derivative estimator of `scheme` on `scene`.
pub fn derivative(scene: Arc<Scene>, scheme: Scheme) -> DerivativeEstimator<Plane> {
    // The sensor position's gradient at a probe; a camera's images are of
    // the parameters only.
    let camera = matches!(scene.sensor(), super::Sensor::Camera { .. });
    let gradient = scheme == Scheme::Transport && !camera;
    let mut names: Vec<Quantity> = scene
        .parameters()
        .iter()
        .map(|p| Quantity::sensitivity(&p.name))
        .collect();
    if gradient {
        names.extend(super::scene::GRADIENT_AXES.map(Quantity::gradient));
    }
    // Transport's twins serve moving reflectors only (elsewhere they would
    // be slots carried for nothing).
    let twins = scheme == Scheme::Transport
        && (0..scene.parameters().len()).any(|j| {
            let k = scene.parameter_shape(j) as usize;
            matches!(scene.shapes()[k].surface, super::Surface::Reflector { .. })
        });
    let caveats = ties(&scene);
    let geometry = Plane::new(scene);
    let slots = Slots::new(&geometry, geometry.scene().shapes().len(), gradient, twins);
    DerivativeEstimator {
        geometry,
        slots,
        scheme,
        names,
        caveats,
        budget: Budget::default(),
    }
}

/// Largest angle (rad) between two corners' sight lines from the sensor
/// that [`ties`] takes for an alignment: the rounding of an exact one.
pub const TIE: f64 = 1e-12;

/// Where `I` may not be differentiable: two corners in front of an
/// irradiance sensor (or a camera) lie on one sight line, within [`TIE`]
/// (plus the rounding of their angles far from the origin),
/// the nearer visible and one of them on a moved shape (an occluder's end
/// exactly on a lamp end's sight line; a segment seen edge-on, its two
/// ends aligned). A corner of the moved shape then crosses the other's
/// sight line at the nominal parameter, and the one-sided derivatives
/// differ: each method returns one of them or neither, with an error bar
/// that cannot tell (found by a random-scene campaign: rendering 1.009,
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
    // "reliable" (campaign).
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

/// Central differences with common random numbers: `I` on the nominal
/// scene, then per parameter `j` the readings of the scene displaced by
/// `±h_j` (`h_j = step` × the scene's size for a translation, `step` for a
/// rotation or a scale), all from one generator state. Errors if a displaced
/// scene is invalid (shapes touching): the error names the parameter and the
/// displacement.
pub fn finite_difference(scene: &Arc<Scene>, step: f64) -> Result<CentralDifference, Error> {
    let step = check("h", step, step > 0.0, "a finite number > 0")?;
    let pairs = scene
        .parameters()
        .iter()
        .enumerate()
        .map(|(j, p)| {
            let (h, note) = match p.motion {
                super::Motion::TranslateX | super::Motion::TranslateY => (
                    step * scene.size(),
                    format!(" (half step {step} × scene size {})", scene.size()),
                ),
                _ => (step, String::new()),
            };
            let displaced = |delta: f64| -> Result<Arc<Scene>, Error> {
                scene
                    .displaced(j, delta)
                    .map(Arc::new)
                    .map_err(|e| invalid_displacement("scene", &p.name, delta, &note, e))
            };
            let (plus, minus) = (displaced(h)?, displaced(-h)?);
            let caveat = view_change(scene, j, h, &plus, &minus).or_else(|| thin_medium(scene, j));
            Ok((
                Pair {
                    parameter: p.name.clone(),
                    plus: Method::Intensity.estimator(plus)?,
                    minus: Method::Intensity.estimator(minus)?,
                    half_step: h,
                },
                caveat,
            ))
        })
        .collect::<Result<Vec<_>, Error>>()?;
    let mut caveats = Vec::new();
    let pairs = pairs
        .into_iter()
        .map(|(pair, caveat)| {
            if let Some(c) = caveat {
                caveats.push((pair.parameter.clone(), c));
            }
            pair
        })
        .collect();
    let mut fd =
        CentralDifference::new(Some(Method::Intensity.estimator(Arc::clone(scene))?), pairs)?;
    for (parameter, why) in caveats {
        fd = fd.with_caveat(&parameter, why);
    }
    Ok(fd)
}

/// Why the central difference along parameter `j` (half step `h`) may not
/// estimate the derivative, if it may not: the moved shape passes the
/// sensor within the step, or the sensor's view (the visible corners in
/// angular order, or what a radiance sensor's ray hits first) differs
/// between the two displaced scenes: the quotient then straddles a change of
/// visibility, and its error bar cannot see it.
fn view_change(scene: &Scene, j: usize, h: f64, plus: &Scene, minus: &Scene) -> Option<String> {
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
            crate::error::Num(round4(travel)),
            crate::error::Num(round4(distance))
        ));
    }
    (sensor_view(plus) != sensor_view(minus)).then(|| {
        format!(
            "finite differences along {name:?}: the sensor's view (visible corners, their \
             order) differs between the scenes displaced by ±{}: the difference straddles a \
             change of visibility; try a smaller --fd-step",
            crate::error::Num(round4(h))
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

/// The expectation method's warp field at the sensor: `V_j(φ)` (rad per
/// unit of parameter `j`) of the looking direction at angle `phi` from +x,
/// for every parameter. For an irradiance sensor, directions behind it get
/// 0 (the field is pinned to the frame at the horizons).
pub fn sensor_warp(plane: &Plane, phi: f64) -> Vec<f64> {
    super::boundaries::sensor_warp(plane, phi)
}

/// The thin-medium caveat of finite differences along parameter `j`
/// ([`thin_medium_caveat`]): the media of its shape and of the shape it
/// lies in.
fn thin_medium(scene: &Scene, j: usize) -> Option<String> {
    let k = scene.parameter_shape(j);
    let media = [Some(k), scene.parent_medium(k)]
        .into_iter()
        .flatten()
        .filter_map(|k| {
            let s = &scene.shapes()[k as usize];
            let m = s.medium.as_ref()?;
            Some((s.name.as_str(), m.ks, chord_bound(&s.vertices)))
        });
    thin_medium_caveat(media)
}
