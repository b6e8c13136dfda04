//! Per-pixel float images: the files `geosens render` writes for the
//! intensity `I`, for every shape-parameter sensitivity and for their
//! standard errors.
//!
//! A [`Plane`] is borrowed row-major `f64` data. It is written as the numbers
//! ([`write_exr`], 32-bit float OpenEXR for image viewers; [`write_npy`],
//! exact `f64` for NumPy) or as a picture ([`write_png_magnitude`] for
//! values ≥ 0 such as `I` and standard errors; [`write_png_diverging`] for
//! signed sensitivities). [`robust_scale`] picks a display range that a few
//! outlier pixels cannot flatten; a PNG shows it in a colour bar under the
//! image (the map over the range, with [`scale_tag`]'s numbers at its ends
//! and at 0) and holds it in its text (`Scale`, and a `Description` of the
//! map), so that its name need not change with it.
//!
//! Each `write_*` writes one file whole or not at all (through a temporary
//! renamed when complete); each `add_*` writes one file of a
//! [`FileSet`], whose files are renamed into place together. Every writer
//! checks the plane first and names the file in its errors
//! ([`Error::Output`]); none panics on bad input.
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

use crate::error::Error;
use crate::file_set::{FileSet, io_error, output_error};

/// A row-major image of f64 values, row 0 at the top.
#[derive(Debug, Clone, Copy)]
pub struct Plane<'a> {
    /// Pixels per row (≥ 1).
    pub width: usize,
    /// Rows (≥ 1).
    pub height: usize,
    /// `width * height` values, row by row from the top, left to right.
    pub data: &'a [f64],
}

/// The colour of a non-finite pixel (NaN, ±∞) in the PNGs: magenta, which
/// neither viridis nor red–blue contains.
pub const NON_FINITE_RGB: [u8; 3] = [255, 0, 255];

/// The file `add` writes, as a set of one.
fn whole(add: impl FnOnce(&mut FileSet) -> Result<(), Error>) -> Result<(), Error> {
    let mut set = FileSet::new();
    add(&mut set)?;
    set.commit().map(drop)
}

/// Writes `plane` as OpenEXR ([`add_exr`]), whole or not at all.
pub fn write_exr(path: &Path, plane: &Plane) -> Result<(), Error> {
    whole(|set| add_exr(set, path, plane))
}

/// Writes `plane` as OpenEXR into `set`: one channel `Y` of 32-bit floats,
/// ZIP compressed (lossless), row 0 at the top. Values are converted with
/// `as f32` (rounded to nearest; beyond the f32 range they become ±∞); NaN
/// and ±∞ are written as they are.
pub fn add_exr(set: &mut FileSet, path: &Path, plane: &Plane) -> Result<(), Error> {
    use exr::prelude::{AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer};
    use exr::prelude::{LayerAttributes, WritableImage};
    check(path, plane)?;
    let samples = plane.data.iter().map(|&x| x as f32).collect();
    let channel = AnyChannel::new("Y", FlatSamples::F32(samples));
    let layer = Layer::new(
        (plane.width, plane.height),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(vec![channel].into()),
    );
    set.write(path, |out| {
        let written = Image::from_layer(layer).write().to_buffered(out);
        written.map_err(|e| match e {
            exr::error::Error::Io(e) => io_error(path, &e),
            e => output_error(path, e),
        })
    })
}

/// Writes `plane` as a NumPy `.npy` file ([`add_npy`]), whole or not at all.
pub fn write_npy(path: &Path, plane: &Plane) -> Result<(), Error> {
    whole(|set| add_npy(set, path, plane))
}

