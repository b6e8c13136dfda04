//! One estimation as data: what `geosens rod`, `geosens flat` and `geosens
//! mesh` run ([`Job`]): the rod and probe or the scene, the method, the
//! finite differences' step. The command line, the Python package and the
//! shards of a run ([`crate::shard`]) build their estimator here, so they
//! estimate the same thing, refuse the same input with the same message, and
//! print the same [`Report`].
//!
//! ```
//! use geosens::job::{Job, SceneSource, Target};
//! use geosens::shard::{Merged, Shard, merge};
//! use geosens::{Method, RunConfig};
//!
//! let job = Job {
//!     target: Target::Flat(SceneSource::File("scenes/occluder.toml".into())),
//!     method: Some(Method::Expectation),
//!     fd_step: None,
//! };
//! let cfg = RunConfig::new(100_000, 7)?;
//! let single = job.run(&cfg, &geosens::runner::quiet)?;
//! // The same run in two shards (two processes, two machines), merged.
//! let states = [1, 2].map(|i| job.run_shard(&cfg, Shard::new(i, 2).unwrap(), &geosens::runner::quiet));
//! let labelled: Vec<_> = states
//!     .into_iter()
//!     .enumerate()
//!     .map(|(i, s)| Ok((format!("shard {}", i + 1), s?)))
//!     .collect::<Result<_, geosens::Error>>()?;
//! let Merged::Probe(merged) = merge(&labelled)? else { unreachable!() };
//! assert_eq!(merged.result.estimates, single.result.estimates);
//! println!("{}", single.json()?); // what `geosens flat --json` prints
//! # Ok::<(), geosens::Error>(())
//! ```
use crate::error::Error;
use crate::estimator::{Estimator, Quantity};
use crate::method::{Method, Problem};
use crate::optimize::Study;
use crate::report::{Header, Report, RodProbe, rod_exact, rod_quantities};
use crate::runner::{RunConfig, RunResult, run_with_progress};
use crate::stats::Estimate;
use crate::{flat, mesh};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Parses a method's name, or `exact` (the rod's exact solution, `None`)
/// where `exact` is allowed; the error lists the names accepted.
pub fn parse_method(name: &str, exact: bool) -> Result<Option<Method>, Error> {
    if exact && name == "exact" {
        return Ok(None);
    }
    name.parse::<Method>().map(Some).map_err(|_| {
        let names: Vec<&str> = exact
            .then_some("exact")
            .into_iter()
            .chain(Method::ALL.iter().map(|m| m.name()))
            .collect();
        Error::Config(format!(
            "unknown method {name:?}: expected one of {}",
            names.join(", ")
        ))
    })
}

/// Where a scene comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum SceneSource {
    /// A scene file, TOML or JSON by its extension; OBJ paths are relative
    /// to its folder.
    File(PathBuf),
    /// The file's schema as JSON text (what a Python dict becomes); OBJ
    /// paths are relative to the current directory.
    Json(String),
}

impl SceneSource {
    /// The scene's name in tables and messages: its file, or `<dict>`.
    pub fn name(&self) -> String {
        match self {
            SceneSource::File(p) => p.display().to_string(),
            SceneSource::Json(_) => "<dict>".to_owned(),
        }
    }

    /// The file, if the scene is one.
    fn path(&self) -> Option<&Path> {
        match self {
            SceneSource::File(p) => Some(p),
            SceneSource::Json(_) => None,
        }
    }

    /// The scene's dimension (2 or 3, by its sensor's point), if it says
    /// ([`crate::scene::file::dimension_of`]).
    pub fn dimension(&self) -> Result<Option<usize>, Error> {
        match self {
            SceneSource::File(p) => crate::scene::file::dimension(p),
            SceneSource::Json(text) => {
                let value: serde_json::Value = serde_json::from_str(text)
                    .map_err(|e| Error::Scene(format!("the scene is not JSON: {e}")))?;
                Ok(crate::scene::file::dimension_of(&value))
            }
        }
    }

    /// Errors if the scene is of another dimension than `want`, with a
    /// message that names the command to use (the loader's own would name
    /// a field); a scene that does not say is left to the loader.
    fn check_dimension(&self, want: usize) -> Result<(), Error> {
        let got = match self.dimension()? {
            Some(got) if got != want => got,
            _ => return Ok(()),
        };
        let (is, use_) = if got == 2 {
            ("a flatland (2D) scene", "flat")
        } else {
            ("a 3D scene", "mesh")
        };
        Err(Error::Scene(format!(
            "{}: this is {is} (its points have {got} coordinates): use `geosens {use_}`",
            self.name()
        )))
    }

