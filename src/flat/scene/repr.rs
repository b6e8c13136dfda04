//! The file forms of flatland's [`Medium`](super::Medium) and
//! [`Motion`](super::Motion), written as `crate::scene::repr` says (every
//! variant of a tagged enum a struct variant, fields read through
//! `crate::scene::repr::field`). Surfaces and phase functions have one file
//! form for both dimensions, in `crate::scene::material`.
use crate::scene::repr::{fields, file_form};
use glam::DVec2;
use serde::{Deserialize, Serialize};

fields!(pivot: Option<DVec2>, point: DVec2, direction: DVec2, normal: DVec2, position: DVec2,
    fov_deg: f64, width: u32);

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

file_form!(Motion <-> super::Motion; units TranslateX, TranslateY; fields Rotate { pivot }, Scale { pivot });
