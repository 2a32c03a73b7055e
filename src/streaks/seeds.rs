//! Step 4 of method §5 (the paper's §3.2.1): seed points and seed superpixels.
//!
//! The photo is blurred, its HSV value V = max(R, G, B) taken (sRGB-encoded, as a person sees
//! it), and every k-th row is mean-filtered and searched for peaks; a peak above t on the water
//! is a seed point.
//!
//! The paper's dropping rule, "a seed whose V is below both its superpixel's mean V and t is
//! dropped", cannot fire if V means the filtered peak (which is above t by construction). We
//! read V as the blurred, unfiltered value at the seed pixel: the row filter can lift a dim
//! pixel next to a narrow glint above t, and such a seed is dropped when the pixel itself is
//! dimmer than both t and its superpixel.

use rayon::prelude::*;

use crate::{Error, Result};

/// Settings of the seed search.
#[derive(Clone, Debug, PartialEq)]
pub struct SeedParams {
    /// k: search every k-th row (starting from row k/2).
    pub row_step: usize,
    /// t: a peak's mean-filtered V (sRGB-encoded, in [0, 1]) must exceed this.
    pub threshold: f32,
    /// Standard deviation, in pixels, of the Gaussian blur applied first (0: no blur).
    pub blur_sigma: f32,
    /// Width in pixels of the mean filter along a row (odd; 1: no filter).
    pub row_filter: usize,
}

impl Default for SeedParams {
    fn default() -> Self {
        SeedParams {
            row_step: 8,
            threshold: 0.35,
            blur_sigma: 1.5,
            row_filter: 9,
        }
    }
}

impl SeedParams {
    /// Refuses settings that make no sense, naming the option.
    pub fn validate(&self) -> Result<()> {
        if self.row_step == 0 {
            return Err(Error::Usage(
                "the seed row step k must be at least 1".into(),
            ));
        }
        if !(self.threshold.is_finite() && (0.0..1.0).contains(&self.threshold)) {
            return Err(Error::Usage(format!(
                "the seed threshold t must be in [0, 1), not {}",
                self.threshold
            )));
        }
        if !(self.blur_sigma.is_finite() && (0.0..=50.0).contains(&self.blur_sigma)) {
            return Err(Error::Usage(format!(
                "the seed blur sigma must be in [0, 50] pixels, not {}",
                self.blur_sigma
            )));
        }
        if self.row_filter == 0 || self.row_filter.is_multiple_of(2) {
            return Err(Error::Usage(format!(
                "the row mean filter width must be odd, not {}",
                self.row_filter
            )));
        }
        Ok(())
    }
}

/// A seed point: a peak of a filtered row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeedPoint {
    /// Column.
    pub x: u32,
    /// Row.
    pub y: u32,
    /// The mean-filtered V of the row at the peak.
    pub value: f32,
}

/// The blurred V plane of the photo: max(R, G, B) of the Gaussian-blurred sRGB colours.
pub fn value_plane(width: u32, height: u32, display: &[[f32; 3]], sigma: f32) -> Vec<f32> {
    if sigma <= 0.0 {
        return display
            .par_iter()
            .map(|p| p[0].max(p[1]).max(p[2]).clamp(0.0, 1.0))
            .collect();
    }
    // The blur is applied to R, G and B before V is taken, as the paper blurs the RGB image;
    // blurring each channel separately keeps a red and a green neighbour from averaging to a
    // bright yellow.
    let mut channels: Vec<Vec<f32>> = (0..3)
        .map(|c| display.par_iter().map(|p| p[c].clamp(0.0, 1.0)).collect())
        .collect();
    for ch in &mut channels {
        gaussian_blur(ch, width as usize, height as usize, sigma);
    }
    let [r, g, b] = [&channels[0], &channels[1], &channels[2]];
    (0..display.len())
        .into_par_iter()
        .map(|i| r[i].max(g[i]).max(b[i]))
        .collect()
}

