//! Step 3 of METHOD.md §5: SLIC superpixels (Achanta et al. 2012), written here rather than
//! taken from a crate (METHOD §9: the Rust crates are buggy or unmaintained).
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
//! count (METHOD §2, determinism).
//!
//! Parallelism: the assignment step splits the image into bands of rows, and each band visits
//! the centres whose window touches it in index order, so every pixel sees the same sequence of
//! comparisons as in the sequential algorithm; the update step sums integers per thread.

use rayon::prelude::*;

use crate::{Error, Result};

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

/// CIELAB in three planes (structure of arrays, so the distance loop vectorises).
struct LabImage {
    l: Vec<f32>,
    a: Vec<f32>,
    b: Vec<f32>,
    /// The same values times [`FIXED`], as exact integers, for the centre sums.
    fixed: Vec<[i32; 3]>,
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

/// Rows per band of the parallel assignment step: small enough to spread over the threads,
/// large enough that a band's list of centres is worth building.
const BAND_ROWS: usize = 16;

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
    let mut dist = vec![f32::INFINITY; n];
    for _ in 0..params.iterations {
        assign(
            &lab,
            w,
            h,
            &centres,
            offset,
            inv_weight,
            &mut labels,
            &mut dist,
        );
        update(&lab, w, &labels, &mut centres);
    }
    let (labels, count) = enforce_connectivity(&labels, w, h, n / centres.len().max(1));
    Ok(Superpixels {
        width,
        height,
        labels,
        count,
    })
}

/// sRGB-encoded [0, 1] to CIELAB (D65 white), in parallel.
fn to_lab(srgb: &[[f32; 3]]) -> LabImage {
    // 8-bit photos hold multiples of 1/255: a table saves three powf per pixel.
    let table: Vec<f32> = (0..256)
        .map(|i| crate::photo_in::srgb_to_linear(i as f32 / 255.0))
        .collect();
    let linear = |c: f32| -> f32 {
        let c = c.clamp(0.0, 1.0);
        let scaled = c * 255.0;
        let idx = (scaled + 0.5) as usize;
        if (scaled - idx as f32).abs() < 1e-3 {
            table[idx]
        } else {
            crate::photo_in::srgb_to_linear(c)
        }
    };
    let fixed: Vec<[i32; 3]> = srgb
        .par_iter()
        .with_min_len(4096)
        .map(|p| {
            let (r, g, b) = (linear(p[0]), linear(p[1]), linear(p[2]));
            // sRGB primaries to XYZ, divided by the D65 white point.
            let x = (0.412_456_4 * r + 0.357_576_1 * g + 0.180_437_5 * b) / 0.950_47;
            let y = 0.212_672_9 * r + 0.715_152_2 * g + 0.072_175 * b;
            let z = (0.019_333_9 * r + 0.119_192 * g + 0.950_304_1 * b) / 1.088_83;
            let (fx, fy, fz) = (lab_f(x), lab_f(y), lab_f(z));
            // Quantised to multiples of 1 / FIXED (rounding half away from zero), so that the
            // centre sums are exact integers.
            let q = |v: f32| {
                let s = v * FIXED;
                (s + 0.5f32.copysign(s)) as i32
            };
            [
                q(116.0 * fy - 16.0),
                q(500.0 * (fx - fy)),
                q(200.0 * (fy - fz)),
            ]
        })
        .collect();
    let plane = |c: usize| -> Vec<f32> { fixed.iter().map(|p| p[c] as f32 / FIXED).collect() };
    LabImage {
        l: plane(0),
        a: plane(1),
        b: plane(2),
        fixed,
    }
}

/// The CIELAB companding function.
fn lab_f(t: f32) -> f32 {
    const EPSILON: f32 = 216.0 / 24389.0;
    const KAPPA: f32 = 24389.0 / 27.0;
    if t > EPSILON {
        fast_cbrt(t)
    } else {
        (KAPPA * t + 16.0) / 116.0
    }
}

