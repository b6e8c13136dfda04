//! The methods over a scene of either dimension: [`Model`] is what the
//! method layer asks of a validated flatland or 3D scene, and on it one
//! [`Problem`] implementation builds every method's estimator (the
//! intensity loop, the three derivative schemes on the path core, and
//! [`finite_difference`]'s central differences). Book: chapter
//! "Where the code lives", and for what each method computes, chapters "Flatland"
//! and "Three dimensions".
use super::{Method, Problem};
use crate::error::Error;
use crate::estimator::{Estimator, Quantity};
use crate::fd::{
    CentralDifference, DEFAULT_STEP, Pair, check_step, invalid_displacement, thin_medium_caveat,
};
use crate::path::deform::Slots;
use crate::path::estimator::{DerivativeEstimator, Scheme};
use crate::path::intensity::IntensityEstimator;
use crate::path::nested::Budget;
use crate::path::{Boundaries, Surface};
use crate::scene::material::check_expectation_g;
use std::sync::Arc;

/// A validated scene as the method layer sees it, whatever its dimension:
/// its shapes' surfaces and media, its parameters, the path core's
/// geometry over it, and the dimension's own caveat detectors (where `I`
/// may have a kink, where a finite difference may straddle a change of
/// visibility).
pub trait Model: Sized + Send + Sync + 'static {
    /// The path core's geometry over the scene.
    type Geometry: Boundaries + 'static;
    /// What the finite-difference checks of one run share (computed once
    /// per scene, not per parameter).
    type FdView;
    /// What a shape is called in messages ("shape", "mesh").
    const SHAPE: &'static str;
    /// The axes of transport's sensor gradient (`∂I/∂x`, …).
    const GRADIENT_AXES: &'static [&'static str];

    /// The geometry over `scene`.
    fn geometry(scene: Arc<Self>) -> Self::Geometry;
    /// Whether the sensor is a camera (its images are of the parameters
    /// only: no sensor gradient).
    fn is_camera(&self) -> bool;
    /// How many shapes the scene holds.
    fn shape_count(&self) -> usize;
    /// Shape `k`'s name.
    fn shape_name(&self, k: u32) -> &str;
    /// Shape `k`'s surface.
    fn surface(&self, k: u32) -> Surface;
    /// Shape `k`'s medium: its scattering coefficient and its phase
    /// function's mean cosine, if it holds one.
    fn medium(&self, k: u32) -> Option<(f64, f64)>;
    /// A bound on the longest chord of shape `k`'s medium
    /// ([`crate::path::thin_media::chord_bound`]).
    fn chord(&self, k: u32) -> f64;
    /// The medium shape around shape `k`, if any.
    fn parent_medium(&self, k: u32) -> Option<u32>;
    /// The parameters' names, in order.
    fn parameter_names(&self) -> impl Iterator<Item = &str>;
    /// The shape parameter `j` moves.
    fn parameter_shape(&self, j: usize) -> u32;
    /// Whether parameter `j` translates its shape (its finite-difference
    /// step is then relative to the scene's size).
    fn translates(&self, j: usize) -> bool;
    /// The scene's size.
    fn size(&self) -> f64;
    /// The scene with parameter `j` changed by `delta`, validated again.
    fn displaced(&self, j: usize, delta: f64) -> Result<Self, Error>;

    /// What the scene measures (flatland's or 3D's sensor).
    type Sensor: Copy + Send + Sync + std::fmt::Debug;
    /// The scene's sensor.
    fn sensor(&self) -> Self::Sensor;
    /// The same shapes and parameters seen by `sensor`, validated again.
    fn with_sensor(&self, sensor: Self::Sensor) -> Result<Self, Error>;
    /// The scene at `offsets` from this pose, one per parameter
    /// ([`crate::scene::pose`]), validated again.
    fn posed(&self, offsets: &[f64]) -> Result<Self, Error>;
    /// `∂δ_j/∂θ_j` at offset `θ_j` ([`crate::scene::pose::Pose::offset_rate`]):
    /// the factor from this scene's `∂I/∂π_j` to the offset's.
    fn offset_rate(&self, j: usize, offset: f64) -> f64;
    /// Parameter `j`'s bounds, if any (offsets from this pose).
    fn bounds(&self, j: usize) -> Option<[f64; 2]>;
    /// The pixel count of a camera sensor (1 for a probe).
    fn pixels(sensor: &Self::Sensor) -> u64;

    /// Where `I` (or, with `gradient`, the sensor's gradient) may not be
    /// differentiable, for the derivative methods.
    fn derivative_caveats(geometry: &Self::Geometry, gradient: bool) -> Vec<(Quantity, String)>;
    /// The shared data of [`Model::fd_caveat`].
    fn fd_view(&self) -> Self::FdView;
    /// Why the central difference of `step` may not estimate the
    /// derivative, if it may not (the thin-medium caveat aside, which
    /// [`finite_difference`] adds).
    fn fd_caveat(&self, step: &Step<'_, Self>, view: &Self::FdView) -> Option<String>;
    /// The caveats of the nominal scene that also hold for finite
    /// differences (3D: faces seen edge-on, tied edges).
    fn fd_nominal_caveats(geometry: &Self::Geometry) -> Vec<(Quantity, String)>;
}

/// One parameter's central difference: the parameter `j`, the half step
/// `h` and the scenes displaced by `±h`.
pub struct Step<'a, S> {
    /// The parameter.
    pub j: usize,
    /// The half step.
    pub h: f64,
    /// The scene displaced by `+h`.
    pub plus: &'a S,
    /// The scene displaced by `−h`.
    pub minus: &'a S,
}

