//! Scene files' lists of fixed-length rows (`vertices = [[x, y, z], …]`,
//! `triangles = [[i, j, k], …]`), read strictly: serde reads a `[T; N]` or
//! a glam vector from a longer list by taking its first `N` entries, and
//! the TOML reader then drops the rest without a word (a quad given as
//! `[0, 1, 2, 3]` became one triangle: half the occluder, a wrong answer).
//! Each row must hold exactly `N` entries; the error names the row.
use glam::{DVec2, DVec3};
use serde::de::{Deserialize, Deserializer, Error};

/// Rows of exactly `N` entries; `what` names a row and an entry in the
/// error (`("vertex", "coordinates")`).
fn rows<'de, D, T, const N: usize>(d: D, what: (&str, &str)) -> Result<Vec<[T; N]>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    let rows: Vec<Vec<T>> = Vec::deserialize(d)?;
    rows.into_iter()
        .enumerate()
        .map(|(i, row)| {
            <[T; N]>::try_from(row).map_err(|row| {
                let hint = if what.0 == "triangle" && row.len() > 3 {
                    " (split a polygon into triangles, or give it in an OBJ file)"
                } else {
                    ""
                };
                D::Error::custom(format!(
                    "{} {i} has {} {}, expected {N}{hint}",
                    what.0,
                    row.len(),
                    what.1
                ))
            })
        })
        .collect()
}

/// Flatland vertices: rows of two coordinates.
pub(crate) fn points2<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<DVec2>, D::Error> {
    Ok(rows::<D, f64, 2>(d, ("vertex", "coordinates"))?
        .into_iter()
        .map(DVec2::from)
        .collect())
}

/// 3D vertices, when given: rows of three coordinates.
pub(crate) fn points3<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Vec<DVec3>>, D::Error> {
    Ok(Some(
        rows::<D, f64, 3>(d, ("vertex", "coordinates"))?
            .into_iter()
            .map(DVec3::from)
            .collect(),
    ))
}

/// Triangles, when given: rows of three vertex indices.
pub(crate) fn triangles<'de, D: Deserializer<'de>>(
    d: D,
) -> Result<Option<Vec<[u32; 3]>>, D::Error> {
    rows::<D, u32, 3>(d, ("triangle", "indices")).map(Some)
}

#[cfg(test)]
mod tests {
    use serde::Deserialize;

    #[derive(Deserialize, Debug)]
    struct Mesh {
        #[serde(default, deserialize_with = "super::points3")]
        vertices: Option<Vec<glam::DVec3>>,
        #[serde(default, deserialize_with = "super::triangles")]
        triangles: Option<Vec<[u32; 3]>>,
    }

    #[test]
    fn a_row_of_the_wrong_length_is_refused_by_number() {
        let ok: Mesh = toml::from_str("vertices = [[0, 0, 1.5]]\ntriangles = [[0, 1, 2]]").unwrap();
        assert_eq!(ok.vertices.unwrap()[0].z, 1.5);
        assert_eq!(ok.triangles.unwrap(), vec![[0, 1, 2]]);
        let none: Mesh = toml::from_str("").unwrap();
        assert!(none.vertices.is_none() && none.triangles.is_none());
        for (text, needle) in [
            (
                "triangles = [[0, 1, 2], [0, 1, 2, 3]]",
                "triangle 1 has 4 indices, expected 3",
            ),
            (
                "triangles = [[0, 1]]",
                "triangle 0 has 2 indices, expected 3",
            ),
            (
                "vertices = [[0, 0, 1, 7]]",
                "vertex 0 has 4 coordinates, expected 3",
            ),
        ] {
            let err = toml::from_str::<Mesh>(text).unwrap_err().to_string();
            assert!(err.contains(needle), "{text}: {err}");
            let json = format!("{{{}}}", text.replace(" = ", "\": ").replacen("", "\"", 1));
            let err = serde_json::from_str::<Mesh>(&json).unwrap_err().to_string();
            assert!(err.contains(needle), "{json}: {err}");
        }
    }
}
