//! The assignment and update steps of SLIC, fused: the image is cut into bands of rows, and a
//! band is assigned and then summed for the update while it is still in cache. The distances
//! live only in a band-sized scratch buffer.
//!
//! Every pixel compares the centres whose window holds it in index order, as in the sequential
//! algorithm, so the labels do not depend on how the bands are spread over the threads; the
//! sums are integers, so neither do the centres.

use rayon::prelude::*;

use super::lab::{LabImage, LAB_LIMIT};
use super::{Centre, FIXED};

/// Rows per band: small enough to spread over the threads and for a band's pixels, labels and
/// distances to stay in the core's cache (300 kB at 1920 pixels a row), large enough that a
/// band's list of centres is worth building. 8 measured 5 % faster than 4, 12 or 16 at
/// 1920 x 1080, S = 20.
const BAND_ROWS: usize = 8;

/// Sums of one centre's pixels: L, a and b (times [`FIXED`]), x, y and their number.
type Sums = [i64; 6];

/// What one band of rows keeps from one iteration to the next, so that iterations allocate
/// nothing.
#[derive(Default)]
struct Band {
    /// The centres whose window reaches the band, in index order.
    centres: Vec<u32>,
    /// The sums of each of `centres`.
    sums: Vec<Sums>,
    /// When some pixel of the band kept a label whose window does not reach it (no window
    /// reached the pixel this time), all the band's sums are here instead, by label, and
    /// `sums` are zero.
    strays: Vec<(u32, Sums)>,
}

/// The assignment and update steps, with the state they keep between iterations.
pub(super) struct Iterations {
    window: Windows,
    bands: Vec<Band>,
    sums: Vec<Sums>,
}

/// The image size and the centres' search windows.
#[derive(Clone, Copy)]
struct Windows {
    w: usize,
    h: usize,
    /// Half the side of a centre's search window.
    offset: i64,
    /// The weight of the squared distance in the image, (m / S)^2, times FIXED^2 as the colour
    /// distance is taken between colours times FIXED. Scaling by a power of two changes no
    /// rounding, so the distances are those in Lab units times FIXED^2, exactly (short of
    /// overflow, i.e. for any compactness below about 1e15).
    weight: f32,
}

impl Iterations {
    /// `inv_weight` is (m / S)^2.
    pub(super) fn new(w: usize, h: usize, offset: i64, inv_weight: f32) -> Self {
        Iterations {
            window: Windows {
                w,
                h,
                offset,
                weight: inv_weight * (FIXED * FIXED),
            },
            bands: (0..h.div_ceil(BAND_ROWS))
                .map(|_| Band::default())
                .collect(),
            sums: Vec::new(),
        }
    }

