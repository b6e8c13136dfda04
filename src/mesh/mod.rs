//! Three dimensions: triangle-mesh scenes whose meshes translate, rotate
//! and scale, on the path core that flatland uses ([`crate::path`]). The
//! book's 3D chapter derives what differs from flatland: silhouette edges
//! instead of corners, and a warp on the sphere.
//!
//! - [`scene`]: the validated scene; [`file`](mod@file): its TOML/JSON file form
//!   (meshes inline or in OBJ files);
//! - [`bvh`]: ray casting through obvhs, every hit re-tested in f64;
//! - [`space`]: the scene behind the path core's `Geometry`; [`lobe`]: the
//!   3D lobes; [`boundaries`]: the edges behind `Boundaries`; [`warp`]: the
//!   expectation method's fibre warp, [`knots`] its knot search; [`sensor_view`]: what the sensor's
//!   point sees of every edge (the warp's knots there without shadow rays);
//! - [`camera`]: the pinhole camera (pixels as lobes, the edges each
//!   pixel sees);
//! - [`methods`]: the estimators; [`exact`]: closed-form references;
//!   [`cases`]: scenes built in code for the figures and `geosens compare`
//!   (the figures themselves: `figures`, with the `figures` feature).
pub mod boundaries;
pub mod bvh;
pub mod camera;
pub mod cases;
pub mod caveats;
pub mod edge_sampler;
pub mod edges;
pub mod exact;
#[cfg(feature = "figures")]
pub mod figures;
pub mod file;
pub mod inverse;
pub mod knots;
pub mod lobe;
pub mod methods;
mod obj_lines;
mod part;
pub mod poles;
pub mod scene;
pub mod sensor_view;
pub mod space;
mod touch;
pub mod warp;

pub use scene::{Medium, Motion, Parameter, Scene, Sensor, Shape, Surface};
pub use space::Space;
