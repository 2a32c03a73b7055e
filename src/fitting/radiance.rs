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
    let member = Membership::new(&obs.pixels, w);
    let usable = |q: u32| member.contains(q) && water[q as usize] && !photo.clipped[q as usize];
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

/// Which pixels of a `width`-wide image belong to a set: one flag per pixel of the set's
/// bounding box (a streak of a large photo holds millions of pixels, each asked about nine
/// times).
struct Membership {
    x0: u32,
    y0: u32,
    columns: u32,
    rows: u32,
    width: u32,
    flags: Vec<bool>,
}

impl Membership {
    fn new(pixels: &[u32], width: u32) -> Self {
        let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
        for &p in pixels {
            let (x, y) = (p % width, p / width);
            (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
        }
        if pixels.is_empty() || width == 0 {
            return Membership {
                x0: 0,
                y0: 0,
                columns: 0,
                rows: 0,
                width,
                flags: Vec::new(),
            };
        }
        let (columns, rows) = (x1 - x0 + 1, y1 - y0 + 1);
        let mut flags = vec![false; columns as usize * rows as usize];
        for &p in pixels {
            let (x, y) = (p % width - x0, p / width - y0);
            flags[y as usize * columns as usize + x as usize] = true;
        }
        Membership {
            x0,
            y0,
            columns,
            rows,
            width,
            flags,
        }
    }

    fn contains(&self, p: u32) -> bool {
        if self.width == 0 {
            return false;
        }
        let (x, y) = (p % self.width, p / self.width);
        if x < self.x0 || y < self.y0 {
            return false;
        }
        let (x, y) = (x - self.x0, y - self.y0);
        x < self.columns
            && y < self.rows
            && self.flags[y as usize * self.columns as usize + x as usize]
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Rng;

    /// Every pixel of an image, in the set's bounding box or not, is a member exactly when
    /// the set holds it; an empty set holds nothing.
    #[test]
    fn membership_is_the_sets() {
        let (w, h) = (37u32, 23u32);
        let mut rng = Rng::new(3, 0);
        let pixels: Vec<u32> = (0..w * h)
            .filter(|&p| {
                let (x, y) = (p % w, p / w);
                (5..30).contains(&x) && (4..19).contains(&y) && rng.next_f32() < 0.4
            })
            .collect();
        let set: std::collections::HashSet<u32> = pixels.iter().copied().collect();
        let member = Membership::new(&pixels, w);
        for p in 0..w * h + 50 {
            assert_eq!(member.contains(p), set.contains(&p), "pixel {p}");
        }
        let none = Membership::new(&[], w);
        assert!((0..w * h).all(|p| !none.contains(p)));
    }
}