/// Cube root of a positive number: a bit-level first guess (Kahan's) and two Newton steps,
/// within 2e-5 relative of `cbrt` and several times faster than the library call.
fn fast_cbrt(t: f32) -> f32 {
    let mut x = f32::from_bits(t.to_bits() / 3 + 709_921_077);
    for _ in 0..2 {
        x = (2.0 * x + t / (x * x)) * (1.0 / 3.0);
    }
    x
}

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
            let i = y * w + x;
            centres.push(Centre {
                l: lab.l[i],
                a: lab.a[i],
                b: lab.b[i],
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
        let (dl, da, db) = (
            lab.l[i] - lab.l[j],
            lab.a[i] - lab.a[j],
            lab.b[i] - lab.b[j],
        );
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
        let i = best.2 * w + best.1;
        *c = Centre {
            l: lab.l[i],
            a: lab.a[i],
            b: lab.b[i],
            x: best.1 as f32,
            y: best.2 as f32,
        };
    }
}

/// The assignment step: every pixel takes the nearest centre whose window holds it.
#[allow(clippy::too_many_arguments)]
fn assign(
    lab: &LabImage,
    w: usize,
    h: usize,
    centres: &[Centre],
    offset: i64,
    inv_weight: f32,
    labels: &mut [u32],
    dist: &mut [f32],
) {
    let bands = h.div_ceil(BAND_ROWS);
    let y_range = |c: &Centre| {
        let y0 = ((c.y as i64) - offset).max(0) as usize;
        let y1 = ((c.y as i64) + offset).min(h as i64).max(0) as usize;
        (y0, y1)
    };
    let mut by_band: Vec<Vec<u32>> = vec![Vec::new(); bands];
    for (k, c) in centres.iter().enumerate() {
        let (y0, y1) = y_range(c);
        if y0 >= y1 {
            continue;
        }
        for list in &mut by_band[y0 / BAND_ROWS..=(y1 - 1) / BAND_ROWS] {
            list.push(k as u32);
        }
    }
    labels
        .par_chunks_mut(BAND_ROWS * w)
        .zip(dist.par_chunks_mut(BAND_ROWS * w))
        .zip(by_band.par_iter())
        .enumerate()
        .for_each(|(band, ((band_labels, band_dist), band_centres))| {
            band_dist.fill(f32::INFINITY);
            let band_y0 = band * BAND_ROWS;
            let band_y1 = band_y0 + band_labels.len() / w;
            for &k in band_centres {
                let c = &centres[k as usize];
                let (y0, y1) = y_range(c);
                let x0 = ((c.x as i64) - offset).max(0) as usize;
                let x1 = ((c.x as i64) + offset).min(w as i64).max(0) as usize;
                if x0 >= x1 {
                    continue;
                }
                for y in y0.max(band_y0)..y1.min(band_y1) {
                    let dy = y as f32 - c.y;
                    let dy_term = dy * dy * inv_weight;
                    let row = y * w;
                    let local = (y - band_y0) * w;
                    let len = x1 - x0;
                    let ls = &lab.l[row + x0..row + x1];
                    let as_ = &lab.a[row + x0..row + x1];
                    let bs = &lab.b[row + x0..row + x1];
                    let ds = &mut band_dist[local + x0..local + x1];
                    let lbs = &mut band_labels[local + x0..local + x1];
                    let (ls, as_, bs) = (&ls[..len], &as_[..len], &bs[..len]);
                    let (ds, lbs) = (&mut ds[..len], &mut lbs[..len]);
                    let dx0 = x0 as f32 - c.x;
                    let (cl, ca, cb) = (c.l, c.a, c.b);
                    distance_row(
                        ls,
                        as_,
                        bs,
                        ds,
                        lbs,
                        [cl, ca, cb, dx0, inv_weight, dy_term],
                        k,
                    );
                }
            }
        });
}

