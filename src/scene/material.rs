//! Surfaces, media and phase functions, as both dimensions read and check
//! them: the file forms of the path core's [`Surface`] and of [`Phase`],
//! a surface's bounds, a medium's coefficients and thickness, the pairing
//! of the two (a medium sits behind a transparent surface and nothing
//! else), and how peaked a phase function the expectation method takes.
//! Book: chapter "Scene files: a reference"; chapter "When not to trust a
//! number", sections "Runs that end" and "Peaked phase functions".
use super::config;
use super::limits::{MAX_OPTICAL_THICKNESS, MAX_SCATTERING_EVENTS};
use super::repr::fields;
use crate::error::{Error, Num};
use crate::path::Surface;
use serde::{Deserialize, Deserializer, Serialize};

/// Angular distribution of scattering in a medium. Flatland normalises it
/// over the circle, 3D over the sphere; 3D files also spell it as a bare
/// `g`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(from = "PhaseForm", into = "PhaseForm")]
pub enum Phase {
    /// `p(θ) = 1/2π` (flatland), `1/4π` (3D).
    #[default]
    Isotropic,
    /// Henyey–Greenstein (in flatland, the wrapped Cauchy law
    /// `p(θ) = (1 − g²) / (2π (1 + g² − 2g cos θ))`).
    HenyeyGreenstein {
        /// Mean cosine, `|g| < 1`.
        g: f64,
    },
}

impl Phase {
    /// The mean cosine (0 for the isotropic function).
    pub fn g(self) -> f64 {
        match self {
            Phase::Isotropic => 0.0,
            Phase::HenyeyGreenstein { g } => g,
        }
    }
}

fields!(radiance: f64, albedo: f64, g: f64);

/// The file form of a [`Surface`] (`kind = "emitter"`, …).
#[derive(Clone, Copy, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
enum SurfaceForm {
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

impl From<SurfaceForm> for Surface {
    fn from(s: SurfaceForm) -> Self {
        match s {
            SurfaceForm::Emitter { radiance } => Self::Emitter { radiance },
            SurfaceForm::Absorber {} => Self::Absorber,
            SurfaceForm::Reflector { albedo } => Self::Reflector { albedo },
            SurfaceForm::Transparent {} => Self::Transparent,
        }
    }
}

impl From<Surface> for SurfaceForm {
    fn from(s: Surface) -> Self {
        match s {
            Surface::Emitter { radiance } => Self::Emitter { radiance },
            Surface::Absorber => Self::Absorber {},
            Surface::Reflector { albedo } => Self::Reflector { albedo },
            Surface::Transparent => Self::Transparent {},
        }
    }
}

/// The path core's [`Surface`] reads and writes through the file form
/// (what `#[serde(from, into)]` would derive, written out because the type
/// lives in `crate::path`).
impl Serialize for Surface {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        SurfaceForm::from(*self).serialize(s)
    }
}

impl<'de> Deserialize<'de> for Surface {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        SurfaceForm::deserialize(d).map(Into::into)
    }
}

/// The file form of a [`Phase`] (`kind = "henyey_greenstein", g = …`).
#[derive(Clone, Copy, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
enum PhaseForm {
    Isotropic {},
    HenyeyGreenstein {
        #[serde(deserialize_with = "g")]
        g: f64,
    },
}

impl From<PhaseForm> for Phase {
    fn from(p: PhaseForm) -> Self {
        match p {
            PhaseForm::Isotropic {} => Self::Isotropic,
            PhaseForm::HenyeyGreenstein { g } => Self::HenyeyGreenstein { g },
        }
    }
}

impl From<Phase> for PhaseForm {
    fn from(p: Phase) -> Self {
        match p {
            Phase::Isotropic => Self::Isotropic {},
            Phase::HenyeyGreenstein { g } => Self::HenyeyGreenstein { g },
        }
    }
}

/// A homogeneous medium's coefficients as the checks see them, whichever
/// dimension's type holds them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coefficients {
    /// Scattering coefficient κs.
    pub ks: f64,
    /// Extinction coefficient κe.
    pub ke: f64,
    /// The phase function's mean cosine.
    pub g: f64,
}

