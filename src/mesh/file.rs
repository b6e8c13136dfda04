//! Placeholder (replaced by the scene-file module).
use super::scene::Scene;
use crate::error::Error;
use std::path::Path;

/// Not yet.
pub fn load(path: &Path) -> Result<Scene, Error> {
    Err(Error::Scene(format!("{}: not yet", path.display())))
}
