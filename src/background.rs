//! The night's smooth background (method §5, the background term): a dim sky reflected in
//! the water, facades lit by it and their reflections. None of it comes from the lights the
//! fit looks for, and all of it varies slowly across the photo, where the lights' streaks
//! and direct images are sharp.
//!
//! It is measured where no light reaches: the photo is cut into cells, and in each cell the
//! pixels away from every streak and every bright pixel give a per-channel median, the water
//! and the rest of the photo apart (the horizon is an edge of the background, not a slope of
//! it). Cells the lights cover are interpolated along their row from the measured ones, and
//! each pixel reads its region's cells bilinearly. The median ignores what little of a streak's faint
//! tail is left in a cell, so a black night measures black.

use rayon::prelude::*;

use crate::fitting::FittedLight;
use crate::photo_in::Photo;
use crate::scene_in::Scene;
use crate::streaks::Segmentation;

/// A smooth background, in radiance per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Background {
    /// Width of the photo.
    pub width: u32,
    /// Height of the photo.
    pub height: u32,
    /// Linear radiance per pixel, row 0 at the top.
    pub pixels: Vec<[f32; 3]>,
    /// Mean over the water's pixels.
    pub water_mean: [f32; 3],
    /// The background's share of the light of the streaks' pixels (luminance, 0 to 1).
    pub streak_share: f32,
    /// Cells measured (on the water and off it), out of all cells with pixels of a region.
    pub cells_measured: usize,
    /// Cells of either region in the photo.
    pub cells: usize,
}

impl Background {
    /// Gives back to each light seen in the photo (`seen`) the radiance of the wall it hides.
    /// The background taken off the photo holds the wall's reflection everywhere, also
    /// where the light stands in front of it, so the lights were fitted to their radiance
    /// less the wall's; the wall's is read where the light's centre appears (off the water,
    /// where the background there was bridged over the light's own image).
    pub fn restore_walls(
        &self,
        scene: &Scene,
        water: &[bool],
        lights: &mut [FittedLight],
        seen: &[bool],
    ) {
        for (light, _) in lights.iter_mut().zip(seen).filter(|(_, &s)| s) {
            let centre = light.plane.point_at(
                0.5 * (light.u_min + light.u_max),
                0.5 * (light.v_min + light.v_max),
            );
            let Some((x, y)) = scene.camera.project(centre, self.width, self.height) else {
                continue;
            };
            if !(x >= 0.0 && y >= 0.0 && x < self.width as f32 && y < self.height as f32) {
                continue;
            }
            let i = y as usize * self.width as usize + x as usize;
            if water.get(i) == Some(&false) {
                for c in 0..3 {
                    light.radiance[c] += self.pixels[i][c];
                }
            }
        }
    }

    /// Whether the background is black wherever it was measured.
    pub fn is_black(&self) -> bool {
        self.pixels.iter().all(|p| p.iter().all(|&c| c <= 0.0))
    }
}

/// Pixels a streak or a bright pixel keeps from the measure, around it: the lobe's halo and
/// the pixel filter spread a light's image by a few pixels.
fn margin(width: u32, height: u32) -> usize {
    (width.min(height) as usize / 60).max(4)
}

/// Side of a measuring cell in pixels: small enough to follow the background's slope away
/// from the horizon, large enough for a median over hundreds of pixels.
fn cell_side(width: u32, height: u32) -> usize {
    (width.min(height) as usize / 30).max(8)
}

/// A pixel brighter than this many times the background's level at it (at first, the median
/// pixel of its region away from the streaks) is a light's, not the background.
const BRIGHT: f32 = 2.5;

/// Luminance of linear RGB (Rec. 709).
fn luminance(p: [f32; 3]) -> f32 {
    0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]
}