impl<S: Model> Problem for Arc<S> {
    /// For [`Method::Fd`] the half step is `fd_step` times the scene's size
    /// for a translation, `fd_step` radians for a rotation and `fd_step` for
    /// a scale.
    fn estimator(&self, method: Method, fd_step: Option<f64>) -> Result<Box<dyn Estimator>, Error> {
        let scene = Arc::clone(self);
        let scheme = match method {
            Method::Intensity => {
                return Ok(Box::new(IntensityEstimator {
                    geometry: S::geometry(scene),
                }));
            }
            Method::Fd => {
                let step = fd_step.map_or(Ok(DEFAULT_STEP), check_step)?;
                return Ok(Box::new(finite_difference(&scene, step)?));
            }
            Method::Expectation => {
                check_peaked_phase(&*scene)?;
                Scheme::Expectation
            }
            Method::Rendering => Scheme::Rendering,
            Method::Transport => Scheme::Transport,
        };
        Ok(Box::new(derivative(scene, scheme)))
    }
}

/// Refuses the expectation method on a medium whose phase function is too
/// peaked for it ([`crate::scene::material::MAX_EXPECTATION_G`]).
fn check_peaked_phase<S: Model>(scene: &S) -> Result<(), Error> {
    for k in 0..scene.shape_count() as u32 {
        if let Some((_, g)) = scene.medium(k) {
            check_expectation_g(S::SHAPE, scene.shape_name(k), g)?;
        }
    }
    Ok(())
}

/// The derivative estimator of `scheme` on `scene`.
pub fn derivative<S: Model>(scene: Arc<S>, scheme: Scheme) -> DerivativeEstimator<S::Geometry> {
    // The sensor position's gradient at a probe; a camera's images are of
    // the parameters only.
    let gradient = scheme == Scheme::Transport && !scene.is_camera();
    let mut names: Vec<Quantity> = scene.parameter_names().map(Quantity::sensitivity).collect();
    if gradient {
        names.extend(S::GRADIENT_AXES.iter().map(|axis| Quantity::gradient(axis)));
    }
    // Transport's twins serve moving reflectors only (elsewhere they would
    // be slots carried for nothing).
    let twins = scheme == Scheme::Transport
        && (0..scene.parameter_names().count()).any(|j| {
            matches!(
                scene.surface(scene.parameter_shape(j)),
                Surface::Reflector { .. }
            )
        });
    let shapes = scene.shape_count();
    let geometry = S::geometry(scene);
    let caveats = S::derivative_caveats(&geometry, gradient);
    let slots = Slots::new(&geometry, shapes, gradient, twins);
    DerivativeEstimator {
        geometry,
        slots,
        scheme,
        names,
        caveats,
        budget: Budget::default(),
    }
}

/// Central differences with common random numbers: `I` on the nominal
/// scene, then per parameter `j` the readings of the scene displaced by
/// `±h_j` (`h_j = step` × the scene's size for a translation, `step` for a
/// rotation or a scale), all from one generator state. Errors if a displaced
/// scene is invalid (shapes touching or crossing): the error names the
/// parameter and the displacement. Caveats: the dimension's own
/// ([`Model::fd_caveat`], then [`Model::fd_nominal_caveats`]) and the
/// thin-medium caveat ([`thin_medium_caveat`]).
pub fn finite_difference<S: Model>(scene: &Arc<S>, step: f64) -> Result<CentralDifference, Error> {
    let step = crate::error::check("h", step, step > 0.0, "a finite number > 0")?;
    let mut caveats = Vec::new();
    let mut pairs = Vec::new();
    let view = scene.fd_view();
    for (j, name) in scene.parameter_names().enumerate() {
        let (h, note) = if scene.translates(j) {
            (
                step * scene.size(),
                format!(" (half step {step} × scene size {})", scene.size()),
            )
        } else {
            (step, String::new())
        };
        let displaced = |delta: f64| -> Result<Arc<S>, Error> {
            scene
                .displaced(j, delta)
                .map(Arc::new)
                .map_err(|e| invalid_displacement("scene", name, delta, &note, e))
        };
        let (plus, minus) = (displaced(h)?, displaced(-h)?);
        let displaced = Step {
            j,
            h,
            plus: &*plus,
            minus: &*minus,
        };
        if let Some(c) = scene
            .fd_caveat(&displaced, &view)
            .or_else(|| thin_medium(&**scene, j))
        {
            caveats.push((name.to_owned(), c));
        }
        pairs.push(Pair {
            parameter: name.to_owned(),
            plus: Method::Intensity.estimator(plus)?,
            minus: Method::Intensity.estimator(minus)?,
            half_step: h,
        });
    }
    // The nominal scene's geometry serves its caveats and then the nominal
    // run.
    let nominal = S::geometry(Arc::clone(scene));
    for (q, why) in S::fd_nominal_caveats(&nominal) {
        if let Quantity::Sensitivity(name) = q
            && !caveats.iter().any(|c: &(String, String)| c.0 == name)
        {
            caveats.push((name, why));
        }
    }
    let nominal: Box<dyn Estimator> = Box::new(IntensityEstimator { geometry: nominal });
    let mut fd = CentralDifference::new(Some(nominal), pairs)?;
    for (parameter, why) in caveats {
        fd = fd.with_caveat(&parameter, why);
    }
    Ok(fd)
}

/// The thin-medium caveat of finite differences along parameter `j`
/// ([`thin_medium_caveat`]): the media of its shape and of the shape it
/// lies in.
fn thin_medium<S: Model>(scene: &S, j: usize) -> Option<String> {
    let k = scene.parameter_shape(j);
    let media = [Some(k), scene.parent_medium(k)]
        .into_iter()
        .flatten()
        .filter_map(|k| {
            let (ks, _) = scene.medium(k)?;
            Some((scene.shape_name(k), ks, scene.chord(k)))
        });
    thin_medium_caveat(media)
}