/// Writes `plane` into `set` as a NumPy `.npy` file (format version 1.0): dtype `'<f8'`
/// (little-endian f64), shape `(height, width)`, C order, every value bit for
/// bit, NaN and ±∞ included. `numpy.load(path)` reads it back.
///
/// Written by hand rather than with `npyz`: the format is a 10-byte preamble,
/// a Python-literal header and the raw values, about 15 lines here, while
/// `npyz` (whose reader parses any header) brings `py_literal`, `pest`,
/// `pest_derive`, `num-bigint` and `psm`'s assembly build script, some twenty
/// crates, to write one fixed header.
pub fn add_npy(set: &mut FileSet, path: &Path, plane: &Plane) -> Result<(), Error> {
    check(path, plane)?;
    let dict = format!(
        "{{'descr': '<f8', 'fortran_order': False, 'shape': ({}, {}), }}",
        plane.height, plane.width
    );
    // Magic, version 1.0, header length (u16 LE), then the dictionary padded
    // with spaces and ended by '\n' so that the data start at a multiple of
    // 64 bytes, as NumPy writes it.
    let header_len = (10 + dict.len() + 1).div_ceil(64) * 64 - 10;
    let mut header = Vec::with_capacity(10 + header_len);
    header.extend_from_slice(b"\x93NUMPY\x01\x00");
    header.extend_from_slice(&(header_len as u16).to_le_bytes());
    header.extend_from_slice(dict.as_bytes());
    header.resize(10 + header_len - 1, b' ');
    header.push(b'\n');
    set.write(path, |out| {
        let mut write = || -> io::Result<()> {
            out.write_all(&header)?;
            (plane.data.iter()).try_for_each(|x| out.write_all(&x.to_le_bytes()))
        };
        write().map_err(|e| io_error(path, &e))
    })
}

/// Writes `plane` as a PNG ([`add_png_magnitude`]), whole or not at all.
pub fn write_png_magnitude(path: &Path, plane: &Plane, max: f64) -> Result<(), Error> {
    whole(|set| add_png_magnitude(set, path, plane, max))
}

/// Writes `plane` into `set` as an 8-bit RGB PNG in the perceptual map
/// viridis, from **0** (dark purple, `#440154`) to `max` (yellow,
/// `#fde725`); a colour bar under the image labels `0` and `max`, and its
/// text gives `max` (`Scale`) and the map (`Description`). The image keeps
/// its pixels at the top left, 1:1; the canvas is wider than the image
/// only when the bar's numbers need it (white on the right).
///
/// The low end is 0, not the image's minimum, so that the images of one
/// render (`I` and its standard error) read alike and a colour means the same
/// value in each; negative values (Monte Carlo noise on a quantity ≥ 0) clamp
/// to the low end, values above `max` to the high end. NaN and ±∞ are
/// [magenta](NON_FINITE_RGB). A `max` ≤ 0 or not finite is "no range": every
/// finite pixel takes the low colour.
pub fn add_png_magnitude(
    set: &mut FileSet,
    path: &Path,
    plane: &Plane,
    max: f64,
) -> Result<(), Error> {
    let legend = if ranged(max) {
        format!(
            "viridis from 0 (#440154) to {} (#fde725), clamped; magenta: not finite",
            scale_tag(max)
        )
    } else {
        NO_RANGE.to_owned()
    };
    let bar = if ranged(max) {
        Bar::new((0.0, max), vec![(0.0, "0".into()), (max, scale_tag(max))])
    } else {
        Bar::no_range()
    };
    add_png(set, path, plane, magnitude_map(max), (max, &legend), &bar)
}

/// Whether a PNG's scale spans a range (else every finite pixel takes one
/// colour).
fn ranged(scale: f64) -> bool {
    scale.is_finite() && scale > 0.0
}

/// A PNG's description when its scale spans no range.
const NO_RANGE: &str =
    "no range (a scale of 0, negative or not finite): one colour; magenta: not finite";

/// The colour of a finite value in [`write_png_magnitude`]'s map (viridis
/// from 0 to `max`), for drawing such images elsewhere (the book's figures).
pub fn magnitude_map(max: f64) -> impl Fn(f64) -> [u8; 3] {
    let ranged = ranged(max);
    move |x| {
        let t = if ranged { x / max } else { 0.0 };
        let c = colorous::VIRIDIS.eval_continuous(t.clamp(0.0, 1.0));
        [c.r, c.g, c.b]
    }
}

