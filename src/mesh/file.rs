//! Scene files: a 3D [`Scene`] written as TOML or JSON, its meshes inline or
//! in Wavefront OBJ files beside it.
//!
//! A file holds the shapes, the parameters (optional) and the sensor. A
//! shape gives its mesh either inline (`vertices = [[x, y, z], …]` and
//! `triangles = [[i, j, k], …]`, indices from 0) or as `mesh = "file.obj"`,
//! relative to the scene file; never both. In TOML:
//!
//! ```toml
//! [sensor]
//! kind = "irradiance"            # or "radiance" with `direction`
//! point = [0.0, 0.0, 0.0]
//! normal = [0.0, 0.0, 1.0]
//!
//! [[shapes]]
//! name = "lamp"
//! vertices = [[-0.5, -0.5, 2.0], [0.5, -0.5, 2.0], [0.5, 0.5, 2.0], [-0.5, 0.5, 2.0]]
//! triangles = [[0, 1, 2], [0, 2, 3]]
//! surface = { kind = "emitter", radiance = 1.0 }  # two-sided
//!
//! [[shapes]]
//! name = "occ"
//! mesh = "occluder.obj"
//! surface = { kind = "absorber" }
//! # medium = { ks = 1.0, ke = 1.5, g = 0.3 } on a closed, transparent mesh
//!
//! [[parameters]]
//! name = "occ_rot"
//! shape = "occ"
//! motion = { kind = "rotate", axis = [0.0, 0.0, 1.0], pivot = [0.0, 0.0, 1.0] }
//! ```
//!
//! Surfaces are flatland's (`emitter`, `absorber`, `reflector`,
//! `transparent`); motions are `translate_x`, `translate_y`, `translate_z`,
//! `rotate { axis, pivot? }` and `scale { pivot? }` (value = factor − 1),
//! pivots defaulting to the mesh's vertex centroid.
//!
//! An OBJ file contributes the positions and faces of all its objects and
//! groups, merged into one mesh, polygons triangulated (fan); normals,
//! texture coordinates, materials, points and lines are ignored.
//!
//! Unknown fields are errors, and so is everything [`Scene::new`] rejects.
//! Every error is an [`Error::Scene`] that names the file (for [`load`]),
//! for a parse error the line and the field at fault, for an OBJ the shape
//! and the OBJ's path. [`from_toml`] and [`from_json`] read `mesh` paths
//! relative to the current directory.
use super::scene::{Medium, Scene, Sensor, Shape, Surface};
use crate::error::Error;
use crate::optimize::Study;
use crate::scene::file::{
    Contents, MAX_SCENE_BYTES, in_file, json_error, parse_file, read_bytes_capped,
};
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A shape as a file gives it: its mesh inline or by OBJ file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShapeFile {
    /// Unique name, used by parameters.
    pub name: String,
    /// Inline vertex positions (with `triangles`; not with `mesh`).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "crate::rows::points3"
    )]
    pub vertices: Option<Vec<DVec3>>,
    /// Inline triangles, indices into `vertices` from 0.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "crate::rows::triangles"
    )]
    pub triangles: Option<Vec<[u32; 3]>>,
    /// An OBJ file holding the mesh, relative to the scene file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<PathBuf>,
    /// The surface's behaviour (two-sided).
    pub surface: Surface,
    /// The medium inside (closed, transparent meshes only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub medium: Option<Medium>,
}

impl ShapeFile {
    /// The shape, its OBJ (if any) read relative to the directory `base`.
    pub fn into_shape(self, base: &Path) -> Result<Shape, Error> {
        let name = self.name;
        let (vertices, triangles) = match (self.vertices, self.triangles, self.mesh) {
            (Some(v), Some(t), None) => (v, t),
            (None, None, Some(mesh)) => read_obj(&base.join(mesh), &name)?,
            (_, _, Some(_)) => {
                return Err(Error::Scene(format!(
                    "shape {name:?} gives both `mesh` and inline `vertices`/`triangles`: \
                     give one"
                )));
            }
            (Some(_), None, None) | (None, Some(_), None) => {
                return Err(Error::Scene(format!(
                    "shape {name:?}: inline meshes need both `vertices` and `triangles`"
                )));
            }
            (None, None, None) => {
                return Err(Error::Scene(format!(
                    "shape {name:?} has no mesh: give `mesh = \"file.obj\"` or inline \
                     `vertices` and `triangles`"
                )));
            }
        };
        Ok(Shape {
            name,
            vertices,
            triangles,
            surface: self.surface,
            medium: self.medium,
        })
    }
}

/// The contents of a 3D scene file: [`Scene::new`]'s arguments, meshes
/// inline or by OBJ, and an optimisation's measurements and objective.
pub type MeshFile = Contents<ShapeFile, super::scene::Motion, Sensor>;

impl MeshFile {
    /// The file form of a scene, meshes inline (welded and oriented, pivots
    /// resolved, sensor vectors normalised): [`MeshFile::into_scene`] gives
    /// back the same scene.
    pub fn of(scene: &Scene) -> MeshFile {
        Contents::of_parts(
            scene
                .shapes()
                .iter()
                .map(|s| ShapeFile {
                    name: s.name.clone(),
                    vertices: Some(s.vertices.clone()),
                    triangles: Some(s.triangles.clone()),
                    mesh: None,
                    surface: s.surface,
                    medium: s.medium,
                })
                .collect(),
            scene.parameters().to_vec(),
            scene.sensor(),
        )
    }

