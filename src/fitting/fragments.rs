//! Fragments of one light (method §5 step 5): waves can break one light's streak into several
//! pieces. Pieces whose lights land on the same face and overlap are one light: their pixels are
//! merged and the union is fitted again.

use super::observation::{luminance, StreakObservation};
use super::FittedLight;
use crate::photo_in::Photo;

/// The first pair (i, j), i < j, of lights on the same face whose rectangles overlap.
pub fn overlapping_pair(lights: &[FittedLight]) -> Option<(usize, usize)> {
    for i in 0..lights.len() {
        for j in i + 1..lights.len() {
            let (a, b) = (&lights[i], &lights[j]);
            if a.plane.same_face(&b.plane) && overlaps_in_plane(a, b) {
                return Some((i, j));
            }
        }
    }
    None
}

/// Overlap of two rectangles on the same face, whose frames may have different origins.
fn overlaps_in_plane(a: &FittedLight, b: &FittedLight) -> bool {
    let shift = a.plane.coords(b.plane.point);
    let rb = super::rect::Rect {
        u_min: b.u_min + shift.x,
        u_max: b.u_max + shift.x,
        v_min: b.v_min + shift.y,
        v_max: b.v_max + shift.y,
    };
    a.rect().overlaps(&rb)
}

/// The union of two streaks' pixels as one observation: edges recomputed for the union (an edge
/// pixel of one piece can be inside the other), brightest pixel the brighter of the two.
pub fn merge(
    a: &StreakObservation,
    b: &StreakObservation,
    photo: &Photo,
) -> Option<StreakObservation> {
    let pixels: Vec<u32> = a.pixels.iter().chain(&b.pixels).copied().collect();
    let mut merged = StreakObservation::from_pixels(
        a.id.min(b.id),
        pixels,
        photo.width,
        photo.height,
        &photo.radiance,
    )?;
    let lum = |p: u32| {
        photo
            .radiance
            .get(p as usize)
            .map_or(0.0, |&c| luminance(c))
    };
    merged.brightest = if lum(a.brightest) >= lum(b.brightest) {
        a.brightest
    } else {
        b.brightest
    };
    Some(merged)
}