    /// One assignment step: every pixel reached by a window takes the nearest such centre
    /// (others keep their label). Then, if `update`, every centre moves to the mean colour and
    /// position of its pixels; a centre without pixels stays where it is.
    pub(super) fn step(
        &mut self,
        lab: &LabImage,
        centres: &mut [Centre],
        labels: &mut [u32],
        update: bool,
    ) {
        let windows = self.window;
        for band in &mut self.bands {
            band.centres.clear();
        }
        for (k, c) in centres.iter().enumerate() {
            let (x0, x1, y0, y1) = windows.window(c);
            if x0 >= x1 || y0 >= y1 {
                continue;
            }
            for band in &mut self.bands[y0 / BAND_ROWS..=(y1 - 1) / BAND_ROWS] {
                band.centres.push(k as u32);
            }
        }
        let shared: &[Centre] = centres;
        labels
            .par_chunks_mut(BAND_ROWS * windows.w)
            .zip(self.bands.par_iter_mut())
            .enumerate()
            .for_each_init(Scratch::default, |scratch, (b, (band_labels, band))| {
                windows.band_step(
                    lab,
                    shared,
                    b * BAND_ROWS,
                    band_labels,
                    band,
                    scratch,
                    update,
                );
            });
        if !update {
            return;
        }

        self.sums.clear();
        self.sums.resize(centres.len(), [0; 6]);
        for band in &self.bands {
            for (&k, s) in band.centres.iter().zip(&band.sums) {
                add(&mut self.sums[k as usize], s);
            }
            for (k, s) in &band.strays {
                add(&mut self.sums[*k as usize], s);
            }
        }
        for (c, s) in centres.iter_mut().zip(&self.sums) {
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
}

impl Windows {
    /// The columns `x0..x1` and rows `y0..y1` of a centre's search window.
    fn window(&self, c: &Centre) -> (usize, usize, usize, usize) {
        let span = |at: f32, len: usize| {
            let lo = ((at as i64) - self.offset).max(0) as usize;
            let hi = ((at as i64) + self.offset).min(len as i64).max(0) as usize;
            (lo, hi)
        };
        let (x0, x1) = span(c.x, self.w);
        let (y0, y1) = span(c.y, self.h);
        (x0, x1, y0, y1)
    }

    /// The assignment, and if `update` the sums, of the band whose first row is `y_start`.
    #[allow(clippy::too_many_arguments)]
    fn band_step(
        &self,
        lab: &LabImage,
        centres: &[Centre],
        y_start: usize,
        labels: &mut [u32],
        band: &mut Band,
        scratch: &mut Scratch,
        update: bool,
    ) {
        let w = self.w;
        let y_end = y_start + labels.len() / w;
        let Scratch { dist, spatial } = scratch;
        dist.clear();
        dist.resize(labels.len(), f32::INFINITY);
        for &k in &band.centres {
            let c = &centres[k as usize];
            let (x0, x1, y0, y1) = self.window(c);
            // The column part of the spatial term is the same in every row of the window.
            let dx0 = x0 as f32 - c.x;
            spatial.clear();
            spatial.extend((0..x1 - x0).map(|i| {
                let dx = dx0 + (i as i32) as f32;
                dx * dx * self.weight
            }));
            let colour = [c.l * FIXED, c.a * FIXED, c.b * FIXED];
            for y in y0.max(y_start)..y1.min(y_end) {
                let dy = y as f32 - c.y;
                let image = y * w + x0..y * w + x1;
                let local = (y - y_start) * w + x0..(y - y_start) * w + x1;
                distance_row(
                    [&lab.l[image.clone()], &lab.a[image.clone()], &lab.b[image]],
                    spatial,
                    &mut dist[local.clone()],
                    &mut labels[local],
                    (colour, dy * dy * self.weight),
                    k,
                );
            }
        }
        if !update {
            return;
        }

        band.sums.clear();
        band.sums.resize(band.centres.len(), [0; 6]);
        band.strays.clear();
        let mut counted = 0;
        for (&k, sums) in band.centres.iter().zip(&mut band.sums) {
            let (x0, x1, y0, y1) = self.window(&centres[k as usize]);
            for y in y0.max(y_start)..y1.min(y_end) {
                let image = y * w + x0..y * w + x1;
                let local = (y - y_start) * w + x0..(y - y_start) * w + x1;
                let [l, a, b, count, x_offsets] = sum_row(
                    [&lab.l[image.clone()], &lab.a[image.clone()], &lab.b[image]],
                    &labels[local],
                    k,
                );
                let row = [
                    l,
                    a,
                    b,
                    x_offsets + x0 as i64 * count,
                    y as i64 * count,
                    count,
                ];
                add(sums, &row);
                counted += count as usize;
            }
        }
        if counted < labels.len() {
            // Some pixel kept a label whose centre's window does not reach it (rare: only
            // where no window reached the pixel this time). Sum the band pixel by pixel.
            band.sums.iter_mut().for_each(|s| *s = [0; 6]);
            for (i, &k) in labels.iter().enumerate() {
                let (x, y) = (i % w, y_start + i / w);
                let j = y * w + x;
                let pixel = [
                    lab.l[j] as i64,
                    lab.a[j] as i64,
                    lab.b[j] as i64,
                    x as i64,
                    y as i64,
                    1,
                ];
                match band.strays.last_mut() {
                    Some((last, s)) if *last == k => add(s, &pixel),
                    _ => band.strays.push((k, pixel)),
                }
            }
        }
    }
}

/// Buffers of one worker, reused from band to band.
#[derive(Default)]
struct Scratch {
    /// The distance of every pixel of the band to its centre so far.
    dist: Vec<f32>,
    /// The column part of the spatial term, along a window's row.
    spatial: Vec<f32>,
}

fn add(to: &mut Sums, s: &Sums) {
    for (t, v) in to.iter_mut().zip(s) {
        *t += v;
    }
}

/// One row of a centre's window: the distance of every pixel to the centre, kept with the
/// label `k` when it beats the pixel's best so far. `centre` is the colour times FIXED and the
/// row part of the spatial term. A plain loop with branch-free selects on bit masks, which the
/// compiler vectorises (with `if`, it makes branches and does not).
#[inline(always)]
fn distance_row(
    lab: [&[f32]; 3],
    spatial: &[f32],
    dist: &mut [f32],
    labels: &mut [u32],
    centre: ([f32; 3], f32),
    k: u32,
) {
    let n = dist.len();
    let (l, a, b) = (&lab[0][..n], &lab[1][..n], &lab[2][..n]);
    let (spatial, labels) = (&spatial[..n], &mut labels[..n]);
    let ([cl, ca, cb], dy_term) = centre;
    for i in 0..n {
        let (dl, da, db) = (l[i] - cl, a[i] - ca, b[i] - cb);
        // The terms in EPFL's order, as before, so that every distance rounds the same.
        let v = dl * dl + da * da + db * db + spatial[i] + dy_term;
        let d = dist[i];
        let mask = 0u32.wrapping_sub((v < d) as u32);
        dist[i] = f32::from_bits((v.to_bits() & mask) | (d.to_bits() & !mask));
        labels[i] = (k & mask) | (labels[i] & !mask);
    }
}

/// The pixels of one row of a centre's window that carry its label `k`: sums of L, a and b
/// (times FIXED), their number, and the sum of their columns counted from the window's first
/// column.
#[inline(always)]
fn sum_row(lab: [&[f32]; 3], labels: &[u32], k: u32) -> [i64; 5] {
    // The values are integers of at most 16 bits: adding 1.5 * 2^23 moves them, exactly, to
    // the low bits of the f32's mantissa, so that the sums are taken on the bits as integers
    // (a loop the compiler vectorises, unlike float sums or saturating casts), and the offset
    // is taken off at the end. Pieces of 2^8 pixels keep the true sums within i32.
    const MAGIC: f32 = 12_582_912.0;
    const PIECE: usize = 1 << 8;
    const _: () = assert!(PIECE as i64 * LAB_LIMIT as i64 <= i32::MAX as i64);
    let offset = MAGIC.to_bits() as i32;
    let mut total = [0i64; 5];
    for (p, labels) in labels.chunks(PIECE).enumerate() {
        let n = labels.len();
        let start = p * PIECE;
        let [l, a, b] = lab.map(|plane| &plane[start..start + n]);
        let mut acc = [0i32; 5];
        for i in 0..n {
            let mask = 0i32.wrapping_sub((labels[i] == k) as i32);
            let bits = |v: f32| (v + MAGIC).to_bits() as i32 & mask;
            acc[0] = acc[0].wrapping_add(bits(l[i]));
            acc[1] = acc[1].wrapping_add(bits(a[i]));
            acc[2] = acc[2].wrapping_add(bits(b[i]));
            acc[3] -= mask;
            acc[4] += i as i32 & mask;
        }
        let count = acc[3];
        let colour = |c: i32| c.wrapping_sub(offset.wrapping_mul(count)) as i64;
        let piece = [
            colour(acc[0]),
            colour(acc[1]),
            colour(acc[2]),
            count as i64,
            acc[4] as i64 + start as i64 * count as i64,
        ];
        for (t, v) in total.iter_mut().zip(piece) {
            *t += v;
        }
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The steps as EPFL writes them, one pixel at a time, in Lab units: the banded, scaled
    /// and vectorised steps must give the same labels and centres, bit for bit.
    fn reference_step(
        lab: &LabImage,
        (w, h): (usize, usize),
        centres: &mut [Centre],
        (offset, inv_weight): (i64, f32),
        labels: &mut [u32],
    ) {
        let mut dist = vec![f32::INFINITY; w * h];
        for (k, c) in centres.iter().enumerate() {
            let x0 = ((c.x as i64) - offset).max(0) as usize;
            let x1 = ((c.x as i64) + offset).min(w as i64).max(0) as usize;
            let y0 = ((c.y as i64) - offset).max(0) as usize;
            let y1 = ((c.y as i64) + offset).min(h as i64).max(0) as usize;
            for y in y0..y1 {
                for x in x0..x1 {
                    let i = y * w + x;
                    let [l, a, b] = lab.colour(i);
                    let (dl, da, db) = (l - c.l, a - c.a, b - c.b);
                    let dx = (x0 as f32 - c.x) + ((x - x0) as i32) as f32;
                    let dy = y as f32 - c.y;
                    let v =
                        dl * dl + da * da + db * db + dx * dx * inv_weight + dy * dy * inv_weight;
                    if v < dist[i] {
                        dist[i] = v;
                        labels[i] = k as u32;
                    }
                }
            }
        }
        let mut sums = vec![[0i64; 6]; centres.len()];
        for (i, &k) in labels.iter().enumerate() {
            let s = &mut sums[k as usize];
            s[0] += lab.l[i] as i64;
            s[1] += lab.a[i] as i64;
            s[2] += lab.b[i] as i64;
            s[3] += (i % w) as i64;
            s[4] += (i / w) as i64;
            s[5] += 1;
        }
        for (c, s) in centres.iter_mut().zip(&sums) {
            if s[5] > 0 {
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
    }

    #[test]
    fn bands_give_the_reference_steps() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut random = move |range: f32| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32 * range
        };
        // Sizes around the band height and the vector width; windows that overlap, and narrow
        // ones that leave pixels no window reaches (which keep their label).
        for &(w, h, k, offset) in &[
            (37, 41, 12, 10),
            (64, 16, 8, 9),
            (53, 70, 6, 4),
            (5, 3, 2, 1),
        ] {
            let n = w * h;
            let mut plane = |range: f32| -> Vec<f32> {
                (0..n)
                    .map(|i| ((i % w) as f32 * 3.0 + random(range) * FIXED).round())
                    .collect()
            };
            let lab = LabImage {
                l: plane(100.0),
                a: plane(50.0),
                b: plane(50.0),
            };
            let mut centres: Vec<Centre> = (0..k)
                .map(|_| Centre {
                    l: random(100.0),
                    a: random(50.0),
                    b: random(50.0),
                    x: random(w as f32),
                    y: random(h as f32),
                })
                .collect();
            let inv_weight = 0.37;
            let mut reference = centres.clone();
            let (mut labels, mut reference_labels) = (vec![0u32; n], vec![0u32; n]);
            let mut iterations = Iterations::new(w, h, offset, inv_weight);
            for _ in 0..4 {
                iterations.step(&lab, &mut centres, &mut labels, true);
                reference_step(
                    &lab,
                    (w, h),
                    &mut reference,
                    (offset, inv_weight),
                    &mut reference_labels,
                );
                assert_eq!(labels, reference_labels, "{w} x {h}");
                let bits = |c: &[Centre]| -> Vec<[u32; 5]> {
                    c.iter()
                        .map(|c| [c.l, c.a, c.b, c.x, c.y].map(f32::to_bits))
                        .collect()
                };
                assert_eq!(bits(&centres), bits(&reference), "{w} x {h}");
            }
        }
    }
}
