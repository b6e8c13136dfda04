//! 3D's caveat detectors, beside the meshes they inspect: where `I` (or
//! the sensor's gradient) may have a kink at the nominal parameter, a face
//! seen edge-on ([`kinks`]) or two edges tied on one plane through the
//! sensor ([`edge_ties`]), and where a central difference may straddle a
//! change of visibility (`fd`, `fd_view`). The estimators attach their
//! messages to the quantities concerned (`Estimator::caveats`). Book:
//! chapter "Choosing a method" (row 4) and chapter "When not to trust a
//! number", section "Finite differences across a
//! change of visibility".
pub(crate) mod fd;
pub(crate) mod fd_view;
mod kinks;
mod ties;

pub use kinks::{EDGE_ON_ULPS, kinks, plane_kinks_of_the_gradient};
pub use ties::{TIE, edge_ties};