/// A separable Gaussian blur with clamped borders, in place. Each pixel's sum is taken over
/// the kernel's taps in order, from zero; a row at a time, each tap added to the whole row
/// (which the processor does several pixels at once), in parallel over rows.
fn gaussian_blur(plane: &mut [f32], w: usize, h: usize, sigma: f32) {
    if w == 0 || h == 0 {
        return;
    }
    let radius = (3.0 * sigma).ceil() as usize;
    let mut kernel: Vec<f32> = (0..=2 * radius)
        .map(|j| {
            let d = j as i64 - radius as i64;
            (-(d * d) as f32 / (2.0 * sigma * sigma)).exp()
        })
        .collect();
    let total: f32 = kernel.iter().sum();
    kernel.iter_mut().for_each(|k| *k /= total);
    let clamped = |i: i64, n: usize| i.clamp(0, n as i64 - 1) as usize;
    // Along the rows, each row read from a copy padded with its end pixels.
    let mut tmp = vec![0.0f32; plane.len()];
    tmp.par_chunks_mut(w).enumerate().for_each_init(
        || vec![0.0f32; w + 2 * radius],
        |padded, (y, out)| {
            let row = &plane[y * w..(y + 1) * w];
            for (i, p) in padded.iter_mut().enumerate() {
                *p = row[clamped(i as i64 - radius as i64, w)];
            }
            out.fill(0.0);
            for (j, &k) in kernel.iter().enumerate() {
                for (o, &v) in out.iter_mut().zip(&padded[j..j + w]) {
                    *o += k * v;
                }
            }
        },
    );
    // Along the columns: each tap a whole row of the first pass.
    plane.par_chunks_mut(w).enumerate().for_each(|(y, out)| {
        out.fill(0.0);
        for (j, &k) in kernel.iter().enumerate() {
            let yy = clamped(y as i64 + j as i64 - radius as i64, h);
            for (o, &v) in out.iter_mut().zip(&tmp[yy * w..(yy + 1) * w]) {
                *o += k * v;
            }
        }
    });
}

/// Finds the seed points: on every k-th row, the peaks of the mean-filtered V over the water
/// pixels whose value exceeds t. A flat-topped peak (a clipped core) gives its middle pixel.
pub fn seed_points(
    width: u32,
    height: u32,
    value: &[f32],
    water: &[bool],
    params: &SeedParams,
) -> Vec<SeedPoint> {
    let (w, h) = (width as usize, height as usize);
    let half = params.row_filter / 2;
    let mut points = Vec::new();
    let mut filtered = vec![f32::NEG_INFINITY; w];
    let mut y = params.row_step / 2;
    while y < h {
        let row = &value[y * w..(y + 1) * w];
        let row_water = &water[y * w..(y + 1) * w];
        // Mean over the water pixels of the window; off the water the row does not exist.
        for x in 0..w {
            filtered[x] = if row_water[x] {
                let (lo, hi) = (x.saturating_sub(half), (x + half + 1).min(w));
                let (mut s, mut n) = (0.0f32, 0u32);
                for j in lo..hi {
                    if row_water[j] {
                        s += row[j];
                        n += 1;
                    }
                }
                s / n as f32
            } else {
                f32::NEG_INFINITY
            };
        }
        let mut x = 0;
        while x < w {
            // A run of equal values is one candidate peak.
            let mut end = x + 1;
            while end < w && filtered[end] == filtered[x] {
                end += 1;
            }
            let v = filtered[x];
            let left = if x > 0 {
                filtered[x - 1]
            } else {
                f32::NEG_INFINITY
            };
            let right = if end < w {
                filtered[end]
            } else {
                f32::NEG_INFINITY
            };
            if v > params.threshold && v > left && v > right {
                points.push(SeedPoint {
                    x: ((x + end - 1) / 2) as u32,
                    y: y as u32,
                    value: v,
                });
            }
            x = end;
        }
        y += params.row_step;
    }
    points
}

