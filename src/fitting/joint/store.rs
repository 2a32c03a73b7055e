//! The traced pixels' samples put in store: each plane's per-sample vectors
//! ([`PlaneSamples`]) and, for a recorded trace, the samples' lobes ([`Recorded`]), filled in
//! parallel.
//!
//! A trace ends with millions of samples in per-pixel lists (the gloss search's first fit on
//! Table 1: 51 000 pixels at 128 samples each). Copied into the planes' vectors one pixel after
//! another, on one core, that took 0.17 s of the search's first fit while the other core
//! waited. Here each plane's vectors are sized first (a count per pixel, then their running
//! sum), cut into the shares of fixed pieces of [`PIECE`] pixels, and the pieces filled
//! on every core: every value lands where the one-by-one copy put it.

use std::sync::Arc;

use glam::Vec2;
use rayon::prelude::*;

use super::control_variate::LobeGaussian;
use super::direct::Hit;
use super::kernel::{smallest_light, POINT_CELL};
use super::reweight::{CameraRay, PixelRecord, Recorded, SampleLobe};
use super::samples::PlaneSamples;
use crate::fitting::light_plane::LightPlane;
use crate::fitting::rect::Rect;
use crate::render::WaterPoint;

/// One traced pixel: its samples in store order (`trace::in_store_order`), its control
/// variate per plane, and, for a recorded trace, its record.
pub(super) type Traced = (Vec<Hit>, Vec<LobeGaussian>, Option<Box<PixelRecord>>);

/// Pixels a parallel piece fills.
const PIECE: usize = 256;

/// Stores `per_pixel` (in the region's order) for each of `planes`; the pixels from
/// `first_direct` on see the lights' walls directly (their samples do not size the smallest
/// light). With `record`, also gathers what weighting the samples again needs (every pixel
/// then carries a record).
pub(super) fn store(
    per_pixel: Vec<Traced>,
    planes: &[&LightPlane],
    first_direct: usize,
    record: bool,
) -> (Vec<PlaneSamples>, Option<Recorded>) {
    let mut lobes = Vec::with_capacity(planes.len());
    let stored = planes
        .iter()
        .enumerate()
        .map(|(k, plane)| {
            let (samples, plane_lobes) = store_plane(&per_pixel, k, plane, first_direct, record);
            lobes.push(plane_lobes);
            samples
        })
        .collect();
    let recorded = record.then(|| {
        // Each pixel's rays and water point moved out, its lists freed, on every core.
        let rest: Vec<(Vec<CameraRay>, Option<WaterPoint>, f32)> = per_pixel
            .into_par_iter()
            .map(|(_, _, r)| {
                let r = r.unwrap_or_default();
                (r.rays, r.water, r.drew)
            })
            .collect();
        let mut rays = Vec::with_capacity(rest.len());
        let mut water = Vec::with_capacity(rest.len());
        let mut drew = Vec::with_capacity(rest.len());
        for (r, w, d) in rest {
            rays.push(r);
            water.push(w);
            drew.push(d);
        }
        Recorded {
            lobes,
            rays,
            water,
            drew,
        }
    });
    (stored, recorded)
}

