//! Step 3 of method §5: SLIC superpixels (Achanta et al. 2012), written here rather than
//! taken from a crate (method §9: the Rust crates are buggy or unmaintained).
//!
//! We follow EPFL's reference code (SLIC.cpp, `PerformSLICO_ForGivenK` without the SLICO
//! adaptive compactness, i.e. the original `PerformSuperpixelSLIC`):
//! - colour in CIELAB (D65) from the sRGB-encoded photo, without stretching its range (unlike
//!   scikit-image, which rescales the image to [0, 1] first, so that the compactness means the
//!   same thing whatever the photo's exposure);
//! - seeds on a regular grid of step S = sqrt(N/K), spread evenly over the leftover pixels as
//!   EPFL does, each moved to the lowest Lab gradient in its 3x3 neighbourhood, and starting
//!   with the colour under it (scikit-image starts every centre at colour zero);
//! - a 2S x 2S search window around every centre (scikit-image: 4S x 4S), 1.5 S when S < 10;
//! - distance d_lab^2 + (m/S)^2 d_xy^2 with compactness m, 10 iterations;
//! - connectivity enforcement as EPFL's `EnforceLabelConnectivity`: 4-connected pieces in raster
//!   order, a piece of at most N/K/4 pixels joins the label of the piece it touches first.
//!
//! Departures from EPFL: a centre that loses all its pixels stays where it was (EPFL moves it
//! to (0, 0) with colour zero, a division guard that became behaviour); centre sums are taken in
//! fixed point (Lab x 256, integers) so that the result is the same bytes whatever the thread
//! count (method §2, determinism).
//!
//! Parallelism: the image is split into bands of rows (assign.rs); each band visits the centres
//! whose window touches it in index order, so every pixel sees the same sequence of comparisons
//! as in the sequential algorithm, and then sums its pixels for the update, as integers, while
//! they are still in cache. Lab conversion and connectivity (on runs of labels) are parallel
//! too.

mod assign;
mod connectivity;
mod lab;

use crate::{Error, Result};
use assign::Iterations;
use connectivity::enforce_connectivity;
use lab::{to_lab, LabImage};

/// SLIC settings.
#[derive(Clone, Debug, PartialEq)]
pub struct SlicParams {
    /// The number of superpixels wanted (K). `None`: one per 400 pixels (S = 20), a size at
    /// which a streak of a few tens of pixels across still holds whole superpixels.
    pub superpixels: Option<usize>,
    /// Compactness m: weight of the distance in the image against the distance in colour.
    /// 10 is EPFL's and scikit-image's usual value for CIELAB.
    pub compactness: f32,
    /// Number of assignment and update rounds (10 in the paper of Achanta et al.).
    pub iterations: usize,
}

impl Default for SlicParams {
    fn default() -> Self {
        SlicParams {
            superpixels: None,
            compactness: 10.0,
            iterations: 10,
        }
    }
}

impl SlicParams {
    /// The K actually used for an image of `pixels` pixels.
    pub fn superpixel_count(&self, pixels: usize) -> usize {
        self.superpixels
            .unwrap_or_else(|| (pixels / 400).max(1))
            .clamp(1, pixels.max(1))
    }
}

/// A superpixel segmentation: every pixel carries a label in `0..count`, and every label is
/// one 4-connected region.
#[derive(Clone, Debug)]
pub struct Superpixels {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The label of every pixel, row by row.
    pub labels: Vec<u32>,
    /// The number of labels.
    pub count: usize,
}

impl Superpixels {
    /// The pixel indices of every label, each list in raster order.
    pub fn members(&self) -> Vec<Vec<u32>> {
        let mut members = vec![Vec::new(); self.count];
        for (i, &l) in self.labels.iter().enumerate() {
            members[l as usize].push(i as u32);
        }
        members
    }

    /// For every label, the sorted list of labels sharing a 4-connected pixel edge with it.
    pub fn adjacency(&self) -> Vec<Vec<u32>> {
        let (w, h) = (self.width as usize, self.height as usize);
        let mut adjacent = vec![Vec::new(); self.count];
        let mut link = |a: u32, b: u32| {
            if a != b {
                adjacent[a as usize].push(b);
                adjacent[b as usize].push(a);
            }
        };
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                if x + 1 < w {
                    link(self.labels[i], self.labels[i + 1]);
                }
                if y + 1 < h {
                    link(self.labels[i], self.labels[i + w]);
                }
            }
        }
        for list in &mut adjacent {
            list.sort_unstable();
            list.dedup();
        }
        adjacent
    }

    /// True for a pixel whose right or lower neighbour has another label: a one-pixel-wide
    /// boundary, as drawn in the pictures and used by boundary recall.
    pub fn boundary(&self) -> Vec<bool> {
        let (w, h) = (self.width as usize, self.height as usize);
        (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                (x + 1 < w && self.labels[i] != self.labels[i + 1])
                    || (y + 1 < h && self.labels[i] != self.labels[i + w])
            })
            .collect()
    }
}

/// A cluster centre: colour and position.
#[derive(Clone, Copy, Debug)]
struct Centre {
    l: f32,
    a: f32,
    b: f32,
    x: f32,
    y: f32,
}