/// Estimates the background of `photo` whose water covers `water`, with the lights' streaks
/// at `streak_pixels` (indices y * width + x).
pub fn estimate(photo: &Photo, water: &[bool], streak_pixels: &[u32]) -> Background {
    let (w, h) = (photo.width as usize, photo.height as usize);
    let mut streak = vec![false; w * h];
    for &i in streak_pixels {
        if let Some(s) = streak.get_mut(i as usize) {
            *s = true;
        }
    }
    // Bright: well above the typical pixel of its region away from the streaks (a lamp on
    // a lit facade, a glint outside the segmented streaks). On a black night the typical
    // pixel is black and every lit pixel is bright.
    let typical = [true, false].map(|on_water| {
        let mut levels: Vec<f32> = (0..w * h)
            .filter(|&i| water[i] == on_water && !streak[i])
            .map(|i| luminance(photo.radiance[i]))
            .collect();
        if levels.is_empty() {
            return 0.0;
        }
        let mid = levels.len() / 2;
        *levels.select_nth_unstable_by(mid, f32::total_cmp).1
    });
    // A first measure against the regions' typical levels, then a second against the
    // first's smooth level at each pixel: the background may brighten tenfold from the near
    // water to the horizon (the Fresnel factor), which one level per region would call
    // bright.
    let first = measure(photo, water, &streak, |i| typical[usize::from(!water[i])]);
    // A black night: the first measure is black, and so are both regions' typical pixels, so
    // the second would compare against the same level (none) everywhere and measure the same.
    let black = typical == [0.0; 2] && first.0.iter().all(|p| p.iter().all(|&c| c <= 0.0));
    let (pixels, cells_measured, cells) = if black {
        first
    } else {
        measure(photo, water, &streak, |i| luminance(first.0[i]))
    };
    let water_count = water.iter().filter(|&&b| b).count().max(1);
    let mut water_mean = [0f64; 3];
    for (p, _) in pixels.iter().zip(water).filter(|(_, &on)| on) {
        for c in 0..3 {
            water_mean[c] += p[c] as f64;
        }
    }
    let (mut under, mut total) = (0f64, 0f64);
    for &i in streak_pixels {
        if let (Some(b), Some(p)) = (pixels.get(i as usize), photo.radiance.get(i as usize)) {
            under += luminance(*b) as f64;
            total += luminance(*p) as f64;
        }
    }
    Background {
        width: photo.width,
        height: photo.height,
        streak_share: if total > 0.0 {
            (under / total).min(1.0) as f32
        } else {
            0.0
        },
        pixels,
        water_mean: water_mean.map(|s| (s / water_count as f64) as f32),
        cells_measured,
        cells,
    }
}

/// The smooth background measured away from the `streak` pixels and from every pixel
/// brighter than [`BRIGHT`] times `level` at it; with the cells measured, and all cells.
fn measure(
    photo: &Photo,
    water: &[bool],
    streak: &[bool],
    level: impl Fn(usize) -> f32 + Sync,
) -> (Vec<[f32; 3]>, usize, usize) {
    let (w, h) = (photo.width as usize, photo.height as usize);
    let lit: Vec<bool> = (0..w * h)
        .into_par_iter()
        .map(|i| streak[i] || photo.clipped[i] || luminance(photo.radiance[i]) > BRIGHT * level(i))
        .collect();
    let excluded = dilate(&lit, w, h, margin(photo.width, photo.height));
    let side = cell_side(photo.width, photo.height);
    let (cw, ch) = (w.div_ceil(side), h.div_ceil(side));
    // Region 0 is the water, 1 the rest.
    let mut grids = [CellGrid::new(cw, ch), CellGrid::new(cw, ch)];
    // Per cell (row by row) and region: whether it holds any of the region's pixels, and
    // its median when enough of them are kept.
    let measured: Vec<[(bool, Option<[f32; 3]>); 2]> = (0..cw * ch)
        .into_par_iter()
        .map(|cell| {
            let (cx, cy) = (cell % cw, cell / cw);
            [true, false].map(|on_water| {
                let mut total = 0usize;
                let mut kept: Vec<[f32; 3]> = Vec::new();
                for y in cy * side..((cy + 1) * side).min(h) {
                    for x in cx * side..((cx + 1) * side).min(w) {
                        let i = y * w + x;
                        if water[i] != on_water {
                            continue;
                        }
                        total += 1;
                        if !excluded[i] {
                            kept.push(photo.radiance[i]);
                        }
                    }
                }
                let value =
                    (kept.len() >= 16 && 2 * kept.len() >= total).then(|| median(&mut kept));
                (total > 0, value)
            })
        })
        .collect();
    let mut cells = 0;
    for (cell, regions) in measured.into_iter().enumerate() {
        for (grid, (present, value)) in grids.iter_mut().zip(regions) {
            if present {
                cells += 1;
                grid.present[cell] = true;
                grid.value[cell] = value;
            }
        }
    }
    let cells_measured = grids
        .iter()
        .map(|g| g.value.iter().filter(|v| v.is_some()).count())
        .sum();
    for grid in &mut grids {
        grid.fill();
    }
    let pixels = (0..w * h)
        .into_par_iter()
        .map(|i| grids[usize::from(!water[i])].at((i % w) as f32, (i / w) as f32, side as f32))
        .collect();
    (pixels, cells_measured, cells)
}