/// Plane `k`'s samples, and with `record` their lobes (else an empty list).
fn store_plane(
    per_pixel: &[Traced],
    k: usize,
    plane: &LightPlane,
    first_direct: usize,
    record: bool,
) -> (PlaneSamples, Vec<SampleLobe>) {
    let mine = |hits: &[Hit]| hits.iter().filter(|h| h.0 as usize == k).count() as u32;
    let counts: Vec<u32> = per_pixel.par_iter().map(|p| mine(&p.0)).collect();
    let mut offsets = Vec::with_capacity(per_pixel.len() + 1);
    offsets.push(0u32);
    let mut sum = 0u32;
    for c in &counts {
        sum += c;
        offsets.push(sum);
    }
    let n = sum as usize;
    let filled = |value| {
        let mut v = Vec::with_capacity(n);
        v.par_extend(rayon::iter::repeat_n(value, n));
        v
    };
    let mut points: Vec<Vec2> = filled(Vec2::ZERO);
    let mut cells: Vec<Vec2> = filled(Vec2::ZERO);
    let mut weights: Vec<f32> = vec![0.0; n];
    let mut halves: Vec<f32> = vec![0.0; n];
    let mut by_v: Vec<u16> = vec![0; n];
    let mut lobes: Vec<SampleLobe> = if record {
        let mut v = Vec::with_capacity(n);
        v.par_extend(rayon::iter::repeat_n(SampleLobe::DIRECT, n));
        v
    } else {
        Vec::new()
    };
    let mut bbox = vec![Rect::EMPTY; per_pixel.len()];
    let mut reaches = vec![Vec2::ZERO; per_pixel.len()];
    // Each piece's pixels, and its share of every vector.
    let starts: Vec<usize> = (0..per_pixel.len()).step_by(PIECE).collect();
    let sample_bounds: Vec<usize> = starts
        .iter()
        .skip(1)
        .map(|&s| offsets[s] as usize)
        .chain(std::iter::once(n))
        .collect();
    let pixel_bounds: Vec<usize> = starts
        .iter()
        .skip(1)
        .copied()
        .chain(std::iter::once(per_pixel.len()))
        .collect();
    let pieces: Vec<Piece> = starts
        .iter()
        .zip(cut(&mut points, &sample_bounds))
        .zip(cut(&mut cells, &sample_bounds))
        .zip(cut(&mut weights, &sample_bounds))
        .zip(cut(&mut halves, &sample_bounds))
        .zip(cut(&mut by_v, &sample_bounds))
        .zip(cut_or_empty(&mut lobes, &sample_bounds))
        .zip(cut(&mut bbox, &pixel_bounds))
        .zip(cut(&mut reaches, &pixel_bounds))
        .map(
            |((((((((&first, points), cells), weights), halves), by_v), lobes), bbox), reach)| {
                Piece {
                    first,
                    points,
                    cells,
                    weights,
                    halves,
                    by_v,
                    lobes,
                    bbox,
                    reach,
                }
            },
        )
        .collect();
    pieces
        .into_par_iter()
        .for_each(|piece| piece.fill(per_pixel, k));
    let gauss: Vec<LobeGaussian> = per_pixel.par_iter().map(|p| p.1[k]).collect();
    let distance = plane.camera_distance();
    // From the water pixels' samples alone: the bound is about the lobes' kernels.
    let lobe_samples = offsets[first_direct.min(per_pixel.len())] as usize;
    let min_size = smallest_light(&cells[..lobe_samples], distance);
    (
        PlaneSamples {
            offsets: Arc::new(offsets),
            bbox: Arc::new(bbox),
            points: Arc::new(points),
            cells: Arc::new(cells),
            weights,
            halves: Arc::new(halves),
            by_v: Arc::new(by_v),
            reach: Arc::new(reaches),
            gauss,
            min_size,
            distance,
        },
        lobes,
    )
}

/// A piece of pixels from `first` on, with its shares of one plane's vectors.
struct Piece<'a> {
    first: usize,
    points: &'a mut [Vec2],
    cells: &'a mut [Vec2],
    weights: &'a mut [f32],
    halves: &'a mut [f32],
    by_v: &'a mut [u16],
    /// Empty when the trace is not recorded.
    lobes: &'a mut [SampleLobe],
    bbox: &'a mut [Rect],
    reach: &'a mut [Vec2],
}

impl Piece<'_> {
    /// Copies plane `k`'s samples of the piece's pixels, in order, with each pixel's bounding
    /// box of its kernels and their largest reach.
    fn fill(self, per_pixel: &[Traced], k: usize) {
        let mut j = 0;
        for (i, (bbox, reach)) in self.bbox.iter_mut().zip(self.reach.iter_mut()).enumerate() {
            let (hits, _, record) = &per_pixel[self.first + i];
            let mut bb = Rect::EMPTY;
            let mut far = Vec2::splat(POINT_CELL);
            for (q, &(kk, p, cell, w, half, v_order)) in hits.iter().enumerate() {
                if kk as usize != k {
                    continue;
                }
                self.points[j] = p;
                self.cells[j] = cell;
                self.weights[j] = w;
                self.halves[j] = half;
                self.by_v[j] = v_order;
                if !self.lobes.is_empty() {
                    // A recorded pixel's lobes run beside its samples, one for one.
                    if let Some(lobe) = record.as_ref().and_then(|r| r.lobes.get(q)) {
                        self.lobes[j] = *lobe;
                    }
                }
                bb = bb.union(&Rect::around(p, cell.abs()));
                far = far.max(cell.abs());
                j += 1;
            }
            *bbox = bb;
            *reach = far;
        }
    }
}

/// `v` cut at the ends `bounds` (ascending, the last `v.len()`): one slice a piece.
fn cut<'a, T>(mut v: &'a mut [T], bounds: &[usize]) -> Vec<&'a mut [T]> {
    let mut at = 0;
    let mut parts = Vec::with_capacity(bounds.len());
    for &end in bounds {
        let (part, rest) = std::mem::take(&mut v).split_at_mut(end - at);
        parts.push(part);
        v = rest;
        at = end;
    }
    parts
}

