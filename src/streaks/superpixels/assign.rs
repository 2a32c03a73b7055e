//! The assignment and update steps of SLIC.

use rayon::prelude::*;

use super::lab::LabImage;
use super::{Centre, BAND_ROWS, FIXED};

/// The assignment step: every pixel takes the nearest centre whose window holds it.
#[allow(clippy::too_many_arguments)]
pub(super) fn assign(
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

/// The update step: every centre moves to the mean colour and position of its pixels.
pub(super) fn update(lab: &LabImage, w: usize, labels: &[u32], centres: &mut [Centre]) {
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
