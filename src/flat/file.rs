//! Scene files: a flatland [`Scene`] written as TOML or JSON.
//!
//! A file holds the shapes, the parameters (optional) and the sensor, spelt
//! as the serde forms of [`Shape`], [`Parameter`](super::scene::Parameter) and [`Sensor`]
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
use super::scene::{Scene, Sensor, Shape};
use crate::error::Error;
use crate::optimize::Study;
use crate::scene::file::{Contents, in_file, json_error, parse_file};
use std::path::Path;

/// The contents of a flatland scene file: [`Scene::new`]'s arguments, and
/// an optimisation's measurements and objective.
pub type SceneFile = Contents<Shape, super::scene::Motion, Sensor>;

impl SceneFile {
    /// The file form of a scene (pivots resolved, sensor vectors normalised).
    pub fn of(scene: &Scene) -> SceneFile {
        Contents::of_parts(
            scene.shapes().to_vec(),
            scene.parameters().to_vec(),
            scene.sensor(),
        )
    }

    /// Validates the contents into a scene.
    pub fn into_scene(self) -> Result<Scene, Error> {
        let sensor = self.scene_sensor()?;
        Scene::new(self.shapes, self.parameters, sensor)
    }

    /// Validates the contents into an optimisation problem.
    pub fn into_study(self) -> Result<Study<Scene>, Error> {
        let (measurements, kind) = self.optimisation()?;
        Study::new(self.into_scene()?, measurements, kind)
    }
}

/// Reads the scene file at `path`: TOML if it ends in `.toml`, JSON if in
/// `.json` (any case). Errors name the file.
pub fn load(path: &Path) -> Result<Scene, Error> {
    parse_file(path, from_toml, from_json)
}

/// Reads the optimisation problem in the scene file at `path` (its
/// `[objective]` and `[[measurements]]`). Errors name the file.
pub fn load_study(path: &Path) -> Result<Study<Scene>, Error> {
    parse_file(path, parse_toml, parse_json)?
        .into_study()
        .map_err(|e| in_file(path, e))
}

fn parse_toml(text: &str) -> Result<SceneFile, Error> {
    toml::from_str(text).map_err(|e| Error::Scene(e.to_string().trim_end().to_string()))
}

fn parse_json(text: &str) -> Result<SceneFile, Error> {
    serde_json::from_str(text).map_err(|e| json_error(text, &e))
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

/// Parses and validates the optimisation problem in a JSON scene (what a
/// Python dict becomes), as [`load_study`] a file's.
pub fn study_from_json(text: &str) -> Result<Study<Scene>, Error> {
    parse_json(text)?.into_study()
}

/// The TOML text of a scene; [`from_toml`] reads it back to the same shapes,
/// parameters and sensor.
pub fn to_toml(scene: &Scene) -> String {
    toml::to_string(&SceneFile::of(scene))
        .expect("a validated scene has finite numbers and string keys")
}