    /// Reads the OBJ files (relative to the directory `base`) and validates
    /// the contents into a scene.
    pub fn into_scene(self, base: &Path) -> Result<Scene, Error> {
        let sensor = self.scene_sensor()?;
        let shapes = self
            .shapes
            .into_iter()
            .map(|s| s.into_shape(base))
            .collect::<Result<Vec<_>, _>>()?;
        Scene::new(shapes, self.parameters, sensor)
    }

    /// Reads the OBJ files (relative to `base`) and validates the contents
    /// into an optimisation problem.
    pub fn into_study(self, base: &Path) -> Result<Study<Scene>, Error> {
        let (measurements, kind) = self.optimisation()?;
        Study::new(self.into_scene(base)?, measurements, kind)
    }
}

/// Reads the optimisation problem in the scene file at `path` (its
/// `[objective]` and `[[measurements]]`); OBJ paths are relative to its
/// directory. Errors name the file.
pub fn load_study(path: &Path) -> Result<Study<Scene>, Error> {
    let base = path.parent().unwrap_or(Path::new(""));
    parse_file(path, parse_toml, parse_json)?
        .into_study(base)
        .map_err(|e| in_file(path, e))
}

/// Reads the scene file at `path`: TOML if it ends in `.toml`, JSON if in
/// `.json` (any case); OBJ paths are relative to its directory. Errors name
/// the file.
pub fn load(path: &Path) -> Result<Scene, Error> {
    let base = path.parent().unwrap_or(Path::new(""));
    parse_file(path, parse_toml, parse_json)?
        .into_scene(base)
        .map_err(|e| in_file(path, e))
}

fn parse_toml(text: &str) -> Result<MeshFile, Error> {
    // toml's message starts with "TOML parse error at line L, column C" and
    // shows the line with the key or value at fault.
    toml::from_str(text).map_err(|e| Error::Scene(e.to_string().trim_end().to_string()))
}

fn parse_json(text: &str) -> Result<MeshFile, Error> {
    serde_json::from_str(text).map_err(|e| json_error(text, &e))
}

/// Parses and validates a TOML scene; `mesh` paths are relative to the
/// current directory.
pub fn from_toml(text: &str) -> Result<Scene, Error> {
    parse_toml(text)?.into_scene(Path::new(""))
}

/// Parses and validates a JSON scene; `mesh` paths are relative to the
/// current directory.
pub fn from_json(text: &str) -> Result<Scene, Error> {
    parse_json(text)?.into_scene(Path::new(""))
}

/// Parses and validates the optimisation problem in a JSON scene (what a
/// Python dict becomes), as [`load_study`] a file's; `mesh` paths are
/// relative to the current directory.
pub fn study_from_json(text: &str) -> Result<Study<Scene>, Error> {
    parse_json(text)?.into_study(Path::new(""))
}

/// The TOML text of a scene, meshes inline; [`from_toml`] reads it back to
/// the same scene.
pub fn to_toml(scene: &Scene) -> Result<String, Error> {
    toml::to_string(&MeshFile::of(scene))
        .map_err(|e| Error::Output(format!("cannot write the scene as TOML: {e}")))
}

/// The JSON text of a scene, meshes inline; [`from_json`] reads it back to
/// the same scene.
pub fn to_json(scene: &Scene) -> Result<String, Error> {
    serde_json::to_string_pretty(&MeshFile::of(scene))
        .map_err(|e| Error::Output(format!("cannot write the scene as JSON: {e}")))
}

/// The vertices and triangles of the OBJ file at `path` for shape `name`:
/// all its objects merged, polygons triangulated.
fn read_obj(path: &Path, name: &str) -> Result<(Vec<DVec3>, Vec<[u32; 3]>), Error> {
    let fail = |why: String| {
        Error::Scene(format!(
            "shape {name:?}: cannot read mesh file {}: {why}",
            path.display()
        ))
    };
    let mut bytes =
        read_bytes_capped(path, MAX_SCENE_BYTES, None).map_err(|why| fail(why.to_string()))?;
    // A UTF-8 byte-order mark, as some editors write: tobj would read it as
    // part of the first line's keyword and drop that line (a first vertex
    // lost shifts every face index by one).
    if bytes.starts_with(b"\xef\xbb\xbf") {
        bytes.drain(..3);
    }
    let options = tobj::LoadOptions {
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let text = String::from_utf8_lossy(&bytes);
    let at_line = |(line, why): (usize, String)| fail(format!("malformed OBJ, line {line}: {why}"));
    if let Some(short) = super::obj_lines::short_face(&text) {
        return Err(at_line(short));
    }
    // Materials are not read: a `mtllib` line loads nothing.
    let (models, _) = tobj::load_obj_buf(&mut bytes.as_slice(), &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| match super::obj_lines::locate(&text) {
        Some(found) => at_line(found),
        None => fail(format!("malformed OBJ ({e})")),
    })?;
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for m in &models {
        let offset = vertices.len();
        let (p, ix) = (&m.mesh.positions, &m.mesh.indices);
        if p.len() % 3 != 0 || ix.len() % 3 != 0 {
            return Err(fail(format!("malformed OBJ (object {:?})", m.name)));
        }
        vertices.extend(p.chunks_exact(3).map(|c| DVec3::new(c[0], c[1], c[2])));
        for t in ix.chunks_exact(3) {
            let mut tri = [0u32; 3];
            for (out, &i) in tri.iter_mut().zip(t) {
                *out = u32::try_from(i as usize + offset)
                    .map_err(|_| fail("more than 2³² vertices".into()))?;
            }
            triangles.push(tri);
        }
    }
    Ok((vertices, triangles))
}