/// Writes `plane` as a PNG ([`add_png_diverging`]), whole or not at all.
pub fn write_png_diverging(path: &Path, plane: &Plane, scale: f64) -> Result<(), Error> {
    whole(|set| add_png_diverging(set, path, plane, scale))
}

/// Writes `plane` into `set` as an 8-bit RGB PNG in the diverging map
/// red–blue (ColorBrewer RdBu reversed; a colour bar under the image labels
/// `-scale`, `0` and `+scale`, and its text gives `scale` and the map, as
/// [`add_png_magnitude`]'s): `+scale` and above are dark red (`#67001f`),
/// `-scale` and below dark blue (`#053061`), 0 the neutral near-white middle
/// (`#f7f7f7`). Colours are interpolated linearly between the map's 11 stops,
/// as matplotlib's `RdBu_r` does (colorous's own continuous evaluation is a
/// B-spline that misses the interior stops: its middle is a warm `#f1efed`).
///
/// NaN and ±∞ are [magenta](NON_FINITE_RGB). A `scale` ≤ 0 or not finite is
/// "no range": every finite pixel takes the middle colour.
pub fn add_png_diverging(
    set: &mut FileSet,
    path: &Path,
    plane: &Plane,
    scale: f64,
) -> Result<(), Error> {
    let tag = scale_tag(scale);
    let legend = if ranged(scale) {
        format!(
            "red-blue (RdBu reversed) from -{tag} (#053061) through 0 (#f7f7f7) to +{tag} \
             (#67001f), clamped; magenta: not finite"
        )
    } else {
        NO_RANGE.to_owned()
    };
    let bar = if ranged(scale) {
        let labels = vec![
            (-scale, format!("-{tag}")),
            (0.0, "0".into()),
            (scale, format!("+{tag}")),
        ];
        Bar::new((-scale, scale), labels)
    } else {
        Bar::no_range()
    };
    add_png(
        set,
        path,
        plane,
        diverging_map(scale),
        (scale, &legend),
        &bar,
    )
}

/// The colour of a finite value in [`write_png_diverging`]'s map (red–blue
/// over `±scale`), for drawing such images elsewhere (the book's figures).
pub fn diverging_map(scale: f64) -> impl Fn(f64) -> [u8; 3] {
    let ranged = ranged(scale);
    // Stop k of 0..=10 runs from blue (k = 0, negative) to red (k = 10).
    let stops: Vec<[f64; 3]> = (0..11)
        .map(|k| colorous::RED_BLUE.eval_rational(10 - k, 11))
        .map(|c| [c.r, c.g, c.b].map(f64::from))
        .collect();
    move |x| {
        let t = if ranged { 0.5 + 0.5 * x / scale } else { 0.5 };
        let p = 10.0 * t.clamp(0.0, 1.0);
        let k = (p.floor() as usize).min(9);
        let (a, b, f) = (stops[k], stops[k + 1], p - k as f64);
        [0, 1, 2].map(|i| (a[i] + f * (b[i] - a[i])).round() as u8)
    }
}

/// A display scale robust to a few outliers: the 99th percentile of `|x|`
/// over the finite values.
///
/// The rule: sort the `n` finite `|x|` and take the one of rank
/// `⌈0.99 n⌉` (nearest-rank percentile), so the `⌊n / 100⌋` largest are
/// ignored. When that is 0 but some value is not (fewer than 1 % of the
/// pixels are non-zero, as for a sensitivity that lives on a silhouette),
/// the largest `|x|` is returned instead. An empty, all-zero or all-non-finite
/// image gives 0, which the PNG writers take as "no range".
pub fn robust_scale(data: &[f64]) -> f64 {
    let finite = data.iter().filter(|x| x.is_finite());
    let mut a: Vec<f64> = finite.map(|x| x.abs()).collect();
    if a.is_empty() {
        return 0.0;
    }
    let rank = (a.len() * 99).div_ceil(100);
    let (_, &mut p, _) = a.select_nth_unstable_by(rank - 1, f64::total_cmp);
    if p > 0.0 {
        p
    } else {
        a.iter().fold(0.0, |m, &x| m.max(x))
    }
}