/// One row of a centre's window: the distance of every pixel to the centre, kept with the
/// label when it beats the pixel's best so far. `c` = (L, a, b, dx of the first pixel,
/// spatial weight, dy term). Written over fixed blocks of 8 with branch-free selects, so that
/// the compiler vectorises it.
#[inline(always)]
fn distance_row(
    ls: &[f32],
    as_: &[f32],
    bs: &[f32],
    ds: &mut [f32],
    lbs: &mut [u32],
    c: [f32; 6],
    k: u32,
) {
    const B: usize = 8;
    let [cl, ca, cb, dx0, inv_weight, dy_term] = c;
    let len = ds.len();
    let blocks = len / B;
    let one = |j: usize, d: &mut f32, lb: &mut u32, l: f32, a: f32, b: f32| {
        let dx = dx0 + (j as i32) as f32;
        let (dl, da, db) = (l - cl, a - ca, b - cb);
        let v = dl * dl + da * da + db * db + dx * dx * inv_weight + dy_term;
        let better = v < *d;
        *d = if better { v } else { *d };
        *lb = if better { k } else { *lb };
    };
    for blk in 0..blocks {
        let o = blk * B;
        let l: &[f32; B] = ls[o..o + B].try_into().unwrap_or(&[0.0; B]);
        let a: &[f32; B] = as_[o..o + B].try_into().unwrap_or(&[0.0; B]);
        let b: &[f32; B] = bs[o..o + B].try_into().unwrap_or(&[0.0; B]);
        let d: &mut [f32; B] = (&mut ds[o..o + B])
            .try_into()
            .unwrap_or_else(|_| unreachable!());
        let lb: &mut [u32; B] = (&mut lbs[o..o + B])
            .try_into()
            .unwrap_or_else(|_| unreachable!());
        let mut v = [0.0f32; B];
        for j in 0..B {
            let dx = dx0 + ((o + j) as i32) as f32;
            let (dl, da, db) = (l[j] - cl, a[j] - ca, b[j] - cb);
            v[j] = dl * dl + da * da + db * db + dx * dx * inv_weight + dy_term;
        }
        // Masks rather than `if`, which the compiler turns back into branches here.
        let mut mask = [0u32; B];
        for j in 0..B {
            mask[j] = 0u32.wrapping_sub((v[j] < d[j]) as u32);
        }
        for j in 0..B {
            d[j] = v[j].min(d[j]);
            lb[j] = (k & mask[j]) | (lb[j] & !mask[j]);
        }
    }
    for j in blocks * B..len {
        one(j, &mut ds[j], &mut lbs[j], ls[j], as_[j], bs[j]);
    }
}

/// Fixed-point scale of the centre sums: Lab units times 256, positions exact.
const FIXED: f32 = 256.0;

/// The update step: every centre moves to the mean colour and position of its pixels.
fn update(lab: &LabImage, w: usize, labels: &[u32], centres: &mut [Centre]) {
    let k = centres.len();
    let threads = rayon::current_num_threads().max(1);
    let rows = labels.len() / w;
    let chunk_rows = rows.div_ceil(threads).max(1);
    // Integer sums are exact, so neither the chunking nor the order of the reduction changes
    // the result.
    let sums = labels
        .par_chunks(chunk_rows * w)
        .enumerate()
        .map(|(chunk, chunk_labels)| {
            let mut s = vec![[0i64; 6]; k];
            let base = chunk * chunk_rows * w;
            for (r, row_labels) in chunk_labels.chunks(w).enumerate() {
                let row = base + r * w;
                let y = (base / w + r) as i64;
                let fixed = &lab.fixed[row..row + row_labels.len()];
                // Labels come in runs along a row: sum a run locally, then add it once.
                let mut x = 0;
                while x < row_labels.len() {
                    let lb = row_labels[x];
                    let start = x;
                    let mut acc = [0i64; 3];
                    while x < row_labels.len() && row_labels[x] == lb {
                        let f = fixed[x];
                        acc[0] += f[0] as i64;
                        acc[1] += f[1] as i64;
                        acc[2] += f[2] as i64;
                        x += 1;
                    }
                    let run = (x - start) as i64;
                    let e = &mut s[lb as usize];
                    e[0] += acc[0];
                    e[1] += acc[1];
                    e[2] += acc[2];
                    // Sum of the columns start..x.
                    e[3] += (start as i64 + x as i64 - 1) * run / 2;
                    e[4] += y * run;
                    e[5] += run;
                }
            }
            s
        })
        .reduce(
            || vec![[0i64; 6]; k],
            |mut a, b| {
                for (x, y) in a.iter_mut().zip(&b) {
                    for c in 0..6 {
                        x[c] += y[c];
                    }
                }
                a
            },
        );
    for (c, s) in centres.iter_mut().zip(&sums) {
        if s[5] == 0 {
            continue;
        }
        let count = s[5] as f64;
        *c = Centre {
            l: (s[0] as f64 / count / FIXED as f64) as f32,
            a: (s[1] as f64 / count / FIXED as f64) as f32,
            b: (s[2] as f64 / count / FIXED as f64) as f32,
            x: (s[3] as f64 / count) as f32,
            y: (s[4] as f64 / count) as f32,
        };
    }
}