    /// The flatland scene.
    pub fn flat(&self) -> Result<flat::Scene, Error> {
        match self {
            SceneSource::File(p) => flat::file::load(p),
            SceneSource::Json(text) => flat::file::from_json(text),
        }
    }

    /// The 3D scene.
    pub fn mesh(&self) -> Result<mesh::Scene, Error> {
        match self {
            SceneSource::File(p) => mesh::file::load(p),
            SceneSource::Json(text) => mesh::file::from_json(text),
        }
    }

    /// The flatland scene's optimisation problem (its `[objective]` and
    /// `[[measurements]]`).
    pub fn flat_study(&self) -> Result<Study<flat::Scene>, Error> {
        match self {
            SceneSource::File(p) => flat::file::load_study(p),
            SceneSource::Json(text) => flat::file::study_from_json(text),
        }
    }

    /// The 3D scene's optimisation problem.
    pub fn mesh_study(&self) -> Result<Study<mesh::Scene>, Error> {
        match self {
            SceneSource::File(p) => mesh::file::load_study(p),
            SceneSource::Json(text) => mesh::file::study_from_json(text),
        }
    }

    /// The flatland (`flat`) or 3D scene's estimator of `method`, with the
    /// scene's numbers of shapes and parameters and what a shard hashes.
    fn estimator(
        &self,
        flat: bool,
        method: Method,
        fd_step: Option<f64>,
    ) -> Result<SceneEstimator, Error> {
        let path = self.path();
        if flat {
            let scene = Arc::new(self.flat()?);
            let sizes = (scene.shapes().len(), scene.parameters().len());
            let est = estimator_of(method, Arc::clone(&scene), fd_step, path)?;
            Ok((est, sizes, Canonical::Flat(scene)))
        } else {
            let scene = Arc::new(self.mesh()?);
            let sizes = (scene.shapes().len(), scene.parameters().len());
            let est = estimator_of(method, Arc::clone(&scene), fd_step, path)?;
            Ok((est, sizes, Canonical::Mesh(scene)))
        }
    }
}

/// A scene's estimator, its numbers of shapes and parameters, and what a
/// shard of its run hashes.
type SceneEstimator = (Box<dyn Estimator>, (usize, usize), Canonical);

/// What a job estimates on.
#[derive(Debug, Clone, PartialEq)]
pub enum Target {
    /// A probe on a rod.
    Rod(RodProbe),
    /// A flatland scene (`geosens flat`).
    Flat(SceneSource),
    /// A 3D scene (`geosens mesh`).
    Mesh(SceneSource),
}

/// The closed form of a [`Target`] ([`Target::exact`]): `I`, every
/// parameter's `∂I/∂π` by name, and the sensor's spatial gradient by axis
/// where it is known, in the order the estimates' JSON line gives them.
#[derive(Debug, Clone, PartialEq)]
pub struct Exact {
    /// `I` (a scene's: the irradiance `E`).
    pub intensity: f64,
    /// `∂I/∂π` per parameter: the rod's `length`, a scene's parameters.
    pub sensitivity: Vec<(String, f64)>,
    /// `∂I/∂x`, … at the sensor: the rod's `x`, flatland's `x`, `y`;
    /// `None` in 3D, whose closed form does not give it.
    pub gradient: Option<Vec<(String, f64)>>,
}

