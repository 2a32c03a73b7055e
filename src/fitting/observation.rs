//! The fitter's input: one streak (or streak fragment) as pixel sets.

pub use crate::streaks::{StreakEdges, StreakSide};

use crate::streaks::edges::streak_edges;

/// One streak of the photo, as the streak extraction hands it to the fitter.
///
/// Pixel indices are `y * width + x` of the photo.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StreakObservation {
    /// Identifier of the streak (reported back in [`super::FittedLight::streak_ids`]).
    pub id: usize,
    /// Every pixel of the streak.
    pub pixels: Vec<u32>,
    /// The brightest pixel of the streak's brightest superpixel: where the light plane is
    /// searched (method §5 step 7).
    pub brightest: u32,
    /// Edge pixels of the streak on each of its sides in the image (method §5 step 6),
    /// indexed by [`StreakSide`].
    pub edges: StreakEdges,
}

impl StreakObservation {
    /// Builds an observation from a streak's pixels: the edge pixels by method §5 step 6
    /// ([`crate::streaks::edges::streak_edges`], as the extraction finds them), and the
    /// brightest pixel by the luminance of `radiance` (the streak extraction picks it per
    /// superpixel instead). The pixels are sorted, so every side lists its pixels in raster
    /// order.
    ///
    /// Returns `None` when `pixels` is empty or holds an index outside the image.
    pub fn from_pixels(
        id: usize,
        mut pixels: Vec<u32>,
        width: u32,
        height: u32,
        radiance: &[[f32; 3]],
    ) -> Option<Self> {
        let n = width as usize * height as usize;
        pixels.sort_unstable();
        pixels.dedup();
        if pixels.is_empty() || pixels.iter().any(|&p| p as usize >= n.min(radiance.len())) {
            return None;
        }
        let mut member = vec![false; n];
        for &p in &pixels {
            member[p as usize] = true;
        }
        let edges = streak_edges(width, height, &pixels, |x, y| {
            member[(y * width + x) as usize]
        });
        let brightest = pixels.iter().copied().max_by(|&a, &b| {
            luminance(radiance[a as usize]).total_cmp(&luminance(radiance[b as usize]))
        })?;
        Some(StreakObservation {
            id,
            pixels,
            brightest,
            edges,
        })
    }
}

/// The pixel at offset (dx, dy) from `p`, or `None` outside the image.
pub fn neighbour(p: u32, dx: i32, dy: i32, width: u32, height: u32) -> Option<u32> {
    let x = (p % width) as i64 + dx as i64;
    let y = (p / width) as i64 + dy as i64;
    if x < 0 || y < 0 || x >= width as i64 || y >= height as i64 {
        None
    } else {
        Some((y as u32) * width + x as u32)
    }
}

/// Rec. 709 luminance of linear RGB.
pub fn luminance(c: [f32; 3]) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}
