//! A threshold segmentation of the photo into streaks: a simple stand-in for the streak
//! extraction of method §5 steps 3-6, used by tests and benchmarks of the fit.

use super::observation::{luminance, StreakObservation};
use crate::photo_in::Photo;

/// A stand-in for the streak extraction, for tests and benchmarks: streaks by thresholding: water pixels brighter than `fraction` of the brightest unclipped
/// water pixel, 4-connected components of at least `min_pixels`, holes filled (so the edges are
/// the streak's outer boundary, as a region-growing extraction gives), ordered left to right.
pub fn threshold_streaks(
    photo: &Photo,
    water: &[bool],
    fraction: f32,
    min_pixels: usize,
) -> Vec<StreakObservation> {
    let (w, h) = (photo.width as usize, photo.height as usize);
    if water.len() != w * h || photo.radiance.len() != w * h || photo.clipped.len() != w * h {
        return Vec::new();
    }
    let peak = (0..w * h)
        .filter(|&i| water[i] && !photo.clipped[i])
        .map(|i| luminance(photo.radiance[i]))
        .fold(0.0f32, f32::max);
    let lit: Vec<bool> = (0..w * h)
        .map(|i| water[i] && luminance(photo.radiance[i]) > fraction * peak)
        .collect();
    let mut label = vec![usize::MAX; w * h];
    let mut components: Vec<Vec<u32>> = Vec::new();
    for start in 0..w * h {
        if !lit[start] || label[start] != usize::MAX {
            continue;
        }
        let id = components.len();
        let mut stack = vec![start];
        let mut pixels = Vec::new();
        label[start] = id;
        while let Some(p) = stack.pop() {
            pixels.push(p as u32);
            let (x, y) = (p % w, p / w);
            let mut push = |q: usize| {
                if lit[q] && label[q] == usize::MAX {
                    label[q] = id;
                    stack.push(q);
                }
            };
            if x > 0 {
                push(p - 1);
            }
            if x + 1 < w {
                push(p + 1);
            }
            if y > 0 {
                push(p - w);
            }
            if y + 1 < h {
                push(p + w);
            }
        }
        components.push(pixels);
    }
    let mut streaks: Vec<(f32, Vec<u32>)> = components
        .into_iter()
        .filter(|c| c.len() >= min_pixels)
        .map(|c| {
            let filled = fill_holes(&c, w, h);
            let mean_x =
                filled.iter().map(|&p| (p as usize % w) as f32).sum::<f32>() / filled.len() as f32;
            (mean_x, filled)
        })
        .collect();
    streaks.sort_by(|a, b| a.0.total_cmp(&b.0));
    streaks
        .into_iter()
        .enumerate()
        .filter_map(|(id, (_, pixels))| {
            StreakObservation::from_pixels(id, pixels, photo.width, photo.height, &photo.radiance)
        })
        .collect()
}

/// The component plus every pixel of its bounding box not reachable from the box's border
/// through non-member pixels.
fn fill_holes(pixels: &[u32], w: usize, h: usize) -> Vec<u32> {
    let xs = pixels.iter().map(|&p| p as usize % w);
    let ys = pixels.iter().map(|&p| p as usize / w);
    let (x0, x1) = (xs.clone().min().unwrap_or(0), xs.max().unwrap_or(0));
    let (y0, y1) = (ys.clone().min().unwrap_or(0), ys.max().unwrap_or(0));
    let (bw, bh) = (x1 - x0 + 1, y1 - y0 + 1);
    let mut member = vec![false; bw * bh];
    for &p in pixels {
        member[(p as usize / w - y0) * bw + (p as usize % w - x0)] = true;
    }
    let mut outside = vec![false; bw * bh];
    let mut stack: Vec<usize> = (0..bw * bh)
        .filter(|&i| {
            let (x, y) = (i % bw, i / bw);
            (x == 0 || y == 0 || x == bw - 1 || y == bh - 1) && !member[i]
        })
        .collect();
    for &i in &stack {
        outside[i] = true;
    }
    while let Some(i) = stack.pop() {
        let (x, y) = (i % bw, i / bw);
        let mut next = Vec::with_capacity(4);
        if x > 0 {
            next.push(i - 1);
        }
        if x + 1 < bw {
            next.push(i + 1);
        }
        if y > 0 {
            next.push(i - bw);
        }
        if y + 1 < bh {
            next.push(i + bw);
        }
        for q in next {
            if !member[q] && !outside[q] {
                outside[q] = true;
                stack.push(q);
            }
        }
    }
    let _ = h;
    (0..bw * bh)
        .filter(|&i| !outside[i])
        .map(|i| ((i / bw + y0) * w + (i % bw + x0)) as u32)
        .collect()
}
