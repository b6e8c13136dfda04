//! The file forms' shared pieces. Tagged enums (`kind = "absorber"`) are
//! written with every variant a struct variant, because serde's
//! `deny_unknown_fields` lets unknown fields through on the unit variants of
//! an internally tagged enum (serde-rs/serde#2123): `{ kind = "absorber",
//! albedo = 0.5 }` would load as a black absorber without a word.
//!
//! The fields of tagged enums are read through [`field`]: serde buffers a
//! tagged table before reading it, so the parser's position (TOML's span,
//! JSON's line and column) is the whole table's and its message alone
//! ("invalid type: string, expected f64") would not say which field is
//! wrong.
use serde::de::Error as _;
use serde::{Deserialize, Deserializer};

/// Deserializes a field, naming it in the error.
pub(crate) fn field<'de, D: Deserializer<'de>, T: Deserialize<'de>>(
    name: &str,
    d: D,
) -> Result<T, D::Error> {
    T::deserialize(d).map_err(|e| D::Error::custom(format_args!("field `{name}`: {e}")))
}

/// One deserializer per `name: type`, reading the field through [`field`]
/// (for `#[serde(deserialize_with = "name")]`).
macro_rules! fields {
    ($($name:ident: $t:ty),*) => {$(
        pub(super) fn $name<'de, D: serde::Deserializer<'de>>(d: D) -> Result<$t, D::Error> {
            $crate::scene::repr::field(stringify!($name), d)
        }
    )*};
}
pub(crate) use fields;

/// The two conversions between a tagged enum and its file form, whose unit
/// variants are empty struct variants there (see the module doc):
/// `file_form!(Form <-> super::Motion; units A, B; fields C { x, y })`.
/// Every variant is named, so a variant added to one side and not the
/// other fails to compile.
macro_rules! file_form {
    ($form:ident <-> $real:ty; units $($u:ident),*; fields $($v:ident { $($f:ident),* }),*) => {
        impl From<$form> for $real {
            fn from(m: $form) -> Self {
                match m {
                    $($form::$u {} => Self::$u,)*
                    $($form::$v { $($f),* } => Self::$v { $($f),* },)*
                }
            }
        }

        impl From<$real> for $form {
            fn from(m: $real) -> Self {
                type Real = $real;
                match m {
                    $(Real::$u => Self::$u {},)*
                    $(Real::$v { $($f),* } => Self::$v { $($f),* },)*
                }
            }
        }
    };
}
pub(crate) use file_form;
