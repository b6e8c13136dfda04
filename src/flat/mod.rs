//! Flatland: polygon scenes in the plane whose shapes translate, rotate and
//! scale, with the rod's estimator interface. The book's chapter "Flatland"
//! derives every estimator.
pub mod boundaries;
pub mod bvh;
pub mod cases;
pub mod caveats;
pub mod corners;
pub mod exact;
#[cfg(feature = "figures")]
pub mod figures;
pub mod file;
pub mod geometry;
pub mod lobe;
pub mod methods;
pub mod scene;
pub mod sensor_gaps;
pub mod space;

pub use methods::Method;
pub use scene::{Medium, Motion, Parameter, Phase, Scene, Sensor, Shape, Surface};