/// Checks shape `name`'s surface, and its medium against it: a medium only
/// behind a transparent surface, and only in a `closed` shape; a
/// transparent surface only around a medium (else it would be invisible).
pub(crate) fn check_material(
    name: &str,
    surface: &Surface,
    medium: Option<Coefficients>,
    closed: bool,
) -> Result<(), Error> {
    check_surface(name, surface)?;
    match (medium, surface) {
        (Some(m), Surface::Transparent) => {
            if !closed {
                return config(format!("shape {name:?} has a medium but is not closed"));
            }
            check_medium(name, m)
        }
        (Some(_), _) => config(format!(
            "shape {name:?} has a medium behind an opaque surface: \
             make its surface transparent"
        )),
        (None, Surface::Transparent) => config(format!(
            "shape {name:?} is transparent but holds no medium: it would be invisible"
        )),
        (None, _) => Ok(()),
    }
}

fn check_surface(name: &str, s: &Surface) -> Result<(), Error> {
    match *s {
        Surface::Emitter { radiance } if !(radiance >= 0.0 && radiance.is_finite()) => {
            config(format!(
                "shape {name:?}: radiance {} is not a finite number ≥ 0",
                Num(radiance)
            ))
        }
        Surface::Reflector { albedo } if !(0.0..=1.0).contains(&albedo) => config(format!(
            "shape {name:?}: albedo {} is not in [0, 1]",
            Num(albedo)
        )),
        _ => Ok(()),
    }
}

fn check_medium(name: &str, m: Coefficients) -> Result<(), Error> {
    if !(m.ks >= 0.0 && m.ks.is_finite()) {
        return config(format!(
            "shape {name:?}: κs = {} is not finite and ≥ 0",
            Num(m.ks)
        ));
    }
    if !(m.ke >= m.ks && m.ke.is_finite()) {
        return config(format!(
            "shape {name:?}: κe = {} must be finite and ≥ κs = {}",
            Num(m.ke),
            Num(m.ks)
        ));
    }
    if m.g.abs() >= 1.0 || m.g.is_nan() {
        return config(format!(
            "shape {name:?}: Henyey–Greenstein g = {} is not in (−1, 1)",
            Num(m.g)
        ));
    }
    Ok(())
}

/// Rejects the medium of shape `name` if it is thicker than
/// [`MAX_OPTICAL_THICKNESS`] across the scene (of size `size`), or if a path
/// in it would scatter more than [`MAX_SCATTERING_EVENTS`] times.
pub(crate) fn check_thickness(name: &str, m: Coefficients, size: f64) -> Result<(), Error> {
    if m.ke * size > MAX_OPTICAL_THICKNESS {
        return config(format!(
            "shape {name:?}: κe × scene size = {} exceeds {MAX_OPTICAL_THICKNESS}",
            Num(m.ke * size)
        ));
    }
    // A path in a medium scatters about min(τs², κs/κa) times before it
    // leaves or the roulette ends it (its weight falls by e^{−κa/κs} per
    // event): beyond MAX_SCATTERING_EVENTS a run would not end.
    let tau = m.ks * size;
    let ka = m.ke - m.ks;
    let events = if ka > 0.0 {
        (tau * tau).min(m.ks / ka)
    } else {
        tau * tau
    };
    if events > MAX_SCATTERING_EVENTS {
        return config(format!(
            "shape {name:?}: κs × scene size = {tau:.4e} with albedo {:.6}: a path would \
             scatter ~{events:.1e} times (at most {MAX_SCATTERING_EVENTS:e} are \
             supported); lower κs or raise the absorption",
            m.ks / m.ke
        ));
    }
    Ok(())
}

/// Largest `|g|` of a Henyey–Greenstein medium the expectation method
/// accepts. Its warp turns scattered directions relative to the incoming
/// one, so its score carries `∂ ln p` along the warp, of order `1/(1 − |g|)`:
/// measured on scenes/fog.toml, its σ is 1.2× rendering's at g = 0.9, 4× at
/// 0.99 and 44× at 0.999 (and ~10⁶× at 0.99999999, where no error bar of a
/// feasible run means anything).
pub const MAX_EXPECTATION_G: f64 = 0.99;

/// Refuses a Henyey–Greenstein `g` beyond [`MAX_EXPECTATION_G`] for the
/// expectation method, naming the `kind` ("shape", "mesh") `name` holding
/// it.
pub(crate) fn check_expectation_g(kind: &str, name: &str, g: f64) -> Result<(), Error> {
    if g.abs() > MAX_EXPECTATION_G {
        return Err(Error::Scene(format!(
            "{kind} {name:?}: Henyey–Greenstein g = {g} is too peaked for the expectation \
             method (|g| ≤ {MAX_EXPECTATION_G}: its variance grows as 1/(1 − |g|)²); \
             use rendering or transport"
        )));
    }
    Ok(())
}
