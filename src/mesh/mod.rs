//! Three dimensions: triangle-mesh scenes whose meshes translate, rotate
//! and scale, on the path core that flatland uses ([`crate::path`]). The
//! book's 3D chapter derives what differs from flatland: silhouette edges
//! instead of corners.
pub mod exact;
pub mod scene;

pub use scene::{Medium, Motion, Parameter, Scene, Sensor, Shape, Surface};
pub mod boundaries;
pub mod lobe;
pub mod methods;
pub mod space;
mod tris;
pub mod warp;

pub use space::Space;