/// EPFL's `EnforceLabelConnectivity` (4-connected): relabels 4-connected pieces in raster
/// order; a piece of at most a quarter of the mean superpixel size joins the piece that its
/// first pixel touches on the left or above (or, failing those, right or below). Returns the
/// new labels and their count.
fn enforce_connectivity(labels: &[u32], w: usize, h: usize, mean_size: usize) -> (Vec<u32>, usize) {
    const NONE: u32 = u32::MAX;
    let n = w * h;
    let mut out = vec![NONE; n];
    let mut queue: Vec<(u32, u32)> = Vec::with_capacity(1024);
    let mut next: u32 = 0;
    let small = (mean_size / 4).max(1);
    for start in 0..n {
        if out[start] != NONE {
            continue;
        }
        let (sx, sy) = (start % w, start / w);
        // EPFL's order: left, up, right, down; the last labelled one wins (a piece flooded
        // earlier can reach round to the right of or below this pixel).
        let mut adjacent = NONE;
        for (ok, j) in [
            (sx > 0, start.wrapping_sub(1)),
            (sy > 0, start.wrapping_sub(w)),
            (sx + 1 < w, start + 1),
            (sy + 1 < h, start + w),
        ] {
            if ok && out[j] != NONE {
                adjacent = out[j];
            }
        }
        let old = labels[start];
        out[start] = next;
        queue.clear();
        queue.push((sx as u32, sy as u32));
        let mut head = 0;
        while head < queue.len() {
            let (x, y) = (queue[head].0 as usize, queue[head].1 as usize);
            head += 1;
            let i = y * w + x;
            if x > 0 && out[i - 1] == NONE && labels[i - 1] == old {
                out[i - 1] = next;
                queue.push((x as u32 - 1, y as u32));
            }
            if y > 0 && out[i - w] == NONE && labels[i - w] == old {
                out[i - w] = next;
                queue.push((x as u32, y as u32 - 1));
            }
            if x + 1 < w && out[i + 1] == NONE && labels[i + 1] == old {
                out[i + 1] = next;
                queue.push((x as u32 + 1, y as u32));
            }
            if y + 1 < h && out[i + w] == NONE && labels[i + w] == old {
                out[i + w] = next;
                queue.push((x as u32, y as u32 + 1));
            }
        }
        if queue.len() <= small && adjacent != NONE {
            for &(x, y) in &queue {
                out[y as usize * w + x as usize] = adjacent;
            }
        } else {
            next += 1;
        }
    }
    (out, next as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lab_of_known_colours() {
        // Reference values from Bruce Lindbloom's calculator (D65, sRGB).
        let lab = to_lab(&[[1.0, 1.0, 1.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]);
        assert!((lab.l[0] - 100.0).abs() < 0.01 && lab.a[0].abs() < 0.01 && lab.b[0].abs() < 0.01);
        assert!((lab.l[1] - 53.24).abs() < 0.05);
        assert!((lab.a[1] - 80.09).abs() < 0.1);
        assert!((lab.b[1] - 67.20).abs() < 0.1);
        assert!(lab.l[2].abs() < 1e-4);
    }

    #[test]
    fn fast_cbrt_is_accurate() {
        for i in 0..10_000 {
            let t = 0.008 + i as f32 * 1.2e-4;
            assert!((fast_cbrt(t) - t.cbrt()).abs() <= 2e-5 * t.cbrt(), "{t}");
        }
    }

    #[test]
    fn small_pieces_join_a_neighbour() {
        // Label 1 is split in two; the one-pixel piece at the right joins its neighbour.
        let labels = vec![
            1, 1, 0, 1, //
            1, 1, 0, 0, //
            1, 1, 0, 0,
        ];
        let (out, count) = enforce_connectivity(&labels, 4, 3, 6);
        assert_eq!(count, 2);
        assert_eq!(out, vec![0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1]);
    }
}