impl Target {
    /// The target's closed form, nothing sampled: the rod's Bellman–Wing
    /// solution ([`crate::rod::exact`]), a flatland scene's
    /// ([`flat::exact::Reference`]: an irradiance sensor, one emitter
    /// segment, black occluders, at most one absorbing medium) or a 3D
    /// scene's ([`mesh::exact::Reference`]: an irradiance sensor, a flat
    /// convex emitter, at most one convex black occluder). A scene without
    /// one is an [`Error::Scene`] that names it and says why.
    pub fn exact(&self) -> Result<Exact, Error> {
        let named = |source: &SceneSource, e: Error| match e {
            Error::Scene(msg) => Error::Scene(format!("{}: {msg}", source.name())),
            other => other,
        };
        let names = |params: Vec<String>, value: &dyn Fn(usize) -> f64| {
            params
                .into_iter()
                .enumerate()
                .map(|(j, name)| (name, value(j)))
                .collect()
        };
        match self {
            Target::Rod(given) => {
                let (rod, probe) = given.build()?;
                let [i, s, g] = rod_exact(&rod, &probe);
                Ok(Exact {
                    intensity: i,
                    sensitivity: vec![(crate::rod::PARAMETER.to_owned(), s)],
                    gradient: Some(vec![("x".to_owned(), g)]),
                })
            }
            Target::Flat(source) => {
                source.check_dimension(2)?;
                let scene = source.flat()?;
                let r = flat::exact::Reference::for_scene(&scene).map_err(|e| named(source, e))?;
                let (gx, gy) = r.gradient();
                let params = scene.parameters().iter().map(|p| p.name.clone()).collect();
                Ok(Exact {
                    intensity: r.value(),
                    sensitivity: names(params, &|j| r.derivative(j)),
                    gradient: Some(vec![("x".to_owned(), gx), ("y".to_owned(), gy)]),
                })
            }
            Target::Mesh(source) => {
                source.check_dimension(3)?;
                let scene = source.mesh()?;
                let r = mesh::exact::Reference::for_scene(&scene).map_err(|e| named(source, e))?;
                let params = scene.parameters().iter().map(|p| p.name.clone()).collect();
                Ok(Exact {
                    intensity: r.value(),
                    sensitivity: names(params, &|j| r.derivative(j)),
                    gradient: None,
                })
            }
        }
    }
}

/// One estimation: a target, a method and the finite differences' step.
#[derive(Debug, Clone, PartialEq)]
pub struct Job {
    /// What to estimate on.
    pub target: Target,
    /// The method; `None` is the rod's exact solution (nothing sampled).
    pub method: Option<Method>,
    /// The half step of [`Method::Fd`] (its default if `None`); an error
    /// with any other method.
    pub fd_step: Option<f64>,
}

/// A job's estimator, built and checked, with what its printing and its
/// shards need.
pub struct Prepared {
    /// The estimator; `None` for the rod's exact solution.
    pub estimator: Option<Box<dyn Estimator>>,
    /// What the table's first line says.
    pub header: Header,
    /// The estimator's caveats.
    pub caveats: Vec<(Quantity, String)>,
    /// The canonical text of what is estimated on (the rod's numbers, the
    /// scene with its meshes inline), hashed into a shard's state.
    canonical: Canonical,
}

/// What the hash of a job covers, kept unformatted until a shard needs it
/// (a 3D scene's text takes a while to write).
#[allow(missing_docs)]
pub enum Canonical {
    Rod([f64; 5]),
    Flat(Arc<flat::Scene>),
    Mesh(Arc<mesh::Scene>),
}

impl Prepared {
    /// The text a shard's state hashes ([`Canonical::text`]).
    pub fn canonical_text(&self, fd_step: Option<f64>) -> Result<String, Error> {
        self.canonical.text(fd_step)
    }
}

impl Canonical {
    /// The text a shard's state hashes: the crate version, the runner's
    /// chunking, the step of `fd`, and the rod or the scene in full.
    pub fn text(&self, fd_step: Option<f64>) -> Result<String, Error> {
        let what = match self {
            Canonical::Rod(v) => format!("rod {:?}", v.map(f64::to_bits)),
            Canonical::Flat(s) => serde_json::to_string(&flat::file::SceneFile::of(s))
                .map_err(|e| Error::Output(e.to_string()))?,
            Canonical::Mesh(s) => mesh::file::to_json(s)?,
        };
        Ok(format!(
            "geosens {}\nchunk {} block {}\nfd_step {:?}\n{what}",
            env!("CARGO_PKG_VERSION"),
            crate::runner::CHUNK,
            crate::runner::BLOCK,
            fd_step.map(f64::to_bits),
        ))
    }
}

