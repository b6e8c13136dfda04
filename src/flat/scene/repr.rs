//! The file forms of [`Surface`](super::Surface), [`Phase`](super::Phase)
//! and [`Motion`](super::Motion): internally tagged (`kind = "absorber"`)
//! with every variant a struct variant, because serde's
//! `deny_unknown_fields` lets unknown fields through on the unit variants of
//! an internally tagged enum (serde-rs/serde#2123): `{ kind = "absorber",
//! albedo = 0.5 }` would load as a black absorber without a word.
//!
//! The fields of tagged enums are read through [`field`]: serde buffers a
//! tagged table before reading it, so the parser's position (TOML's span,
//! JSON's line and column) is the whole table's and its message alone ("invalid
//! type: string, expected f64") would not say which field is wrong.
use glam::DVec2;
use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serialize};

/// Deserializes a field, naming it in the error.
fn field<'de, D: Deserializer<'de>, T: Deserialize<'de>>(name: &str, d: D) -> Result<T, D::Error> {
    T::deserialize(d).map_err(|e| D::Error::custom(format_args!("field `{name}`: {e}")))
}

macro_rules! fields {
    ($($name:ident: $t:ty),*) => {$(
        pub(super) fn $name<'de, D: Deserializer<'de>>(d: D) -> Result<$t, D::Error> {
            field(stringify!($name), d)
        }
    )*};
}
fields!(radiance: f64, albedo: f64, g: f64, pivot: Option<DVec2>,
    point: DVec2, direction: DVec2, normal: DVec2, position: DVec2, fov_deg: f64, width: u32);

#[derive(Clone, Copy, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Surface {
    Emitter {
        #[serde(deserialize_with = "radiance")]
        radiance: f64,
    },
    Absorber {},
    Reflector {
        #[serde(deserialize_with = "albedo")]
        albedo: f64,
    },
    Transparent {},
}

impl From<Surface> for super::Surface {
    fn from(s: Surface) -> Self {
        match s {
            Surface::Emitter { radiance } => Self::Emitter { radiance },
            Surface::Absorber {} => Self::Absorber,
            Surface::Reflector { albedo } => Self::Reflector { albedo },
            Surface::Transparent {} => Self::Transparent,
        }
    }
}

impl From<super::Surface> for Surface {
    fn from(s: super::Surface) -> Self {
        match s {
            super::Surface::Emitter { radiance } => Self::Emitter { radiance },
            super::Surface::Absorber => Self::Absorber {},
            super::Surface::Reflector { albedo } => Self::Reflector { albedo },
            super::Surface::Transparent => Self::Transparent {},
        }
    }
}

#[derive(Clone, Copy, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Phase {
    Isotropic {},
    HenyeyGreenstein {
        #[serde(deserialize_with = "g")]
        g: f64,
    },
}

/// A medium as a file gives it: flatland's `phase` table or 3D's `g`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Medium {
    ks: f64,
    ke: f64,
    #[serde(default)]
    phase: Option<super::Phase>,
    #[serde(default)]
    g: Option<f64>,
}

impl TryFrom<Medium> for super::Medium {
    type Error = String;

    fn try_from(m: Medium) -> Result<Self, String> {
        let phase = match (m.phase, m.g) {
            (Some(_), Some(_)) => {
                return Err("a medium takes `phase` or `g` (the 3D spelling), not both".into());
            }
            (Some(p), None) => p,
            (None, Some(0.0)) => super::Phase::Isotropic,
            (None, Some(g)) => super::Phase::HenyeyGreenstein { g },
            (None, None) => super::Phase::Isotropic,
        };
        Ok(super::Medium {
            ks: m.ks,
            ke: m.ke,
            phase,
        })
    }
}

impl From<Phase> for super::Phase {
    fn from(p: Phase) -> Self {
        match p {
            Phase::Isotropic {} => Self::Isotropic,
            Phase::HenyeyGreenstein { g } => Self::HenyeyGreenstein { g },
        }
    }
}

impl From<super::Phase> for Phase {
    fn from(p: super::Phase) -> Self {
        match p {
            super::Phase::Isotropic => Self::Isotropic {},
            super::Phase::HenyeyGreenstein { g } => Self::HenyeyGreenstein { g },
        }
    }
}

#[derive(Clone, Copy, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Motion {
    TranslateX {},
    TranslateY {},
    Rotate {
        #[serde(
            default,
            deserialize_with = "pivot",
            skip_serializing_if = "Option::is_none"
        )]
        pivot: Option<DVec2>,
    },
    Scale {
        #[serde(
            default,
            deserialize_with = "pivot",
            skip_serializing_if = "Option::is_none"
        )]
        pivot: Option<DVec2>,
    },
}

impl From<Motion> for super::Motion {
    fn from(m: Motion) -> Self {
        match m {
            Motion::TranslateX {} => Self::TranslateX,
            Motion::TranslateY {} => Self::TranslateY,
            Motion::Rotate { pivot } => Self::Rotate { pivot },
            Motion::Scale { pivot } => Self::Scale { pivot },
        }
    }
}

impl From<super::Motion> for Motion {
    fn from(m: super::Motion) -> Self {
        match m {
            super::Motion::TranslateX => Self::TranslateX {},
            super::Motion::TranslateY => Self::TranslateY {},
            super::Motion::Rotate { pivot } => Self::Rotate { pivot },
            super::Motion::Scale { pivot } => Self::Scale { pivot },
        }
    }
}

/// The path core's [`Surface`](super::Surface) reads and writes through the
/// file form (what `#[serde(from, into)]` would derive, written out because
/// the type lives in `crate::path`).
impl Serialize for super::Surface {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        Surface::from(*self).serialize(s)
    }
}

impl<'de> Deserialize<'de> for super::Surface {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        Surface::deserialize(d).map(Into::into)
    }
}
