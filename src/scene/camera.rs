//! The bounds every camera shares, flatland's line camera and the 3D
//! pinhole alike: its field of view, its image sides, its narrowest pixel.
//! Book: chapter "Three dimensions", section "A camera".

/// Largest image side accepted, in pixels.
pub const MAX_SIDE: u32 = 8192;

/// Why a camera's field of view (`fov_deg`, described as `what`) or image
/// sides (`(name, pixels)`, the horizontal first) cannot be, if they
/// cannot: a field of view outside `(0, 170]` degrees, a side outside
/// `1..=MAX_SIDE`, a pixel narrower than [`MIN_PIXEL`]. Flatland's line
/// camera and the 3D camera share these bounds.
pub fn view_problem(fov_deg: f64, what: &str, sides: &[(&str, u32)]) -> Option<String> {
    if !(fov_deg > 0.0 && fov_deg <= 170.0) {
        return Some(format!(
            "camera fov_deg = {}: expected {what} in (0, 170]",
            crate::error::Num(fov_deg)
        ));
    }
    if let Some(why) = sides.iter().find_map(|&(name, n)| {
        (n == 0 || n > MAX_SIDE)
            .then(|| format!("camera {name} = {n}: expected 1 to {MAX_SIDE} pixels"))
    }) {
        return Some(why);
    }
    // A pixel's directions are the view axis plus a tangent offset: below
    // ~10⁻¹⁵ they all round to the axis (a random scene's fov of 10⁻¹⁶°
    // read I 37σ low and cube_x 0.85 where −6·10¹⁶ was due, both
    // "reliable"; 10⁻¹³° was already 30 % off).
    let pixel = 2.0 * (0.5 * fov_deg.to_radians()).tan() / f64::from(sides.first()?.1);
    (pixel < MIN_PIXEL).then(|| {
        format!(
            "camera fov_deg = {} over {} pixels: a pixel spans {} rad, below {MIN_PIXEL:e}, \
             where its directions round to one another; widen the field of view",
            crate::error::Num(fov_deg),
            sides[0].1,
            crate::error::Num(pixel)
        )
    })
}

/// Narrowest pixel accepted, in radians (tangent units at the axis): 10⁶
/// ulps of the unit view axis, so a pixel's directions stay distinct.
pub const MIN_PIXEL: f64 = 1e-10;
