//! The scene layer that flatland and 3D share: what a scene is made of and
//! held to whatever its dimension. Reading a scene file ([`file`](mod@file)), the
//! limits and the parameters' checks ([`limits`]), surfaces, media and
//! phase functions ([`material`]), the cameras' bounds ([`camera`]), what
//! an optimisation asks of a scene ([`objective`], [`pose`]) and the
//! file forms' shared pieces (`repr`). `crate::flat` and `crate::mesh` build
//! their scenes on it and keep only what is theirs (polygons, meshes, OBJ
//! files); neither imports the other. Book: chapter "Where the code lives".
use crate::error::Error;

pub mod camera;
pub mod file;
pub mod limits;
pub mod material;
pub mod objective;
pub mod parameter;
pub mod pose;
pub(crate) mod repr;

/// A scene error with message `msg`.
pub(crate) fn config<T>(msg: String) -> Result<T, Error> {
    Err(Error::Scene(msg))
}
