//! Reading a scene file, whatever its dimension: the extension chooses
//! TOML or JSON, the size is capped, a byte-order mark is dropped, pipes are
//! refused, and every error names the file and (for a parse error) the
//! line, the column and the field at fault. The flatland loader
//! (`crate::flat::file`) and the 3D loader (`crate::mesh::file`, which also
//! reads OBJ meshes through `read_bytes_capped`) build their scenes from
//! what it parses; [`dimension`] tells them apart. Book: chapter "Scene
//! files: a reference".
use crate::error::Error;
use std::path::Path;

/// The dimension of the scene file at `path` ([`dimension_of`]: `None`
/// when the file does not say, and the loader must tell what is wrong).
/// Errors only if the file cannot be read or parsed at all, with the
/// parser's line and column.
pub fn dimension(path: &Path) -> Result<Option<usize>, Error> {
    fn as_json(text: &str) -> Result<serde_json::Value, Error> {
        let value: toml::Value =
            toml::from_str(text).map_err(|e| Error::Scene(e.to_string().trim_end().to_string()))?;
        serde_json::to_value(value).map_err(|e| Error::Scene(e.to_string()))
    }
    fn from_json_text(text: &str) -> Result<serde_json::Value, Error> {
        serde_json::from_str(text).map_err(|e| json_error(text, &e))
    }
    Ok(dimension_of(&parse_file(path, as_json, from_json_text)?))
}

/// The dimension of a scene given as the file's schema in JSON (a parsed
/// file, or a Python dict): the number of coordinates of its sensor's
/// point (`point`, or a camera's `position`), or failing that of the first
/// shape's first vertex, if 2 or 3; `None` if neither says (no sensor, a
/// misspelt key, a point of one coordinate: the loader of either dimension
/// names the fault).
pub fn dimension_of(value: &serde_json::Value) -> Option<usize> {
    let sensor = &value["sensor"];
    let point = if sensor["point"].is_array() {
        &sensor["point"]
    } else {
        &sensor["position"]
    };
    let vertex = &value["shapes"][0]["vertices"][0];
    [point, vertex]
        .iter()
        .filter_map(|p| p.as_array().map(Vec::len))
        .find(|n| (2..=3).contains(n))
}

/// `e` with the file `path` named in its message (scene errors only).
pub(crate) fn in_file(path: &Path, e: Error) -> Error {
    match e {
        Error::Scene(msg) => Error::Scene(format!("{}: {msg}", path.display())),
        other => other,
    }
}

/// The scene file at `path` parsed by `toml` or `json` after its extension
/// (any case), at most [`MAX_SCENE_BYTES`] read; errors name the file. The
/// flatland and the 3D loaders share it.
pub(crate) fn parse_file<T>(
    path: &Path,
    toml: fn(&str) -> Result<T, Error>,
    json: fn(&str) -> Result<T, Error>,
) -> Result<T, Error> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let parse = match ext.as_deref() {
        Some("toml") => toml,
        Some("json") => json,
        _ => {
            return Err(Error::Scene(format!(
                "{}: unknown scene file extension {:?}: expected .toml or .json",
                path.display(),
                path.extension().unwrap_or_default()
            )));
        }
    };
    let text = read_capped(path)?;
    // A byte-order mark, as some editors write: TOML allows it, JSON not.
    parse(text.trim_start_matches('\u{feff}')).map_err(|e| in_file(path, e))
}

/// Largest scene file read (bytes): a path that names an endless stream
/// (a link to `/dev/zero`, a pipe) stops there instead of filling memory.
pub const MAX_SCENE_BYTES: u64 = 256 << 20;

/// The text of the file at `path`, at most [`MAX_SCENE_BYTES`] long.
pub(crate) fn read_capped(path: &Path) -> Result<String, Error> {
    let bytes = read_bytes_capped(path, MAX_SCENE_BYTES, None)
        .map_err(|why| Error::Scene(format!("cannot read scene file {}: {why}", path.display())))?;
    String::from_utf8(bytes).map_err(|e| {
        Error::Scene(format!(
            "cannot read scene file {}: not UTF-8 text ({e})",
            path.display()
        ))
    })
}