/// A short rendering of a scale (a PNG's description) with three significant
/// digits and no trailing zeros: `0.0123` → `"1.23e-2"`, `1.0` → `"1e0"`,
/// `250.0` → `"2.5e2"`; `0` → `"0"`, a negative value keeps its `-`, NaN →
/// `"nan"`, ±∞ → `"inf"`/`"-inf"`. Only digits, `.`, `-`, `e` and those
/// words appear.
pub fn scale_tag(scale: f64) -> String {
    if scale == 0.0 {
        return "0".into();
    }
    if !scale.is_finite() {
        return scale.to_string().to_lowercase();
    }
    let text = format!("{scale:.2e}");
    match text.split_once('e') {
        Some((mantissa, exp)) => {
            let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
            format!("{mantissa}e{exp}")
        }
        None => text,
    }
}

/// Checks the plane's shape, naming `path` in the error.
fn check(path: &Path, plane: &Plane) -> Result<(), Error> {
    let (w, h, n) = (plane.width, plane.height, plane.data.len());
    let cause = if w == 0 || h == 0 {
        format!("the image is {w}×{h}: width and height must be ≥ 1")
    } else if w.checked_mul(h) != Some(n) {
        format!("the image is {w}×{h} but has {n} values")
    } else {
        return Ok(());
    };
    Err(output_error(path, cause))
}

/// The colour bar drawn under a PNG's image: the map over the displayed
/// range, with numbers at some of its values, so that the picture carries
/// its own scale.
#[derive(Debug, Clone, PartialEq)]
struct Bar {
    /// The values at the bar's left and right ends.
    range: (f64, f64),
    /// Values and their labels (digits, `.`, `-`, `+`, `e`).
    labels: Vec<(f64, String)>,
}

impl Bar {
    fn new(range: (f64, f64), labels: Vec<(f64, String)>) -> Bar {
        Bar { range, labels }
    }

    /// The bar of a map without a range: one colour, labelled so.
    fn no_range() -> Bar {
        Bar::new((0.0, 1.0), vec![(0.5, "no range".into())])
    }
}

/// Rows of the 5×7 pixel font of the colour bar's labels (bit 4 is the
/// leftmost column); a character it lacks is drawn blank.
fn glyph(c: char) -> [u8; 7] {
    match c {
        '0' => [0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E],
        '1' => [0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E],
        '2' => [0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F],
        '3' => [0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E],
        '4' => [0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02],
        '5' => [0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E],
        '6' => [0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E],
        '7' => [0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08],
        '8' => [0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E],
        '9' => [0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C],
        '.' => [0, 0, 0, 0, 0, 0x0C, 0x0C],
        '-' => [0, 0, 0, 0x1F, 0, 0, 0],
        '+' => [0, 0x04, 0x04, 0x1F, 0x04, 0x04, 0],
        'e' => [0, 0, 0x0E, 0x11, 0x1F, 0x10, 0x0E],
        'n' => [0, 0, 0x16, 0x19, 0x11, 0x11, 0x11],
        'o' => [0, 0, 0x0E, 0x11, 0x11, 0x11, 0x0E],
        'r' => [0, 0, 0x16, 0x19, 0x10, 0x10, 0x10],
        'a' => [0, 0, 0x0E, 0x01, 0x0F, 0x11, 0x0F],
        'g' => [0, 0x0F, 0x11, 0x11, 0x0F, 0x01, 0x0E],
        _ => [0; 7],
    }
}

/// Colour of the bar's text and ticks.
const INK: [u8; 3] = [0x20, 0x20, 0x20];
/// Colour around the image and the bar.
const PAPER: [u8; 3] = [0xff, 0xff, 0xff];

/// An RGB picture being drawn: the image, then its colour bar.
struct Canvas {
    width: usize,
    height: usize,
    rgb: Vec<u8>,
}

