//! Scene files: a flatland [`Scene`] written as TOML or JSON.
//!
//! A file holds the shapes, the parameters (optional) and the sensor, spelt
//! as the serde forms of [`Shape`], [`Parameter`] and [`Sensor`]
//! (points are `[x, y]`). In TOML:
//!
//! ```toml
//! [sensor]
//! kind = "irradiance"
//! point = [0.0, 0.0]
//! normal = [0.0, 1.0]
//!
//! [[shapes]]
//! name = "lamp"
//! vertices = [[-1.0, 2.0], [1.0, 2.0]]
//! surface = { kind = "emitter", radiance = 1.0 }
//!
//! [[shapes]]
//! name = "occluder"
//! vertices = [[-0.6, 1.0], [0.2, 1.0]]
//! surface = { kind = "absorber" }
//!
//! [[parameters]]
//! name = "occluder_tx"
//! shape = "occluder"
//! motion = { kind = "translate_x" }
//! ```
//!
//! Unknown fields are errors, and so is everything [`Scene::new`] rejects.
//! Every error is an [`Error::Scene`] that names the file (for [`load`]), and
//! for a parse error the line, the column and the field at fault.
use super::scene::{Parameter, Scene, Sensor, Shape};
use crate::error::Error;
use crate::scene::file::{json_error, parse_file};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The contents of a scene file: [`Scene::new`]'s arguments.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// The shapes, in order.
    pub shapes: Vec<Shape>,
    /// The parameters whose sensitivities are wanted (none if absent).
    #[serde(default)]
    pub parameters: Vec<Parameter>,
    /// What is measured.
    pub sensor: Sensor,
}

impl SceneFile {
    /// The file form of a scene (pivots resolved, sensor vectors normalised).
    pub fn of(scene: &Scene) -> SceneFile {
        SceneFile {
            shapes: scene.shapes().to_vec(),
            parameters: scene.parameters().to_vec(),
            sensor: scene.sensor(),
        }
    }

    /// Validates the contents into a scene.
    pub fn into_scene(self) -> Result<Scene, Error> {
        Scene::new(self.shapes, self.parameters, self.sensor)
    }
}

/// Reads the scene file at `path`: TOML if it ends in `.toml`, JSON if in
/// `.json` (any case). Errors name the file.
pub fn load(path: &Path) -> Result<Scene, Error> {
    parse_file(path, from_toml, from_json)
}

/// Parses and validates a TOML scene.
pub fn from_toml(text: &str) -> Result<Scene, Error> {
    let file: SceneFile = toml::from_str(text).map_err(|e| {
        // toml's message starts with "TOML parse error at line L, column C"
        // and shows the line with the key or value at fault.
        Error::Scene(e.to_string().trim_end().to_string())
    })?;
    file.into_scene()
}

/// Parses and validates a JSON scene.
pub fn from_json(text: &str) -> Result<Scene, Error> {
    let file: SceneFile = serde_json::from_str(text).map_err(|e| json_error(text, &e))?;
    file.into_scene()
}

/// The TOML text of a scene; [`from_toml`] reads it back to the same shapes,
/// parameters and sensor.
pub fn to_toml(scene: &Scene) -> String {
    toml::to_string(&SceneFile::of(scene))
        .expect("a validated scene has finite numbers and string keys")
}