/// Why [`read_bytes_capped`] read nothing; `Display` says it in words for
/// the caller's "cannot read FILE: …".
#[derive(Debug)]
pub(crate) enum Unread {
    /// The file could not be opened or read.
    Io(std::io::Error),
    /// It holds more than the cap, in bytes.
    TooLarge(u64),
    /// It is a named pipe or a socket: opening or reading it waits for a
    /// writer that may never come or never close it, silently. (Unix
    /// only: elsewhere, wasm32 say, no file is one.)
    #[cfg_attr(not(unix), allow(dead_code))]
    Pipe,
    /// Its first byte past white space is not the one its format starts
    /// with (a stream of zeros, say: refused before the cap is read).
    Lead(u8),
}

impl std::fmt::Display for Unread {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Unread::Io(e) => write!(f, "{e}"),
            Unread::TooLarge(cap) => write!(
                f,
                "larger than {} MiB (or an endless stream): not read",
                cap >> 20
            ),
            Unread::Pipe => write!(
                f,
                "a named pipe, not a file: not read (its writer may never open or close it; \
                 save what it carries to a file)"
            ),
            Unread::Lead(b) => write!(
                f,
                "not in the expected format (its text does not start with `{}`)",
                char::from(*b)
            ),
        }
    }
}

/// The bytes of the file at `path`, at most `cap` (scene files here, OBJ
/// meshes in `mesh::file`, shard states in `shard`), whose first byte
/// past white space is `lead` if given. A pipe is refused before it is
/// opened: `open` itself blocks until a writer comes.
pub(crate) fn read_bytes_capped(
    path: &Path,
    cap: u64,
    lead: Option<u8>,
) -> Result<Vec<u8>, Unread> {
    use std::io::Read;
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let kind = std::fs::metadata(path).map_err(Unread::Io)?.file_type();
        if kind.is_fifo() || kind.is_socket() {
            return Err(Unread::Pipe);
        }
    }
    let mut file = std::fs::File::open(path).map_err(Unread::Io)?.take(cap + 1);
    let mut bytes = Vec::new();
    if let Some(want) = lead {
        let mut byte = [0u8];
        loop {
            match file.read(&mut byte) {
                Ok(0) => break,
                Ok(_) => {
                    bytes.push(byte[0]);
                    if !byte[0].is_ascii_whitespace() {
                        if byte[0] != want {
                            return Err(Unread::Lead(want));
                        }
                        break;
                    }
                }
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(Unread::Io(e)),
            }
        }
    }
    file.read_to_end(&mut bytes).map_err(Unread::Io)?;
    if bytes.len() as u64 > cap {
        return Err(Unread::TooLarge(cap));
    }
    Ok(bytes)
}

/// serde_json's message (which ends "at line L column C"), preceded by the
/// key being read there when the message names no field (a wrong type, an
/// unknown variant).
pub(crate) fn json_error(text: &str, e: &serde_json::Error) -> Error {
    let msg = e.to_string();
    let names_field = msg.contains("field `");
    let key = (e.classify() == serde_json::error::Category::Data && !names_field && e.line() > 0)
        .then(|| key_before(text, e.line(), e.column()))
        .flatten();
    match key {
        Some(key) => Error::Scene(format!("JSON: field `{key}`: {msg}")),
        None => Error::Scene(format!("JSON: {msg}")),
    }
}

/// The last object key (`"name":`) written before line `line`, column
/// `column` (both from 1), if any. None at the end of an object: serde_json
/// reports there the errors of a buffered (internally tagged) object, whose
/// last key need not be the one at fault.
fn key_before(text: &str, line: usize, column: usize) -> Option<String> {
    let start: usize = text
        .split_inclusive('\n')
        .take(line - 1)
        .map(str::len)
        .sum();
    let rest = &text[start..];
    let upto = rest
        .char_indices()
        .nth(column)
        .map_or(rest.len(), |(i, _)| i);
    let prefix = &text[..start + upto];
    if prefix.trim_end().ends_with('}') {
        return None;
    }
    // Scan strings left to right; remember each string followed by ':'.
    let bytes = prefix.as_bytes();
    let mut key = None;
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'"' {
            let open = i + 1;
            i += 1;
            while i < bytes.len() && bytes[i] != b'"' {
                i += if bytes[i] == b'\\' { 2 } else { 1 };
            }
            let close = i.min(bytes.len());
            let mut j = i + 1;
            while j < bytes.len() && bytes[j].is_ascii_whitespace() {
                j += 1;
            }
            if j < bytes.len() && bytes[j] == b':' {
                key = Some(prefix[open..close].to_string());
            }
        }
        i += 1;
    }
    key
}

