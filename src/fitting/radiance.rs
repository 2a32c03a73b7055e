//! method §5 step 8 (paper §4.2, eq. 7): the light's radiance, per RGB channel, from the
//! streak's brightest pixels.
//!
//! The paper divides the brightest pixel by its coefficient with the whole plane lit. When
//! the lobe is wider than the light (e = 500 spreads a pixel's rays over about a metre at ten
//! metres) that coefficient counts rays that miss the light, and L comes out low. Here the
//! whole-plane estimate only starts the fit; once a rectangle is known, L is the least-squares
//! fit of `I(p) = L c(p; rect)` over the brightest interior pixels, per channel, so a channel
//! the light does not emit comes out at zero.

use super::footprint::Footprint;
use super::observation::{luminance, neighbour, StreakObservation};

use super::rect::Rect;
use crate::photo_in::Photo;

/// How many of the brightest pixels estimate the radiance: enough to average out the photo's
/// noise (a few percent per pixel at 256 spp), few enough to stay where the streak is bright.
pub const RADIANCE_PIXELS: usize = 32;

/// Centres of the brightest 3 x 3 boxes of the streak (at most `count`), each to be fitted by
/// its box mean ([`Footprint::observed`] with radius 1). A box qualifies when its nine pixels
/// belong to the streak, are water and are unclipped.
///
/// Boxes are ranked by the mean of the 16 pixels around them (the 5 x 5 ring outside the box),
/// never by their own values: the photo's noise is independent from pixel to pixel, so the
/// values fitted are not the ones selected on. Ranking by the fitted values themselves picks
/// pixels whose noise happens to be high and biased L up by 3 % on the Table 1 sample.
pub fn bright_pixels(
    obs: &StreakObservation,
    photo: &Photo,
    water: &[bool],
    count: usize,
) -> Vec<u32> {
    let (w, h) = (photo.width, photo.height);
    let mut member = std::collections::HashSet::with_capacity(obs.pixels.len());
    member.extend(obs.pixels.iter().copied());
    let usable = |q: u32| member.contains(&q) && water[q as usize] && !photo.clipped[q as usize];
    let box_ok = |p: u32| {
        (-1..=1).all(|dy| (-1..=1).all(|dx| neighbour(p, dx, dy, w, h).is_some_and(usable)))
    };
    let ring_mean = |p: u32| {
        let mut sum = 0.0;
        let mut n = 0;
        for dy in -2i32..=2 {
            for dx in -2i32..=2 {
                if dx.abs() == 2 || dy.abs() == 2 {
                    if let Some(q) = neighbour(p, dx, dy, w, h) {
                        sum += luminance(photo.radiance[q as usize]);
                        n += 1;
                    }
                }
            }
        }
        sum / n.max(1) as f32
    };
    let mut scored: Vec<(f32, u32)> = obs
        .pixels
        .iter()
        .copied()
        .filter(|&p| box_ok(p))
        .map(|p| (ring_mean(p), p))
        .collect();
    scored.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    scored.truncate(count);
    scored.into_iter().map(|s| s.1).collect()
}

/// Least-squares radiance per channel, `L_c = sum I_c c / sum c^2`, over `footprints` with the
/// light covering `rect` (the whole plane when `None`). `None` when no pixel sees the light.
pub fn fit_radiance(
    photo: &Photo,
    footprints: &[&Footprint],
    rect: Option<&Rect>,
) -> Option<[f32; 3]> {
    let mut num = [0f64; 3];
    let mut den = 0f64;
    for fp in footprints {
        let c = match rect {
            Some(r) => fp.coefficient(r),
            None => fp.whole_plane(),
        } as f64;
        let i = fp.observed(photo);
        for k in 0..3 {
            num[k] += i[k] as f64 * c;
        }
        den += c * c;
    }
    if den <= 0.0 {
        return None;
    }
    Some(num.map(|n| (n / den).max(0.0) as f32))
}

/// The scalar coefficient a pixel shows for a light of colour `radiance`: the least-squares
/// `k` in `I = k L` over the three channels, so every channel the light emits counts and a
/// channel it does not emit is ignored.
pub fn observed_coefficient(pixel: [f32; 3], radiance: [f32; 3]) -> Option<f32> {
    let ll: f32 = radiance.iter().map(|c| c * c).sum();
    if ll <= 0.0 {
        return None;
    }
    let il: f32 = pixel.iter().zip(&radiance).map(|(i, l)| i * l).sum();
    Some(il / ll)
}
