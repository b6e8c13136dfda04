//! The file forms of [`Motion`](super::Motion) and [`Sensor`](super::Sensor),
//! written as `crate::scene::repr` says: every variant of a tagged enum a
//! struct variant (else `{ kind = "translate_x", pivot = [0, 0, 0] }` would
//! load without a word), or one holding a struct that refuses unknown
//! fields (the camera's, [`Camera`](crate::mesh::camera::Camera), written
//! once), fields read through `crate::scene::repr::field` so that errors
//! name them. Surfaces and phase functions have one file form for both
//! dimensions, in `crate::scene::material`.
use crate::scene::repr::{fields, file_form};
use glam::DVec3;
use serde::{Deserialize, Serialize};

fields!(axis: DVec3, pivot: Option<DVec3>, point: DVec3, direction: DVec3, normal: DVec3);

#[derive(Clone, Copy, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Motion {
    TranslateX {},
    TranslateY {},
    TranslateZ {},
    Rotate {
        #[serde(deserialize_with = "axis")]
        axis: DVec3,
        #[serde(
            default,
            deserialize_with = "pivot",
            skip_serializing_if = "Option::is_none"
        )]
        pivot: Option<DVec3>,
    },
    Scale {
        #[serde(
            default,
            deserialize_with = "pivot",
            skip_serializing_if = "Option::is_none"
        )]
        pivot: Option<DVec3>,
    },
}

file_form!(Motion <-> super::Motion; units TranslateX, TranslateY, TranslateZ; fields Rotate { axis, pivot }, Scale { pivot });

#[derive(Clone, Copy, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Sensor {
    Radiance {
        #[serde(deserialize_with = "point")]
        point: DVec3,
        #[serde(deserialize_with = "direction")]
        direction: DVec3,
    },
    Irradiance {
        #[serde(deserialize_with = "point")]
        point: DVec3,
        #[serde(deserialize_with = "normal")]
        normal: DVec3,
    },
    Camera(crate::mesh::camera::Camera),
}

impl From<Sensor> for super::Sensor {
    fn from(s: Sensor) -> Self {
        match s {
            Sensor::Radiance { point, direction } => Self::Radiance { point, direction },
            Sensor::Irradiance { point, normal } => Self::Irradiance { point, normal },
            Sensor::Camera(c) => Self::Camera(c),
        }
    }
}

impl From<super::Sensor> for Sensor {
    fn from(s: super::Sensor) -> Self {
        match s {
            super::Sensor::Radiance { point, direction } => Self::Radiance { point, direction },
            super::Sensor::Irradiance { point, normal } => Self::Irradiance { point, normal },
            super::Sensor::Camera(c) => Self::Camera(c),
        }
    }
}