/// The background of `photo` measured away from the streaks of `segmentation`, with the photo
/// less it; `None` for a black night, or when no streak was found (nothing to fit on it).
pub fn take_off(
    photo: &Photo,
    water: &[bool],
    segmentation: &Segmentation,
) -> Option<(Background, Photo)> {
    if segmentation.streaks.is_empty() {
        return None;
    }
    let pixels: Vec<u32> = segmentation
        .streaks
        .iter()
        .flat_map(|s| s.pixels.iter().copied())
        .collect();
    let background = estimate(photo, water, &pixels);
    if background.is_black() {
        return None;
    }
    let less = photo.less(&background.pixels);
    Some((background, less))
}

/// Per-channel median (the upper one for an even count).
fn median(values: &mut [[f32; 3]]) -> [f32; 3] {
    let mid = values.len() / 2;
    let mut out = [0.0; 3];
    for (c, o) in out.iter_mut().enumerate() {
        let mut channel: Vec<f32> = values.iter().map(|p| p[c]).collect();
        channel.select_nth_unstable_by(mid, f32::total_cmp);
        *o = channel[mid].max(0.0);
    }
    out
}

/// `mask` grown by `r` pixels in each direction (a square), by prefix sums along the rows
/// and then the columns.
fn dilate(mask: &[bool], w: usize, h: usize, r: usize) -> Vec<bool> {
    // One line (a row, or a column as `len` values `stride` apart from `first`) of `src`,
    // grown along itself.
    let line = |src: &[bool], first: usize, stride: usize, len: usize| -> Vec<bool> {
        let mut prefix = vec![0u32; len + 1];
        for k in 0..len {
            prefix[k + 1] = prefix[k] + src[first + k * stride] as u32;
        }
        (0..len)
            .map(|k| prefix[(k + r + 1).min(len)] > prefix[k.saturating_sub(r)])
            .collect()
    };
    let rows: Vec<bool> = (0..h)
        .into_par_iter()
        .flat_map_iter(|y| line(mask, y * w, 1, w))
        .collect();
    let columns: Vec<Vec<bool>> = (0..w)
        .into_par_iter()
        .map(|x| line(&rows, x, w, h))
        .collect();
    let mut out = vec![false; w * h];
    for (x, column) in columns.iter().enumerate() {
        for (y, &v) in column.iter().enumerate() {
            out[y * w + x] = v;
        }
    }
    out
}

/// One region's cells: which hold its pixels, and their measured or filled values.
struct CellGrid {
    cw: usize,
    ch: usize,
    present: Vec<bool>,
    value: Vec<Option<[f32; 3]>>,
}

impl CellGrid {
    fn new(cw: usize, ch: usize) -> Self {
        CellGrid {
            cw,
            ch,
            present: vec![false; cw * ch],
            value: vec![None; cw * ch],
        }
    }

