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
//! The first scene is the rod of the paper's Section 3 ([`rod`]), with its
//! exact Bellman–Wing solution ([`rod::exact`]). The second is flatland
//! ([`flat`]): polygon scenes in the plane (emitters, absorbers, Lambertian
//! reflectors, homogeneous media) whose shapes translate, rotate and scale,
//! with closed-form and quadrature references ([`flat::exact`]) and scene
//! files ([`flat::file`]). The book (`book/`) derives every estimator.
//!
//! The figures (`plot`, `rod::figures`, `flat::figures`) are behind the
//! default cargo feature `figures`, which brings in plotters and its system
//! font libraries; `default-features = false` leaves them out.
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