impl Canvas {
    fn set(&mut self, x: usize, y: usize, c: [u8; 3]) {
        if x < self.width && y < self.height {
            let i = 3 * (y * self.width + x);
            self.rgb[i..i + 3].copy_from_slice(&c);
        }
    }

    /// `text` with its top left at `(x, y)`, each font pixel `k`×`k`.
    fn text(&mut self, (x, y): (usize, usize), text: &str, k: usize) {
        for (i, c) in text.chars().enumerate() {
            for (row, bits) in glyph(c).into_iter().enumerate() {
                for col in (0..5).filter(|col| bits & (0x10 >> col) != 0) {
                    for (dx, dy) in (0..k).flat_map(|dx| (0..k).map(move |dy| (dx, dy))) {
                        let px = x + (6 * i + col) * k + dx;
                        self.set(px, y + row * k + dy, INK);
                    }
                }
            }
        }
    }
}

/// Width in pixels of `text` in the bar's font at `k` pixels per font pixel.
fn text_width(text: &str, k: usize) -> usize {
    (6 * text.chars().count()).saturating_sub(1) * k
}

/// The picture of a PNG: `plane`'s pixels (`pixel` of each value) at the top
/// left, 1:1, and under them `bar` in `colour`, with its labels; the canvas
/// is widened (white on the right) when the image is too narrow for them.
fn picture(
    plane: &Plane,
    pixel: impl Fn(f64) -> [u8; 3],
    colour: impl Fn(f64) -> [u8; 3],
    bar: &Bar,
) -> Canvas {
    // Font pixels grow with the image, so that the numbers stay legible
    // beside it without dwarfing a small one.
    let k = (plane.width / 100).clamp(1, 4);
    let pad = 2 * k;
    // The first label starts at the bar's left end, the last ends at its
    // right end, a middle one is centred: room for a gap of 6 font pixels
    // between neighbours ("−7.47e-2 0 +7.47e-2" under a 32-pixel image ran
    // together with less).
    let w: Vec<usize> = bar.labels.iter().map(|(_, t)| text_width(t, k)).collect();
    let gap = 6 * k;
    let labels = match w.as_slice() {
        [a, m, b] => 2 * (*a).max(*b) + m + 2 * gap,
        _ => w.iter().sum::<usize>() + gap * w.len().saturating_sub(1),
    };
    let width = plane.width.max(labels + 2 * pad);
    let (bar_top, bar_h, tick) = (plane.height + 2 * k, 5 * k, 2 * k);
    let text_top = bar_top + bar_h + tick + k;
    let height = text_top + 7 * k + 2 * k;
    let mut canvas = Canvas {
        width,
        height,
        rgb: PAPER.repeat(width * height),
    };
    for (i, &v) in plane.data.iter().enumerate() {
        canvas.set(i % plane.width, i / plane.width, pixel(v));
    }
    let (lo, hi) = bar.range;
    let span = (width - 2 * pad) as f64;
    let at = |v: f64| pad as f64 + span * (v - lo) / (hi - lo);
    for x in pad..width - pad {
        let c = colour(lo + (hi - lo) * (x - pad) as f64 / (span - 1.0).max(1.0));
        for y in bar_top..bar_top + bar_h {
            canvas.set(x, y, c);
        }
    }
    for (v, text) in &bar.labels {
        let x = at(*v).round().clamp(pad as f64, (width - pad - 1) as f64) as usize;
        for dx in 0..k.min(width - x) {
            for y in bar_top + bar_h..bar_top + bar_h + tick {
                canvas.set(x + dx, y, INK);
            }
        }
        // Centred on its tick, kept inside the canvas.
        let w = text_width(text, k);
        let last = width.saturating_sub(pad + w).max(pad);
        canvas.text(
            ((x.saturating_sub(w / 2)).clamp(pad, last), text_top),
            text,
            k,
        );
    }
    canvas
}