/// Segments an image given as sRGB-encoded colours in [0, 1] (row by row) into superpixels.
pub fn slic(
    width: u32,
    height: u32,
    srgb: &[[f32; 3]],
    params: &SlicParams,
) -> Result<Superpixels> {
    let (w, h) = (width as usize, height as usize);
    let n = w * h;
    if n == 0 || srgb.len() != n {
        return Err(Error::Usage(format!(
            "SLIC needs a {width} x {height} image with {n} pixels, got {} pixels",
            srgb.len()
        )));
    }
    if !(params.compactness.is_finite() && params.compactness > 0.0) {
        return Err(Error::Usage(format!(
            "the SLIC compactness must be a positive number, not {}",
            params.compactness
        )));
    }
    if params.superpixels == Some(0) {
        return Err(Error::Usage(
            "the number of superpixels must be at least 1".into(),
        ));
    }
    if params.iterations == 0 {
        return Err(Error::Usage("SLIC needs at least one iteration".into()));
    }
    let k_wanted = params.superpixel_count(n);
    let lab = to_lab(srgb);
    let step = ((n as f64 / k_wanted as f64).sqrt() + 0.5).max(1.0) as usize;
    let mut centres = grid_seeds(&lab, w, h, step);
    perturb_seeds(&lab, w, h, &mut centres);

    let offset = if step < 10 {
        (step as f32 * 1.5) as i64
    } else {
        step as i64
    };
    let inv_weight = {
        let s_over_m = step as f32 / params.compactness;
        1.0 / (s_over_m * s_over_m)
    };
    let mut labels = vec![0u32; n];
    let mut iterations = Iterations::new(w, h, offset, inv_weight);
    for i in 0..params.iterations {
        // The centres after the last assignment are not needed.
        let update = i + 1 < params.iterations;
        iterations.step(&lab, &mut centres, &mut labels, update);
    }
    let count = enforce_connectivity(&mut labels, w, h, n / centres.len().max(1));
    Ok(Superpixels {
        width,
        height,
        labels,
        count,
    })
}

/// Fixed-point scale of the centre sums: Lab units times 256, positions exact.
const FIXED: f32 = 256.0;

/// EPFL's `GetLABXYSeeds_ForGivenK`: a grid of step `step`, the remainder spread over strips.
fn grid_seeds(lab: &LabImage, w: usize, h: usize, step: usize) -> Vec<Centre> {
    let strips = |len: usize| ((len as f64 / step as f64 + 0.5) as usize).max(1);
    let (xstrips, ystrips) = (strips(w), strips(h));
    let xerr_per = (w as f64 - (step * xstrips) as f64) / xstrips as f64;
    let yerr_per = (h as f64 - (step * ystrips) as f64) / ystrips as f64;
    let off = step as f64 / 2.0;
    let mut centres = Vec::with_capacity(xstrips * ystrips);
    for sy in 0..ystrips {
        let y = ((sy * step) as f64 + off + sy as f64 * yerr_per) as usize;
        let y = y.min(h - 1);
        for sx in 0..xstrips {
            let x = ((sx * step) as f64 + off + sx as f64 * xerr_per) as usize;
            let x = x.min(w - 1);
            let [l, a, b] = lab.colour(y * w + x);
            centres.push(Centre {
                l,
                a,
                b,
                x: x as f32,
                y: y as f32,
            });
        }
    }
    centres
}

/// EPFL's `PerturbSeeds`: move each seed to the lowest Lab gradient in its 3x3 neighbourhood,
/// so that no seed starts on an edge or a noisy pixel.
fn perturb_seeds(lab: &LabImage, w: usize, h: usize, centres: &mut [Centre]) {
    let colour_sq = |i: usize, j: usize| {
        let (ci, cj) = (lab.colour(i), lab.colour(j));
        let (dl, da, db) = (ci[0] - cj[0], ci[1] - cj[1], ci[2] - cj[2]);
        dl * dl + da * da + db * db
    };
    let gradient = |x: usize, y: usize| -> f32 {
        // EPFL's DetectLabEdges is zero on the image border.
        if x == 0 || y == 0 || x + 1 >= w || y + 1 >= h {
            return 0.0;
        }
        let i = y * w + x;
        colour_sq(i - 1, i + 1) + colour_sq(i - w, i + w)
    };
    for c in centres.iter_mut() {
        let (ox, oy) = (c.x as usize, c.y as usize);
        let mut best = (gradient(ox, oy), ox, oy);
        for dy in -1i64..=1 {
            for dx in -1i64..=1 {
                let (x, y) = (ox as i64 + dx, oy as i64 + dy);
                if x < 0 || y < 0 || x >= w as i64 || y >= h as i64 {
                    continue;
                }
                let g = gradient(x as usize, y as usize);
                if g < best.0 {
                    best = (g, x as usize, y as usize);
                }
            }
        }
        let [l, a, b] = lab.colour(best.2 * w + best.1);
        *c = Centre {
            l,
            a,
            b,
            x: best.1 as f32,
            y: best.2 as f32,
        };
    }
}