/// Applies the paper's dropping rule and returns the kept seed points and the seed
/// superpixels (each once, in the order of their first seed). `takes_part` says which
/// superpixels are water superpixels.
pub fn seed_superpixels(
    points: &[SeedPoint],
    width: u32,
    labels: &[u32],
    value: &[f32],
    superpixel_mean_value: &[f32],
    takes_part: &[bool],
    threshold: f32,
) -> (Vec<SeedPoint>, Vec<u32>) {
    let mut kept = Vec::new();
    let mut superpixels = Vec::new();
    let mut seen = vec![false; superpixel_mean_value.len()];
    for p in points {
        let i = p.y as usize * width as usize + p.x as usize;
        let s = labels[i] as usize;
        let v = value[i];
        if (v < superpixel_mean_value[s] && v < threshold) || !takes_part[s] {
            continue;
        }
        kept.push(*p);
        if !seen[s] {
            seen[s] = true;
            superpixels.push(s as u32);
        }
    }
    (kept, superpixels)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn peaks_above_threshold_on_water_only() {
        // One row: a bump at 2 (0.8), a flat top over 6..=8 (0.9), a bump off the water at 11.
        let row = [
            0.1, 0.3, 0.8, 0.3, 0.1, 0.5, 0.9, 0.9, 0.9, 0.2, 0.1, 0.9, 0.1,
        ];
        let water: Vec<bool> = (0..row.len()).map(|x| x != 11).collect();
        let params = SeedParams {
            row_step: 1,
            threshold: 0.35,
            blur_sigma: 0.0,
            row_filter: 1,
        };
        let pts = seed_points(row.len() as u32, 1, &row, &water, &params);
        let xs: Vec<u32> = pts.iter().map(|p| p.x).collect();
        assert_eq!(xs, vec![2, 7]);
    }

    /// Each pixel of the blur is the clamped-border convolution summed pixel by pixel, tap by
    /// tap in order, to the bit: on images wider than tall, taller than wide and narrower
    /// than the kernel.
    #[test]
    fn blur_is_the_per_pixel_convolution_to_the_bit() {
        let reference = |plane: &[f32], w: usize, h: usize, sigma: f32| {
            let radius = (3.0 * sigma).ceil() as i64;
            let mut kernel: Vec<f32> = (-radius..=radius)
                .map(|d| (-(d * d) as f32 / (2.0 * sigma * sigma)).exp())
                .collect();
            let total: f32 = kernel.iter().sum();
            kernel.iter_mut().for_each(|k| *k /= total);
            let at = |i: i64, n: usize| i.clamp(0, n as i64 - 1) as usize;
            let mut tmp = vec![0.0f32; plane.len()];
            for y in 0..h {
                for x in 0..w {
                    let mut s = 0.0;
                    for (j, k) in kernel.iter().enumerate() {
                        s += k * plane[y * w + at(x as i64 + j as i64 - radius, w)];
                    }
                    tmp[y * w + x] = s;
                }
            }
            let mut out = vec![0.0f32; plane.len()];
            for y in 0..h {
                for x in 0..w {
                    let mut s = 0.0;
                    for (j, k) in kernel.iter().enumerate() {
                        s += k * tmp[at(y as i64 + j as i64 - radius, h) * w + x];
                    }
                    out[y * w + x] = s;
                }
            }
            out
        };
        let mut rng = crate::random::Rng::new(5, 0);
        for (w, h, sigma) in [(41, 17, 1.5f32), (9, 30, 2.0), (5, 4, 3.0)] {
            let plane: Vec<f32> = (0..w * h).map(|_| rng.next_f32()).collect();
            let mut got = plane.clone();
            gaussian_blur(&mut got, w, h, sigma);
            let want = reference(&plane, w, h, sigma);
            for (i, (g, r)) in got.iter().zip(&want).enumerate() {
                assert_eq!(
                    g.to_bits(),
                    r.to_bits(),
                    "{w} x {h}, sigma {sigma}: pixel {i}"
                );
            }
        }
    }

    #[test]
    fn blur_keeps_a_constant_image_and_spreads_a_dot() {
        let mut plane = vec![0.5f32; 25];
        gaussian_blur(&mut plane, 5, 5, 1.0);
        assert!(plane.iter().all(|v| (v - 0.5).abs() < 1e-6));
        let mut dot = vec![0.0f32; 25];
        dot[12] = 1.0;
        gaussian_blur(&mut dot, 5, 5, 1.0);
        // Weight of the centre of a normalised 7-tap Gaussian of sigma 1, squared.
        let g: f32 = (-3i32..=3).map(|d| (-(d * d) as f32 / 2.0).exp()).sum();
        assert!((dot[12] - 1.0 / (g * g)).abs() < 1e-6);
        assert!(dot[11] > 0.0 && dot[11] < dot[12]);
    }
}
