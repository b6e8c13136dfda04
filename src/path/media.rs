//! The media of a scene as the walk sees them, whatever the dimension: per
//! shape, its medium's coefficients, a bound on its chords (for the
//! thin-media rate, [`super::thin_media`]) and the medium around it, so
//! that a ray crossing a transparent boundary knows where it goes. Each
//! geometry builds one ([`Media::new`]) and the [`Geometry`](super::Geometry)
//! trait answers `coefficients`, `medium_chord` and `crossed` from it.
use super::thin_media::chord_bound;
use super::{Coefficients, MediumId, Vector};

/// Per shape: its medium (if any), its chord bound, the medium around it.
#[derive(Debug, Clone, Default)]
pub struct Media {
    coefficients: Vec<Option<Coefficients>>,
    /// A bound on each medium's chords; 0 for the shapes without one (the
    /// walk asks only of media).
    chords: Vec<f64>,
    parent: Vec<Option<u32>>,
}

/// No medium anywhere: what a geometry without media answers from.
pub static NO_MEDIA: Media = Media {
    coefficients: Vec::new(),
    chords: Vec::new(),
    parent: Vec::new(),
};

impl Media {
    /// The table of shapes given in order as (their medium's
    /// coefficients, their boundary's vertices, the medium around them).
    pub fn new<'a, V: Vector + 'a>(
        shapes: impl IntoIterator<Item = (Option<Coefficients>, &'a [V], Option<u32>)>,
    ) -> Media {
        let mut media = Media::default();
        for (coefficients, vertices, parent) in shapes {
            media
                .chords
                .push(coefficients.map_or(0.0, |_| chord_bound(vertices)));
            media.coefficients.push(coefficients);
            media.parent.push(parent);
        }
        media
    }

    /// The coefficients of medium `m` (`None`: vacuum).
    #[inline]
    pub fn coefficients(&self, m: MediumId) -> Option<Coefficients> {
        m.and_then(|k| self.coefficients[k as usize])
    }

    /// A bound on the chords of medium `m` (infinite in vacuum).
    #[inline]
    pub fn chord(&self, m: MediumId) -> f64 {
        m.map_or(f64::INFINITY, |k| self.chords[k as usize])
    }

    /// The medium entered or left when a ray in `m` crosses the
    /// transparent boundary of shape `k`: out to the medium around `k` if
    /// `m` is `k`'s, else into `k`'s.
    #[inline]
    pub fn crossed(&self, m: MediumId, k: u32) -> MediumId {
        if m == Some(k) {
            self.parent[k as usize]
        } else {
            Some(k)
        }
    }
}