/// The scene's sensor: the file's `[sensor]`, else its first measurement's.
fn first_sensor<S: Copy>(
    sensor: Option<S>,
    measurements: &[crate::scene::objective::Measurement<S>],
) -> Result<S, Error> {
    sensor
        .or_else(|| measurements.first().map(|m| m.sensor))
        .ok_or_else(|| {
            Error::Scene(
                "missing field `sensor`: a scene needs a [sensor] or [[measurements]]".into(),
            )
        })
}

/// The file's objective: refused when absent (the caller asked for an
/// optimisation).
fn objective_of(
    objective: &Option<crate::scene::objective::Objective>,
) -> Result<crate::scene::objective::ObjectiveKind, Error> {
    objective.map(|o| o.kind).ok_or_else(|| {
        Error::Scene(
            "missing table [objective]: an optimisation needs `kind = \"least_squares\"`, \
             \"maximize\" or \"minimize\""
                .into(),
        )
    })
}

/// The contents of a scene file, whatever its dimension (`Sh` its shapes'
/// file form, `M` its motions, `Se` its sensors): flatland's
/// [`SceneFile`](crate::flat::file::SceneFile) and 3D's
/// [`MeshFile`](crate::mesh::file::MeshFile).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(
    deny_unknown_fields,
    bound(
        serialize = "Sh: serde::Serialize, M: serde::Serialize, Se: serde::Serialize",
        deserialize = "Sh: serde::Deserialize<'de>, M: serde::Deserialize<'de>, \
                       Se: serde::de::DeserializeOwned"
    )
)]
pub struct Contents<Sh, M, Se> {
    /// The shapes, in order.
    pub shapes: Vec<Sh>,
    /// The parameters whose sensitivities are wanted (none if absent).
    #[serde(default)]
    pub parameters: Vec<crate::scene::parameter::Parameter<M>>,
    /// What is measured (the first measurement's sensor if absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensor: Option<Se>,
    /// For an optimisation: what is measured, with targets and weights.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub measurements: Vec<crate::scene::objective::Measurement<Se>>,
    /// For an optimisation: what is made least or greatest.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub objective: Option<crate::scene::objective::Objective>,
}

impl<Sh, M, Se: Copy> Contents<Sh, M, Se> {
    /// A scene's file form: its shapes, parameters and sensor.
    pub fn of_parts(
        shapes: Vec<Sh>,
        parameters: Vec<crate::scene::parameter::Parameter<M>>,
        sensor: Se,
    ) -> Self {
        Contents {
            shapes,
            parameters,
            sensor: Some(sensor),
            measurements: Vec::new(),
            objective: None,
        }
    }

    /// The scene's sensor: the file's `[sensor]`, else its first
    /// measurement's.
    pub fn scene_sensor(&self) -> Result<Se, Error> {
        first_sensor(self.sensor, &self.measurements)
    }

    /// The optimisation's measurements and objective (refused without an
    /// `[objective]`).
    pub fn optimisation(
        &self,
    ) -> Result<
        (
            Vec<crate::scene::objective::Measurement<Se>>,
            crate::scene::objective::ObjectiveKind,
        ),
        Error,
    >
    where
        Se: Clone,
    {
        Ok((self.measurements.clone(), objective_of(&self.objective)?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_json_key_before_an_error_is_found() {
        let text = "{\n  \"a\": 1,\n  \"b\": \"x\"\n}";
        assert_eq!(key_before(text, 3, 10).as_deref(), Some("b"));
        assert_eq!(key_before(text, 2, 8).as_deref(), Some("a"));
        assert_eq!(key_before(text, 1, 1), None);
        assert_eq!(key_before(text, 4, 1), None);
    }
}