impl Job {
    /// Builds the estimator, checking every input: the rod and probe, the
    /// scene (and that its dimension matches the target), that `fd_step`
    /// goes with `fd`, that the sensor is not a camera (its images come from
    /// `geosens render`).
    pub fn prepare(&self) -> Result<Prepared, Error> {
        let method = self.method;
        check_fd_step(method, self.fd_step)?;
        match &self.target {
            Target::Rod(given) => {
                let (rod, probe) = given.build()?;
                let estimator = match method {
                    Some(m) => Some(estimator_of(m, (rod, probe), self.fd_step, None)?),
                    None => None,
                };
                let r = RodProbe::of(&rod, &probe);
                Ok(Prepared {
                    caveats: estimator.as_ref().map_or(Vec::new(), |e| e.caveats()),
                    estimator,
                    header: Header::Rod(r),
                    canonical: Canonical::Rod([r.ks, r.ke, r.length, r.x, r.omega]),
                })
            }
            Target::Flat(source) | Target::Mesh(source) => {
                let flat = matches!(self.target, Target::Flat(_));
                source.check_dimension(if flat { 2 } else { 3 })?;
                let m = method.ok_or_else(|| {
                    Error::Config("the exact solution is the rod's only (--method exact)".into())
                })?;
                let (estimator, (shapes, parameters), canonical) =
                    source.estimator(flat, m, self.fd_step)?;
                if estimator.image().is_some() {
                    return Err(Error::Config(format!(
                        "{}: the sensor is a camera: its images come from `geosens render`",
                        source.name()
                    )));
                }
                Ok(Prepared {
                    caveats: estimator.caveats(),
                    estimator: Some(estimator),
                    header: Header::Scene {
                        scene: source.name(),
                        shapes,
                        parameters,
                    },
                    canonical,
                })
            }
        }
    }

    /// Runs the job: what `geosens rod`, `flat` or `mesh` prints, as a
    /// [`Report`]. `progress` is called with the paths sampled so far
    /// ([`crate::runner::run_with_progress`]).
    pub fn run(&self, cfg: &RunConfig, progress: crate::runner::Progress) -> Result<Report, Error> {
        crate::runner::check_threads(cfg.threads)?;
        let prepared = self.prepare()?;
        let result = match &prepared.estimator {
            Some(est) => run_with_progress(est.as_ref(), cfg, progress)?,
            None => exact_result(&prepared.header)?,
        };
        Ok(Report {
            header: prepared.header,
            result,
            seed: cfg.seed,
            caveats: prepared.caveats,
        })
    }
}

/// Errors if `fd_step` is given for a method other than [`Method::Fd`]
/// (`None`: the rod's exact solution).
fn check_fd_step(method: Option<Method>, fd_step: Option<f64>) -> Result<(), Error> {
    if fd_step.is_some() && method != Some(Method::Fd) {
        let name = method.map_or("exact", Method::name);
        return Err(Error::Config(format!(
            "--fd-step sets the half step of --method fd, not of {name}"
        )));
    }
    Ok(())
}

/// `method`'s estimator on `problem` with `fd_step`. An invalid scene's
/// error names its file (`path`), if any; a step too large for it gets a
/// hint.
fn estimator_of(
    method: Method,
    problem: impl Problem,
    fd_step: Option<f64>,
    path: Option<&Path>,
) -> Result<Box<dyn Estimator>, Error> {
    let file = path.map_or(String::new(), |p| format!("{}: ", p.display()));
    problem.estimator(method, fd_step).map_err(|e| match e {
        Error::Scene(msg) => Error::Scene(format!("{file}{msg}")),
        Error::FdStep(msg) => Error::FdStep(format!("{file}{msg}; try a smaller --fd-step")),
        other => other,
    })
}

/// The rod's exact solution as a [`RunResult`] (stderr 0, `paths` 0:
/// nothing is sampled; `seconds` is the time of the evaluation).
pub fn exact_result(header: &Header) -> Result<RunResult, Error> {
    let Header::Rod(given) = header else {
        return Err(Error::Config("the exact solution is the rod's only".into()));
    };
    let (rod, probe) = given.build()?;
    let start = crate::runner::Stopwatch::start();
    let values = rod_exact(&rod, &probe);
    let seconds = start.seconds();
    Ok(RunResult {
        method: "exact",
        estimates: rod_quantities()
            .into_iter()
            .zip(values.map(Estimate::exact))
            .collect(),
        paths: 0,
        seconds,
    })
}

/// One rendering: what `geosens render` runs on a camera scene (3D, or
/// flatland's line camera).
#[derive(Debug, Clone, PartialEq)]
pub struct RenderJob {
    /// The scene, whose sensor is a camera.
    pub scene: SceneSource,
    /// The method.
    pub method: Method,
    /// The half step of [`Method::Fd`] (its default if `None`).
    pub fd_step: Option<f64>,
}