/// Checks `plane`, maps every value to a colour and writes the PNG into
/// `set`: the image with its colour `bar` under it, and its scale and the
/// map's description (`legend`) as text.
fn add_png(
    set: &mut FileSet,
    path: &Path,
    plane: &Plane,
    colour: impl Fn(f64) -> [u8; 3],
    (scale, legend): (f64, &str),
    bar: &Bar,
) -> Result<(), Error> {
    check(path, plane)?;
    let pixel = |x: f64| {
        if x.is_finite() {
            colour(x)
        } else {
            NON_FINITE_RGB
        }
    };
    let canvas = picture(plane, pixel, &colour, bar);
    let size = |n: usize, what: &str| {
        u32::try_from(n).map_err(|_| output_error(path, format!("{what} {n} is too large for PNG")))
    };
    let (w, h) = (size(canvas.width, "width")?, size(canvas.height, "height")?);
    let rgb = canvas.rgb;
    let png_error = |e: png::EncodingError| match e {
        png::EncodingError::IoError(e) => io_error(path, &e),
        e => output_error(path, e),
    };
    set.write(path, |out: &mut BufWriter<File>| {
        let mut encoder = png::Encoder::new(out, w, h);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        // The scale at full precision (it round-trips), ASCII as tEXt wants.
        encoder
            .add_text_chunk("Scale".into(), format!("{scale:e}"))
            .map_err(png_error)?;
        encoder
            .add_text_chunk("Description".into(), legend.into())
            .map_err(png_error)?;
        let mut writer = encoder.write_header().map_err(png_error)?;
        writer.write_image_data(&rgb).map_err(png_error)?;
        writer.finish().map_err(png_error)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    /// A fresh directory under the system temp dir, removed on drop.
    struct TempDir(PathBuf);

    impl TempDir {
        fn new(name: &str) -> Self {
            let pid = std::process::id();
            let dir = std::env::temp_dir().join(format!("geosens-image_io-{pid}-{name}"));
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).unwrap();
            TempDir(dir)
        }
    }

    impl Drop for TempDir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    const NAN: f64 = f64::NAN;
    const INF: f64 = f64::INFINITY;
    /// 3 rows of 4, with NaN, both infinities and a value beyond f32.
    const DATA: [f64; 12] = [
        0.0, -1.5, 2.25, 1e-300, NAN, INF, -INF, 1e40, -0.0, 3.0, 4.0, 0.1,
    ];

    fn plane(width: usize, height: usize, data: &[f64]) -> Plane<'_> {
        Plane {
            width,
            height,
            data,
        }
    }

    #[test]
    fn exr_reads_back_as_f32() {
        let dir = TempDir::new("exr");
        let path = dir.0.join("i.exr");
        write_exr(&path, &plane(4, 3, &DATA)).unwrap();
        let image = exr::prelude::read_first_flat_layer_from_file(&path).unwrap();
        let layer = &image.layer_data;
        assert_eq!((layer.size.width(), layer.size.height()), (4, 3));
        let [channel] = &layer.channel_data.list[..] else {
            panic!("not one channel")
        };
        assert!(channel.name.eq("Y"));
        let exr::prelude::FlatSamples::F32(read) = &channel.sample_data else {
            panic!("not f32")
        };
        let expected = DATA.iter().map(|&x| (x as f32).to_bits());
        assert!(read.iter().map(|x| x.to_bits()).eq(expected));
    }

    #[test]
    fn npy_reads_back_exactly() {
        let dir = TempDir::new("npy");
        let path = dir.0.join("i.npy");
        write_npy(&path, &plane(4, 3, &DATA)).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
        let start = 10 + u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        assert_eq!((start % 64, bytes.len()), (0, start + 8 * 12));
        let header = std::str::from_utf8(&bytes[10..start]).unwrap();
        let dict = "{'descr': '<f8', 'fortran_order': False, 'shape': (3, 4), }";
        assert_eq!((header.trim_end(), header.ends_with('\n')), (dict, true));
        let read = bytes[start..]
            .chunks(8)
            .map(|c| u64::from_le_bytes(c.try_into().unwrap()));
        assert!(read.eq(DATA.iter().map(|x| x.to_bits())));
    }

    /// Decodes a PNG of `geosens render` and keeps its image, the top left
    /// `w`×`h` pixels (the colour bar under it and any margin cut away).
    fn image(path: &Path, w: usize, h: usize) -> Vec<[u8; 3]> {
        let (width, height, px) = decode(path);
        assert!(width as usize >= w && height as usize > h);
        (0..h)
            .flat_map(|y| px[y * width as usize..][..w].to_vec())
            .collect()
    }

    /// Decodes an 8-bit RGB PNG: (width, height, pixels).
    fn decode(path: &Path) -> (u32, u32, Vec<[u8; 3]>) {
        let file = std::io::BufReader::new(File::open(path).unwrap());
        let mut reader = png::Decoder::new(file).read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        let format = (info.color_type, info.bit_depth);
        assert_eq!(format, (png::ColorType::Rgb, png::BitDepth::Eight));
        let pixels = buf[..info.buffer_size()].chunks(3);
        (
            info.width,
            info.height,
            pixels.map(|c| [c[0], c[1], c[2]]).collect(),
        )
    }

    #[test]
    fn diverging_png_is_centred_on_zero() {
        let dir = TempDir::new("div");
        let path = dir.0.join("d.png");
        let data = [0.0, 2.0, -2.0, 5.0, -5.0, NAN];
        write_png_diverging(&path, &plane(3, 2, &data), 2.0).unwrap();
        let (mid, red, blue) = ([0xf7, 0xf7, 0xf7], [0x67, 0x00, 0x1f], [0x05, 0x30, 0x61]);
        let px = image(&path, 3, 2);
        assert_eq!(px, [mid, red, blue, red, blue, NON_FINITE_RGB]);
        for no_range in [0.0, -1.0, NAN, INF] {
            write_png_diverging(&path, &plane(3, 2, &data), no_range).unwrap();
            let px = image(&path, 3, 2);
            assert_eq!(px, [mid, mid, mid, mid, mid, NON_FINITE_RGB]);
        }
    }

    #[test]
    fn magnitude_png_spans_viridis() {
        let dir = TempDir::new("mag");
        let path = dir.0.join("i.png");
        let data = [0.0, 3.0, -1.0, 7.0, INF, 1.5];
        write_png_magnitude(&path, &plane(2, 3, &data), 3.0).unwrap();
        let (low, high) = ([0x44, 0x01, 0x54], [0xfd, 0xe7, 0x25]);
        let px = image(&path, 2, 3);
        assert_eq!(px[..5], [low, high, low, high, NON_FINITE_RGB]);
        assert!(px[5] != low && px[5] != high);
        write_png_magnitude(&path, &plane(2, 3, &data), 0.0).unwrap();
        let px = image(&path, 2, 3);
        assert_eq!(px, [low, low, low, low, NON_FINITE_RGB, low]);
    }

    /// The colour bar's row of pixels through its middle and whether any
    /// pixel under it is ink (its labels).
    fn bar_row(path: &Path, image_height: usize) -> (Vec<[u8; 3]>, bool) {
        let (width, height, px) = decode(path);
        // Images under 100 pixels wide: one pixel per font pixel.
        let k = 1;
        let y = image_height + 2 * k + 2 * k;
        let row = px[y * width as usize..][..width as usize].to_vec();
        let below = &px[(image_height + 9 * k) * width as usize..];
        let inked = below.contains(&INK);
        assert!(height as usize > image_height + 9 * k);
        (row, inked)
    }

    #[test]
    fn pngs_carry_a_colour_bar_with_numbers() {
        let dir = TempDir::new("bar");
        let path = dir.0.join("b.png");
        let data = [0.0, 1.0, 2.0, 3.0];
        // A 2×2 image is widened for the labels; the bar runs over the map.
        write_png_magnitude(&path, &plane(2, 2, &data), 3.0).unwrap();
        let (row, inked) = bar_row(&path, 2);
        let bar: Vec<_> = row.iter().filter(|&&p| p != PAPER).collect();
        let (low, high) = ([0x44, 0x01, 0x54], [0xfd, 0xe7, 0x25]);
        assert_eq!((*bar[0], *bar[bar.len() - 1]), (low, high));
        assert!(bar.len() > 10 && inked);
        write_png_diverging(&path, &plane(2, 2, &data), 3.0).unwrap();
        let (row, inked) = bar_row(&path, 2);
        let bar: Vec<_> = row.iter().filter(|&&p| p != PAPER).collect();
        let (red, blue) = ([0x67, 0x00, 0x1f], [0x05, 0x30, 0x61]);
        assert_eq!((*bar[0], *bar[bar.len() - 1]), (blue, red));
        assert!(inked);
        // A wide image keeps its width: the bar goes under it.
        let wide = vec![1.0; 300 * 2];
        write_png_magnitude(&path, &plane(300, 2, &wide), 1.0).unwrap();
        assert_eq!(decode(&path).0, 300);
    }

    #[test]
    fn the_font_draws_every_character_of_a_scale() {
        for tag in ["-1.23e-2", "+9.87e6", "4.5e0", "no range"] {
            for c in tag.chars().filter(|&c| c != ' ') {
                assert!(glyph(c).iter().any(|&row| row != 0), "{c:?}");
            }
        }
    }

    #[test]
    fn bad_planes_and_paths_name_the_file() {
        let dir = TempDir::new("err");
        let path = dir.0.join("x.png");
        let missing = dir.0.join("no_such_dir").join("x.npy");
        type Writer = fn(&Path, &Plane) -> Result<(), Error>;
        let writers: [Writer; 4] = [
            write_exr,
            write_npy,
            |p, plane| write_png_magnitude(p, plane, 1.0),
            |p, plane| write_png_diverging(p, plane, 1.0),
        ];
        for write in writers {
            for (plane, target, cause) in [
                (plane(4, 3, &DATA[..11]), &path, "4×3 but has 11 values"),
                (plane(0, 3, &[]), &path, "must be ≥ 1"),
                (plane(4, 3, &DATA), &missing, "no_such_dir does not exist"),
                (plane(4, 3, &DATA), &dir.0, "directory"), // "Is a directory"
            ] {
                let Err(Error::Output(m)) = write(target, &plane) else {
                    panic!("{target:?}")
                };
                let named = m.contains(&target.display().to_string());
                assert!(named && m.contains(cause), "{m}");
            }
        }
        assert!(!path.exists());
    }

    #[test]
    fn robust_scale_ignores_the_top_percent() {
        // |x| = 1..=200 with alternating signs: rank ⌈0.99 · 200⌉ = 198, the
        // two largest ignored; non-finite values do not count.
        let mut data: Vec<f64> = (1..=200).map(|i| f64::from(i) * (-1f64).powi(i)).collect();
        data.extend([NAN, INF, -INF]);
        assert_eq!(robust_scale(&data), 198.0);
        // Sparse: 3 non-zero pixels of 1003 → the largest.
        let mut sparse = vec![0.0; 1000];
        sparse.extend([0.5, -2.0, 1.0]);
        assert_eq!(robust_scale(&sparse), 2.0);
        for zero in [&[0.0; 9][..], &[], &[NAN]] {
            assert_eq!(robust_scale(zero), 0.0);
        }
        assert_eq!(robust_scale(&[-3.0]), 3.0);
    }

    #[test]
    fn scale_tags_are_short() {
        let cases = [
            (0.0123, "1.23e-2"),
            (1.0, "1e0"),
            (250.0, "2.5e2"),
            (0.009_999_6, "1e-2"),
            (1e-300, "1e-300"),
            (123_456.0, "1.23e5"),
            (-0.5, "-5e-1"),
            (0.0, "0"),
            (-0.0, "0"),
            (NAN, "nan"),
            (INF, "inf"),
            (-INF, "-inf"),
        ];
        for (scale, tag) in cases {
            assert_eq!(scale_tag(scale), tag, "{scale}");
        }
    }
}