    /// Gives every cell without a value one: along its row first, linearly between the
    /// nearest measured cells on either side (or the one side's), since the background on
    /// the water varies mostly with the view's angle to it, that is down the rows (the
    /// Fresnel factor); then, in rows with no measured cell, the mean of its valued
    /// neighbours (8-connected), ring by ring; black when nothing was measured.
    fn fill(&mut self) {
        if self.value.iter().all(Option::is_none) {
            self.value.iter_mut().for_each(|v| *v = Some([0.0; 3]));
            return;
        }
        for cy in 0..self.ch {
            let row: Vec<Option<[f32; 3]>> = self.value[cy * self.cw..(cy + 1) * self.cw].to_vec();
            for cx in 0..self.cw {
                if row[cx].is_some() {
                    continue;
                }
                let left = (0..cx).rev().find_map(|x| row[x].map(|v| (x, v)));
                let right = (cx + 1..self.cw).find_map(|x| row[x].map(|v| (x, v)));
                self.value[cy * self.cw + cx] = match (left, right) {
                    (Some((xl, vl)), Some((xr, vr))) => {
                        let t = (cx - xl) as f32 / (xr - xl) as f32;
                        Some([0, 1, 2].map(|c| vl[c] + (vr[c] - vl[c]) * t))
                    }
                    (Some((_, v)), None) | (None, Some((_, v))) => Some(v),
                    (None, None) => None,
                };
            }
        }
        while self.value.iter().any(Option::is_none) {
            let mut next = self.value.clone();
            for cy in 0..self.ch {
                for cx in 0..self.cw {
                    if self.value[cy * self.cw + cx].is_some() {
                        continue;
                    }
                    let (mut sum, mut n) = ([0f32; 3], 0);
                    for (nx, ny) in neighbours(cx, cy, self.cw, self.ch) {
                        if let Some(v) = self.value[ny * self.cw + nx] {
                            (0..3).for_each(|c| sum[c] += v[c]);
                            n += 1;
                        }
                    }
                    if n > 0 {
                        next[cy * self.cw + cx] = Some(sum.map(|s| s / n as f32));
                    }
                }
            }
            self.value = next;
        }
    }

    /// The value at pixel (`x`, `y`), bilinear between the centres of cells of side `side`;
    /// cells without the region's pixels are skipped by weighting only those that have them.
    fn at(&self, x: f32, y: f32, side: f32) -> [f32; 3] {
        let fx = ((x + 0.5) / side - 0.5).clamp(0.0, (self.cw - 1) as f32);
        let fy = ((y + 0.5) / side - 0.5).clamp(0.0, (self.ch - 1) as f32);
        let (x0, y0) = (fx as usize, fy as usize);
        let (x1, y1) = ((x0 + 1).min(self.cw - 1), (y0 + 1).min(self.ch - 1));
        let (tx, ty) = (fx - x0 as f32, fy - y0 as f32);
        let mut sum = [0f32; 3];
        let mut weight = 0.0;
        for (cx, cy, wgt) in [
            (x0, y0, (1.0 - tx) * (1.0 - ty)),
            (x1, y0, tx * (1.0 - ty)),
            (x0, y1, (1.0 - tx) * ty),
            (x1, y1, tx * ty),
        ] {
            let k = cy * self.cw + cx;
            if !self.present[k] || wgt <= 0.0 {
                continue;
            }
            if let Some(v) = self.value[k] {
                (0..3).for_each(|c| sum[c] += v[c] * wgt);
                weight += wgt;
            }
        }
        if weight > 0.0 {
            sum.map(|s| s / weight)
        } else {
            let k = y0 * self.cw + x0;
            self.value[k].unwrap_or([0.0; 3])
        }
    }
}

/// The in-grid 8-neighbours of cell (`x`, `y`).
fn neighbours(x: usize, y: usize, cw: usize, ch: usize) -> impl Iterator<Item = (usize, usize)> {
    (-1i64..=1)
        .flat_map(move |dy| (-1i64..=1).map(move |dx| (dx, dy)))
        .filter(|&d| d != (0, 0))
        .map(move |(dx, dy)| (x as i64 + dx, y as i64 + dy))
        .filter(move |&(nx, ny)| nx >= 0 && ny >= 0 && (nx as usize) < cw && (ny as usize) < ch)
        .map(|(nx, ny)| (nx as usize, ny as usize))
}
