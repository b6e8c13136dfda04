//! # geosens: geometric sensitivities in radiative transfer with Monte Carlo
//!
//! geosens estimates the intensity `I` at a point and direction and its
//! derivatives `s = ∂I/∂π` with respect to shape parameters `π`, with the three
//! approaches classified by He et al. (2024), *Three approaches on estimating
//! geometric sensitivities in radiative transfer with Monte Carlo*:
//!
//! 1. **expectation differentiation**: differentiate the path-space expectation
//!    with a domain-deformation velocity; `I` and `s` come from the same paths;
//! 2. **differentiable rendering**: differentiate the Fredholm equation; the
//!    boundary term is joined to the path by double randomization;
//! 3. **sensitivity transport**: `s` obeys the transport equation of `I` with
//!    sources on the moving boundary, coupled to the spatial gradient of `I`.
//!
//! Every estimator implements one interface, [`Estimator`]: one call samples one
//! path (or path pair) and writes its Monte Carlo weights, one per
//! [`Quantity`]. One [`Method`] enum names the methods on every scene kind, a
//! [`Problem`] (a probe on a rod, a flatland scene) builds their estimators,
//! and [`fd`] holds the central differences all of them are checked against. The [`runner`] turns those weights into [`Estimate`]s (mean,
//! standard error, sample count and a tail diagnostic), in parallel and bit for
//! bit reproducible from a seed whatever the thread count.
//!
//! ## Three kinds of scene
//!
//! - **The rod** of the paper's Section 3 ([`rod`]), with its exact
//!   Bellman–Wing solution ([`rod::exact`]).
//! - **Flatland** ([`flat`]): polygon scenes in the plane (emitters,
//!   absorbers, Lambertian reflectors, homogeneous media) whose shapes
//!   translate, rotate and scale, with closed-form and quadrature references
//!   ([`flat::exact`]) and scene files ([`flat::file`]).
//! - **3D** ([`mesh`]): triangle meshes (inline or Wavefront OBJ) with the
//!   same surfaces and media, translating, rotating and scaling, ray cast
//!   through a BVH ([`mesh::bvh`]); Lambert's closed form with an occluder's
//!   shadow and its exact derivatives ([`mesh::exact`]), scene files
//!   ([`mesh::file`]).
//!
//! Flatland and 3D run on one path tracer ([`path`]), generic over the
//! geometry; the scene layer they share ([`scene`]) reads files and checks
//! limits. [`job::Target::exact`] gives a rod probe's or a scene's closed
//! form where it has one.
//!
//! ## Runs, images, shards, optimisation
//!
//! - [`job`]: one estimation as data (a target, a method), what the command
//!   line and the Python package run; [`report`] prints it as a table or a
//!   JSON line.
//! - **Rendering** ([`image`]): a camera sensor makes every pixel a probe;
//!   [`image::render`] estimates `I` and every `∂I/∂π` per pixel, and
//!   [`image_io`] writes the images (EXR, `.npy`, PNG).
//! - **Shards** ([`shard`]): a run split over processes or cluster nodes
//!   (`--shard I/N` on the command line, Slurm job arrays, Dask); each shard
//!   writes its exact moments to a state file, and [`shard::merge`] gives the
//!   single run's result bit for bit.
//! - **Optimisation** ([`optimize`]): inverse problems and design by
//!   stochastic gradient descent on a scene's parameters.
//!
//! ## Command line, Python, book
//!
//! The `geosens` binary (`src/bin/geosens`) runs all of it: `rod`, `flat`,
//! `mesh`, `render`, `merge`, `optimize`, `compare`. The Python package
//! `geosens` (`python/`, PyO3; `pip install .` from the repository) calls the
//! same [`job`]s from notebooks and clusters, returns results as dicts and
//! images as numpy arrays, and gives the closed forms too. The book
//! (`book/`) derives every estimator, and its chapter "From Python" documents
//! the package.
//!
//! The figures (`plot`, `rod::figures`, `flat::figures`, `mesh::figures`)
//! are behind the default cargo feature `figures`, which brings in plotters
//! and its system font libraries; `default-features = false` leaves them
//! out.
//!
//! ## Examples
//!
//! The rod, built in code, against its exact solution:
//!
//! ```
//! use geosens::rod::{Direction, Probe, Rod, Method};
//! use geosens::{run, Quantity, RunConfig};
//!
//! let rod = Rod::new(2.1, 3.0, 2.0)?; // κs, κe, length
//! let probe = Probe::new(&rod, 1.0, Direction::Left)?;
//! let estimator = Method::Expectation.estimator((rod, probe))?;
//! let result = run(estimator.as_ref(), &RunConfig::new(10_000, 7)?)?;
//! let s = result.get(&Quantity::sensitivity("length")).unwrap();
//! let exact = geosens::rod::exact::solve(&rod, probe.x, probe.omega);
//! assert!((s.mean - exact.sensitivity).abs() < 5.0 * s.stderr);
//! # Ok::<(), geosens::Error>(())
//! ```
//!
//! A shipped scene file (the flatland occluder), every parameter's
//! sensitivity by the transport model, against the scene's closed form:
//!
//! ```
//! use geosens::job::{Job, SceneSource, Target};
//! use geosens::{Method, Quantity, RunConfig};
//!
//! let file = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/occluder.toml");
//! let job = Job {
//!     target: Target::Flat(SceneSource::File(file.into())),
//!     method: Some(Method::Transport),
//!     fd_step: None,
//! };
//! let report = job.run(&RunConfig::new(20_000, 3)?, &geosens::runner::quiet)?;
//! let exact = job.target.exact()?;
//! for (name, value) in &exact.sensitivity {
//!     let s = report.result.get(&Quantity::sensitivity(name)).unwrap();
//!     assert!((s.mean - value).abs() < 5.0 * s.stderr, "∂I/∂{name}");
//! }
//! println!("{}", report.json()?); // the line of `geosens flat --json`
//! # Ok::<(), geosens::Error>(())
//! ```
//!
//! A 3D scene loads the same way, through [`job::Target::Mesh`] or
//! [`mesh::file::load`].
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod bvh_frame;
pub mod error;
pub mod estimator;
pub mod fd;
#[cfg(feature = "figures")]
mod figures_common;
pub mod file_set;
pub mod flat;
pub mod image;
pub mod image_io;
pub mod job;
pub mod mesh;
pub mod method;
pub mod optimize;
pub mod path;
#[cfg(feature = "figures")]
pub mod plot;
pub mod report;
pub mod rng;
pub mod rod;
mod rows;
pub mod runner;
pub mod scene;
pub mod shard;
pub mod stats;

pub use error::Error;
pub use estimator::{Estimator, Quantity};
pub use method::{Method, Problem};
pub use runner::{RunConfig, RunResult, run};
pub use stats::Estimate;
