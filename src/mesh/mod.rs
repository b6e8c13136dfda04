//! Three dimensions: triangle-mesh scenes whose meshes translate, rotate
//! and scale, on the path core that flatland uses ([`crate::path`]). The
//! book's 3D chapter derives what differs from flatland: silhouette edges
//! instead of corners.
pub mod bvh;
pub mod scene;

pub use scene::{Medium, Motion, Parameter, Scene, Sensor, Shape, Surface};