impl RenderJob {
    /// Builds the estimator (flatland or 3D by the scene's dimension) and
    /// checks that the sensor is a camera.
    pub fn prepare(&self) -> Result<(Box<dyn Estimator>, Canonical), Error> {
        check_fd_step(Some(self.method), self.fd_step)?;
        let flat = self.scene.dimension()? == Some(2);
        let (est, _, canonical) = self.scene.estimator(flat, self.method, self.fd_step)?;
        if est.image().is_none() {
            return Err(Error::Config(format!(
                "{}: the scene's sensor is not a camera: an image needs `[sensor] kind = \"camera\"` \
                 (`geosens flat` or `geosens mesh` estimate at a probe)",
                self.scene.name()
            )));
        }
        Ok((est, canonical))
    }

    /// Renders every pixel with `spp` paths from `seed` on `threads`
    /// threads (0: all cores); `progress` is called with the pixels done
    /// ([`crate::runner::Progress`]).
    pub fn run(
        &self,
        spp: u64,
        seed: u64,
        threads: usize,
        progress: crate::runner::Progress,
    ) -> Result<ImageReport, Error> {
        let (est, _) = self.prepare()?;
        let result = crate::image::render(est.as_ref(), spp, seed, threads, progress)?;
        Ok(ImageReport {
            result,
            caveats: est.caveats(),
        })
    }
}

/// A rendering's images with the estimator's caveats: what `geosens render`
/// writes and prints.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageReport {
    /// The images.
    pub result: crate::image::ImageResult,
    /// Why a quantity may be far off whatever its error bar.
    pub caveats: Vec<(Quantity, String)>,
}

/// The JSON line of `geosens render`.
#[derive(serde::Serialize)]
struct RenderJsonLine<'a> {
    method: &'a str,
    #[serde(rename = "I")]
    intensity: crate::report::MeanErr,
    sensitivity: serde_json::Map<String, serde_json::Value>,
    width: u32,
    height: u32,
    paths: u64,
    seconds: f64,
}

impl ImageReport {
    /// The warnings `geosens render` prints on stderr: one per caveat, one
    /// per image with a pixel that is not finite, one per image with a
    /// pixel the EXR files' 32-bit floats cannot hold.
    pub fn warnings(&self) -> Vec<String> {
        let mut w: Vec<String> = self
            .caveats
            .iter()
            .map(|(q, why)| format!("warning: {q}: {why}"))
            .collect();
        for (q, img) in &self.result.images {
            if img
                .iter()
                .any(|e| !e.mean.is_finite() || !e.stderr.is_finite())
            {
                w.push(format!(
                    "warning: {q}: some pixels are not finite (overflow, or an error bar lost to \
                     underflow)"
                ));
            }
            // The EXR files hold 32-bit floats (the .npy files doubles).
            let beyond_f32 = |x: f64| {
                x.is_finite()
                    && x != 0.0
                    && !(f64::from(f32::MIN_POSITIVE)..=f64::from(f32::MAX)).contains(&x.abs())
            };
            if img
                .iter()
                .any(|e| beyond_f32(e.mean) || beyond_f32(e.stderr))
            {
                w.push(format!(
                    "warning: {q}: some pixels lie outside the 32-bit range of the EXR files \
                     (below 1.2e-38 they lose digits or read 0, above 3.4e38 they read inf); \
                     the .npy files keep them as doubles"
                ));
            }
        }
        w
    }

    /// The JSON line (without its newline): every image's mean pixel value
    /// with its standard error, the size, the paths and the time.
    pub fn json(&self) -> Result<String, Error> {
        let r = &self.result;
        let mut intensity = None;
        let mut sensitivity = serde_json::Map::new();
        for ((q, _), e) in r.images.iter().zip(&r.means) {
            let m = crate::report::MeanErr::of(e, crate::report::caveat_of(&self.caveats, q));
            match q {
                Quantity::Intensity => intensity = Some(m),
                Quantity::Sensitivity(p) => {
                    sensitivity.insert(
                        p.clone(),
                        serde_json::to_value(m).map_err(|e| Error::Output(e.to_string()))?,
                    );
                }
                Quantity::Gradient(_) => {}
            }
        }
        serde_json::to_string(&RenderJsonLine {
            method: r.method,
            intensity: intensity.ok_or_else(|| Error::Output("no intensity image".into()))?,
            sensitivity,
            width: r.width,
            height: r.height,
            paths: r.paths(),
            seconds: r.seconds,
        })
        .map_err(|e| Error::Output(e.to_string()))
    }
}