/// [`cut`], or an empty slice a piece when `v` is empty (a trace not recorded).
fn cut_or_empty<'a, T>(v: &'a mut [T], bounds: &[usize]) -> Vec<&'a mut [T]> {
    if v.is_empty() {
        bounds.iter().map(|_| Default::default()).collect()
    } else {
        cut(v, bounds)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Rng;

    /// The one-by-one copy the parallel store replaces: every pixel in order, its samples of
    /// plane `k` pushed as they come.
    fn one_by_one(per_pixel: &[Traced], k: usize) -> (Vec<u32>, Vec<Hit>, Vec<SampleLobe>) {
        let mut offsets = vec![0u32];
        let mut hits = Vec::new();
        let mut lobes = Vec::new();
        for (h, _, r) in per_pixel {
            for (q, hit) in h.iter().enumerate() {
                if hit.0 as usize == k {
                    hits.push(*hit);
                    if let Some(r) = r {
                        lobes.push(r.lobes[q]);
                    }
                }
            }
            offsets.push(hits.len() as u32);
        }
        (offsets, hits, lobes)
    }

    /// Random pixels over several pieces (empty ones among them, two planes interleaved),
    /// stored in parallel: every vector equal to the one-by-one copy's, each pixel's box and
    /// reach those of its own samples, and the records' rays and water points in order.
    #[test]
    fn stored_in_parallel_is_the_one_by_one_copy() {
        let mut rng = Rng::new(7, 11);
        let pixels = 3 * PIECE + 17;
        let per_pixel: Vec<Traced> = (0..pixels)
            .map(|i| {
                let n = if i % 5 == 0 {
                    0
                } else {
                    (rng.next_f32() * 40.0) as usize
                };
                let hits: Vec<Hit> = (0..n)
                    .map(|s| {
                        (
                            (rng.next_f32() < 0.3) as u16,
                            Vec2::new(rng.next_f32(), rng.next_f32()),
                            Vec2::new(rng.next_f32() * 0.1, -rng.next_f32() * 0.1),
                            rng.next_f32() - 0.5,
                            if s % 2 == 0 { 1.0 } else { -1.0 },
                            s as u16,
                        )
                    })
                    .collect();
                let lobes = (0..n)
                    .map(|s| SampleLobe {
                        ray: (s % 7) as u8,
                        wi: glam::Vec3::new(rng.next_f32(), 1.0, rng.next_f32()),
                        pdf: rng.next_f32(),
                        area_pdf: rng.next_f32(),
                    })
                    .collect();
                let record = PixelRecord {
                    lobes,
                    rays: vec![(glam::Vec3::X, glam::Vec3::Y); i % 3],
                    water: None,
                    drew: i as f32,
                };
                (hits, vec![LobeGaussian::NONE; 2], Some(Box::new(record)))
            })
            .collect();
        let plane = LightPlane::with_frame(
            (0, 0, 0),
            glam::Vec3::new(0.0, 0.0, -10.0),
            glam::Vec3::Z,
            glam::Vec3::X,
            1.0,
        )
        .expect("a plane");
        let expected: Vec<_> = (0..2).map(|k| one_by_one(&per_pixel, k)).collect();
        let boxes: Vec<Vec<(Rect, Vec2)>> = (0..2)
            .map(|k| {
                per_pixel
                    .iter()
                    .map(|(h, _, _)| {
                        let mut bb = Rect::EMPTY;
                        let mut far = Vec2::splat(POINT_CELL);
                        for hit in h.iter().filter(|hit| hit.0 as usize == k) {
                            bb = bb.union(&Rect::around(hit.1, hit.2.abs()));
                            far = far.max(hit.2.abs());
                        }
                        (bb, far)
                    })
                    .collect()
            })
            .collect();
        let (stored, recorded) = store(per_pixel, &[&plane, &plane], pixels - 9, true);
        let recorded = recorded.expect("a recorded trace");
        for k in 0..2 {
            let (offsets, hits, lobes) = &expected[k];
            let s = &stored[k];
            assert!(hits.len() > 1000, "{} samples", hits.len());
            assert_eq!(&s.offsets[..], &offsets[..]);
            let got: Vec<Hit> = (0..hits.len())
                .map(|j| {
                    (
                        k as u16,
                        s.points[j],
                        s.cells[j],
                        s.weights[j],
                        s.halves[j],
                        s.by_v[j],
                    )
                })
                .collect();
            assert_eq!(&got, hits);
            assert_eq!(&recorded.lobes[k], lobes);
            for (i, (bb, far)) in boxes[k].iter().enumerate() {
                assert_eq!((s.bbox[i], s.reach[i]), (*bb, *far), "pixel {i}");
            }
        }
        assert_eq!(recorded.rays.len(), pixels);
        for (i, (rays, drew)) in recorded.rays.iter().zip(&recorded.drew).enumerate() {
            assert_eq!((rays.len(), *drew), (i % 3, i as f32));
        }
    }
}
