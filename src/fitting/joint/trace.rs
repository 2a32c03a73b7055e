//! The trace of the joint fit's stored samples (method §5, last paragraph): every fitted
//! pixel's camera rays and lobe samples, traced once, kept per light plane as
//! [`PlaneSamples`] where they land inside the plane's region of interest.

use std::sync::atomic::{AtomicU64, Ordering};

use glam::Vec2;
use rayon::prelude::*;

use super::control_variate::{self, LobeGaussian};
use super::direct::{direct_hits, Hit, DIRECT_RAYS};
use super::kernel::{cell_half_extents, LobeNeighbours};
use super::reweight::{PixelRecord, Recorded, SampleLobe};
use super::samples::{effective_samples, lobe_strata, PlaneSamples, CAMERA_STRATA};
use super::store::{store, Traced};
use crate::fitting::light_plane::LightPlane;
use crate::fitting::rect::Rect;
use crate::optics::{compact_strata, ReflectionModel};
use crate::progress::Reporter;
use crate::random::Rng;
use crate::scene_in::Scene;
use crate::water_model::WaterModel;

/// Stream tag of the joint fit's random numbers: distinct from the renderer's (the bare pixel
/// index), from the plane search's and from the paper fit's footprints, so the fit never
/// reuses the photo's own noise.
pub(super) const JOINT_STREAM: u64 = 3 << 48;

/// Traces every pixel's samples once and stores, per light, those whose first hit is that
/// light's plane inside its region of interest `roi[k]` (a sample landing on a face shared by
/// several lights is stored for each). A sample whose ray meets no plane inside a region of
/// interest is never traced: it could not change any coefficient the fit will evaluate.
/// With the control variate (`gaussians`), a sample whose ray would meet a light's plane
/// inside its region of interest but hits something else first (or nothing: the wall ends)
/// is stored too, with the lobe's weight 0: the Gaussian it subtracts must be subtracted
/// wherever the Gaussian is, or the estimate would see light through the obstacle.
/// `repeat` and `draw` select independent random streams: `draw` 0 is the set every start
/// light reads, `draw` 1, 2, ... the sets of lights that splits added (one plane each).
/// The pixels from `first_direct` on see the lights' walls directly: their samples are their
/// strata's camera rays ([`super::direct`]), without a control variate. `progress` hears the
/// count of pixels traced.
#[allow(clippy::too_many_arguments)]
pub(super) fn trace_samples(
    water_model: &dyn WaterModel,
    scene: &Scene,
    model: &ReflectionModel,
    planes: &[&LightPlane],
    roi: &[Rect],
    pixels: &[u32],
    width: u32,
    height: u32,
    samples: u32,
    seed: u64,
    repeat: u32,
    draw: u32,
    gaussians: bool,
    first_direct: usize,
    progress: Reporter<'_>,
) -> (Vec<PlaneSamples>, u32) {
    let (stored, n, _) = trace_recorded(
        water_model,
        scene,
        model,
        planes,
        roi,
        pixels,
        (width, height),
        (samples, seed, repeat, draw),
        gaussians,
        first_direct,
        false,
        progress,
    );
    (stored, n)
}

/// [`trace_samples`], with, when `record` is set, what each stored sample needs to be
/// weighted again for another lobe ([`super::reweight`]): per plane, per sample, its
/// [`SampleLobe`], and per pixel its camera rays' directions back to the camera and lobe
/// axes, the water point its control variate was matched at and the share of its camera
/// rays that met the water. The image's size and the draw's
/// (samples, seed, repeat, draw) come as pairs and quadruples. With `record`, every sample
/// that lands inside a region of interest is stored, of zero weight or not: under another
/// lobe it may weigh.
#[allow(clippy::too_many_arguments)]
pub(super) fn trace_recorded(
    water_model: &dyn WaterModel,
    scene: &Scene,
    model: &ReflectionModel,
    planes: &[&LightPlane],
    roi: &[Rect],
    pixels: &[u32],
    (width, height): (u32, u32),
    (samples, seed, repeat, draw): (u32, u64, u32, u32),
    gaussians: bool,
    first_direct: usize,
    record: bool,
    progress: Reporter<'_>,
) -> (Vec<PlaneSamples>, u32, Option<Recorded>) {
    let lobe = lobe_strata(samples);
    let per_pixel_samples = effective_samples(samples);
    let direct_weight = per_pixel_samples as f32 / DIRECT_RAYS as f32;
    let total = pixels.len() as u64;
    let traced = AtomicU64::new(0);
    // About a hundred reports over the whole set.
    let every = (total / 100).max(1);
    progress.advance(0, total);
    // The pixels are traced in an interleaved order and put back in the region's order
    // after: the traced samples cluster where the lobes reach the lights, and in the
    // region's own order the first half of Table 1's pixels took a twentieth of the time, so
    // the progress's time left came out many times too short.
    let order = interleaved(pixels.len());
    // The control variates' grid of lobe directions, drawn once for every pixel.
    let grid = control_variate::grid_draws(water_model, model);
    let traced_in_order: Vec<Traced> = order
        .par_iter()
        .with_max_len(crate::fitting::PIXELS_PER_TASK)
        .map(|&index| {
            let pixel = pixels[index];
            let done = traced.fetch_add(1, Ordering::Relaxed) + 1;
            if done.is_multiple_of(every) || done == total {
                progress.advance(done, total);
            }
            let stream = JOINT_STREAM | (draw as u64) << 52 | (repeat as u64) << 32 | pixel as u64;
            let mut rng = Rng::new(seed, stream);
            let (x, y) = (pixel % width, pixel / width);
            if index >= first_direct {
                let hits = direct_hits(scene, planes, roi, x, y, width, height, direct_weight);
                let lobes = if record {
                    vec![SampleLobe::DIRECT; hits.len()]
                } else {
                    Vec::new()
                };
                let (hits, lobes) = in_store_order(hits, lobes, planes.len());
                return (
                    hits,
                    vec![LobeGaussian::NONE; planes.len()],
                    record.then(|| {
                        Box::new(PixelRecord {
                            lobes,
                            rays: Vec::new(),
                            water: None,
                            drew: 0.0,
                        })
                    }),
                );
            }
            let mut hits = Vec::new();
            let mut lobes = Vec::new();
            let mut rays = Vec::new();
            let mut first_water = None;
            let mut missed_water = 0u32;
            // The control variates, matched to the pixel's first camera ray to meet the water
            // before any of its lobe samples is drawn: they depend on no lobe sample, so the
            // estimate keeps its expectation.
            let mut gauss: Option<Vec<LobeGaussian>> = None;
            let inv_c = 1.0 / CAMERA_STRATA as f32;
            let inv_grid = 1.0 / (lobe * CAMERA_STRATA) as f32;
            // The pixel's camera rays first: where each is drawn in the stream, its stratum
            // offsets, and the generator as its lobe samples find it (each camera ray's
            // numbers come in one run: its position, then its lobe samples'). Traced
            // together, as the pixel's rays run close together.
            let mut offsets: Vec<u32> = (0..CAMERA_STRATA * CAMERA_STRATA).collect();
            let rays_per_pixel = (2 * CAMERA_STRATA * CAMERA_STRATA) as usize;
            let mut camera = Vec::with_capacity(rays_per_pixel);
            let mut positions = Vec::with_capacity(rays_per_pixel);
            for i in 0..2 * CAMERA_STRATA * CAMERA_STRATA {
                let cs = i % (CAMERA_STRATA * CAMERA_STRATA);
                let half_sign = if i < CAMERA_STRATA * CAMERA_STRATA {
                    1.0
                } else {
                    -1.0
                };
                if cs == 0 {
                    shuffle(&mut offsets, &mut rng);
                }
                let (ox, oy) = (
                    offsets[cs as usize] % CAMERA_STRATA,
                    offsets[cs as usize] / CAMERA_STRATA,
                );
                let fx = ((cs % CAMERA_STRATA) as f32 + rng.next_f32()) * inv_c;
                let fy = ((cs / CAMERA_STRATA) as f32 + rng.next_f32()) * inv_c;
                positions.push(Vec2::new(x as f32 + fx, y as f32 + fy));
                camera.push((ox, oy, half_sign, rng.clone()));
                // Past this ray's lobe numbers, drawn whatever it hits.
                for _ in 0..lobe * lobe {
                    rng.next_f32();
                    rng.next_f32();
                }
            }
            let mut points = vec![None; positions.len()];
            let (mut drawn, mut wis, mut tmaxes, mut reflected) =
                (Vec::new(), Vec::new(), Vec::new(), Vec::new());
            water_model.water_points(scene, &positions, width, height, &mut points);
            for ((ox, oy, half_sign, mut rng), water) in camera.into_iter().zip(points) {
                let Some(water) = water else {
                    missed_water += 1;
                    continue;
                };
                // Its place among the pixel's recorded camera rays (each met the water).
                let ray = rays.len();
                if record {
                    rays.push((water.wo, water.normal));
                }
                let gauss = gauss.get_or_insert_with(|| {
                    first_water = Some(water);
                    if !gaussians {
                        return vec![LobeGaussian::NONE; planes.len()];
                    }
                    let (dirs, count) =
                        control_variate::lobe_directions(water_model, model, &water, &grid);
                    planes
                        .iter()
                        .map(|plane| LobeGaussian::matched(plane, water.start, &dirs, count))
                        .collect()
                });
                // The camera ray's lobe samples that may land in a region of interest, then
                // their rays traced together (they leave one point), then each one stored.
                drawn.clear();
                for ls in 0..lobe * lobe {
                    let grid_u = Vec2::new(
                        (((ls % lobe) * CAMERA_STRATA + ox) as f32 + rng.next_f32()) * inv_grid,
                        (((ls / lobe) * CAMERA_STRATA + oy) as f32 + rng.next_f32()) * inv_grid,
                    );
                    let u = compact_strata(grid_u);
                    let Some(s) = water_model.reflect(&water, model, u) else {
                        continue;
                    };
                    // The farthest plane it lands on inside a region of interest: nothing
                    // beyond it matters, so the trace stops there.
                    let reach = planes
                        .iter()
                        .zip(roi)
                        .filter_map(|(plane, r)| {
                            let (t, q) = plane.hit(water.start, s.wi)?;
                            r.contains(q).then_some(t)
                        })
                        .reduce(f32::max);
                    let Some(reach) = reach else {
                        continue;
                    };
                    // A thousandth further: a face's triangles lie within a ten-thousandth
                    // of the distance of its plane.
                    drawn.push((grid_u, s, reach * 1.001));
                }
                wis.clear();
                wis.extend(drawn.iter().map(|d| d.1.wi));
                tmaxes.clear();
                tmaxes.extend(drawn.iter().map(|d| d.2));
                reflected.clear();
                reflected.resize(drawn.len(), None);
                water.reflected_hits(scene, &wis, &tmaxes, &mut reflected);
                for (&(grid_u, s, _), &hit) in drawn.iter().zip(&reflected) {
                    let mut lobe_cell = None;
                    for (k, plane) in planes.iter().enumerate() {
                        let g = &gauss[k];
                        let on_plane = hit.filter(|h| plane.contains_triangle(scene, h.triangle));
                        // Where the ray lands on the plane, how far, and the lobe's weight there.
                        let (q, t, lobe_weight) = match on_plane {
                            Some(h) => (plane.coords(water.start + s.wi * h.t), h.t, s.weight),
                            None if !g.is_none() => {
                                let Some((t, q)) = plane.hit(water.start, s.wi) else {
                                    continue;
                                };
                                if !roi[k].contains(q) {
                                    continue;
                                }
                                (q, t, 0.0)
                            }
                            None => continue,
                        };
                        let lobe_cell = lobe_cell.get_or_insert_with(|| {
                            LobeNeighbours::new(water_model, model, &water, s.wi, grid_u, inv_grid)
                        });
                        let cell = cell_half_extents(lobe_cell, water.start, plane);
                        // Another light's sample on a shared wall, out of this light's
                        // reach: it could never fall in its rectangle.
                        if !roi[k].overlaps(&Rect::around(q, cell)) {
                            continue;
                        }
                        // The density the sample was drawn with, per unit area of the plane.
                        let area_pdf = s.pdf * s.wi.dot(plane.normal).abs() / (t * t);
                        let weight = if g.is_none() {
                            lobe_weight
                        } else if area_pdf > 0.0 {
                            // Less the Gaussian's density over it.
                            lobe_weight - g.density(q) / area_pdf
                        } else {
                            lobe_weight
                        };
                        if record {
                            hits.push((k as u16, q, cell, weight, half_sign, 0));
                            lobes.push(SampleLobe {
                                ray: ray as u8,
                                wi: s.wi,
                                pdf: if lobe_weight != 0.0 { s.pdf } else { 0.0 },
                                area_pdf,
                            });
                        } else if weight != 0.0 {
                            hits.push((k as u16, q, cell, weight, half_sign, 0));
                        }
                    }
                }
            }
            // A camera ray that misses the water draws nothing, so nothing of the Gaussian
            // is subtracted for it: the closed-form part counts only the rays that drew.
            let drew = 1.0 - missed_water as f32 / (2 * CAMERA_STRATA * CAMERA_STRATA) as f32;
            let mut gauss = gauss.unwrap_or_else(|| vec![LobeGaussian::NONE; planes.len()]);
            for g in gauss.iter_mut() {
                g.mass *= drew;
            }
            let (hits, lobes) = in_store_order(hits, lobes, planes.len());
            let recorded = record.then(|| {
                Box::new(PixelRecord {
                    lobes,
                    rays,
                    water: first_water,
                    drew,
                })
            });
            (hits, gauss, recorded)
        })
        .collect();
    let mut slots: Vec<Option<Traced>> = (0..pixels.len()).map(|_| None).collect();
    for (hits, &index) in traced_in_order.into_iter().zip(&order) {
        slots[index] = Some(hits);
    }
    let per_pixel: Vec<Traced> = slots.into_iter().map(Option::unwrap_or_default).collect();
    let (stored, recorded) = store(per_pixel, planes, first_direct, record);
    (stored, per_pixel_samples, recorded)
}

/// One pixel's samples as the planes store them: in order of u (see [`PlaneSamples::near`];
/// a stable sort, so that the order is the same on every run), each carrying, as its last
/// field, the entry of its plane's order in v ([`PlaneSamples::by_v`]) at its place among
/// that plane's samples. Sorted here, in the parallel trace, rather than while the planes
/// are gathered.
fn in_store_order(
    hits: Vec<Hit>,
    lobes: Vec<SampleLobe>,
    planes: usize,
) -> (Vec<Hit>, Vec<SampleLobe>) {
    // The same stable order for both: by u, ties in the order drawn.
    let order = stable_order(hits.iter().map(|h| h.1.x));
    let mut hits: Vec<Hit> = order.iter().map(|&i| hits[i as usize]).collect();
    let lobes = if lobes.is_empty() {
        lobes
    } else {
        order.iter().map(|&i| lobes[i as usize]).collect()
    };
    let mut mine = Vec::new();
    for k in 0..planes {
        mine.clear();
        mine.extend((0..hits.len()).filter(|&q| hits[q].0 as usize == k));
        // At most `super::MAX_JOINT_SAMPLES` per pixel (checked before the trace), so an
        // entry fits in a u16.
        let order = stable_order(mine.iter().map(|&q| hits[q].1.y));
        for (&q, v) in mine.iter().zip(order) {
            hits[q].5 = v as u16;
        }
    }
    (hits, lobes)
}

/// The indices of `values` in the order a stable sort by [`f32::total_cmp`] puts them:
/// sorted as one integer each, the value's place in that order above its index, which
/// keeps equal values in their order without a stable sort's comparisons through the list.
fn stable_order(values: impl Iterator<Item = f32>) -> Vec<u32> {
    let mut keys: Vec<u64> = values
        .enumerate()
        .map(|(i, v)| (total_order_key(v) as u64) << 32 | i as u64)
        .collect();
    keys.sort_unstable();
    keys.into_iter().map(|k| k as u32).collect()
}

/// `v`'s place in [`f32::total_cmp`]'s order as an unsigned integer: a negative value's bits
/// all flipped, a positive value's sign bit set (the map `total_cmp` itself compares by).
fn total_order_key(v: f32) -> u32 {
    let bits = v.to_bits();
    if bits >> 31 == 1 {
        !bits
    } else {
        bits | 1 << 31
    }
}

/// Pixels apart in the interleaved order of [`interleaved`].
const INTERLEAVE: usize = 16;

/// `0..n` in an interleaved order: every [`INTERLEAVE`]-th index from 0, then from 1, and so
/// on, so that any stretch of the order samples the whole range evenly.
fn interleaved(n: usize) -> Vec<usize> {
    (0..INTERLEAVE.min(n.max(1)))
        .flat_map(|start| (start..n).step_by(INTERLEAVE))
        .collect()
}

/// Fisher-Yates shuffle from the pixel's own stream.
fn shuffle(items: &mut [u32], rng: &mut Rng) {
    for i in (1..items.len()).rev() {
        let j = ((rng.next_f32() * (i + 1) as f32) as usize).min(i);
        items.swap(i, j);
    }
}

#[cfg(test)]
mod tests {
    use super::super::fixture::table3_light0;
    use super::*;

    /// The order of integer keys is a stable sort by `total_cmp`: values with many ties, of
    /// both signs and both zeros, infinities and a NaN, against `sort_by`.
    #[test]
    fn the_keyed_order_is_the_stable_sort() {
        let mut rng = Rng::new(3, 9);
        let specials = [
            0.0,
            -0.0,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            1e-40,
            -1e-40,
        ];
        for n in [0, 1, 2, 7, 64, 300] {
            let values: Vec<f32> = (0..n)
                .map(|i| {
                    if i % 11 == 5 {
                        specials[i % specials.len()]
                    } else {
                        ((rng.next_f32() * 9.0) as i32 - 4) as f32 * 0.25
                    }
                })
                .collect();
            let mut expected: Vec<u32> = (0..n as u32).collect();
            expected.sort_by(|&a, &b| values[a as usize].total_cmp(&values[b as usize]));
            assert_eq!(stable_order(values.iter().copied()), expected, "{n}");
        }
    }

    #[test]
    fn the_interleaved_order_visits_every_index_once() {
        for n in [0, 1, 5, 16, 17, 1000] {
            let mut order = interleaved(n);
            // Its first half reaches across the whole range.
            if n >= 2 * INTERLEAVE {
                assert!(order[..n / 2].iter().any(|&i| i >= n - INTERLEAVE), "{n}");
            }
            order.sort_unstable();
            assert_eq!(order, (0..n).collect::<Vec<_>>(), "{n}");
        }
    }

    #[test]
    fn extra_sample_sets_are_independent_draws_of_the_same_coefficients() {
        // A split light's own set (draw 1) against the set every light reads (draw 0): other
        // samples, the same expectation.
        let t = table3_light0();
        let rect = t.light.rect();
        let sums = |draw: u32| -> (Vec<Vec2>, Vec<f64>) {
            let (planes, n) = t.trace(72, 1, draw, true);
            let inv = 1.0 / n as f32;
            let c = (0..t.pixels.len())
                .map(|i| planes[0].coefficient(i, &rect, inv).0 as f64)
                .collect();
            (planes[0].points.to_vec(), c)
        };
        let (points0, c0) = sums(0);
        let (points1, c1) = sums(1);
        let shared = points0.iter().zip(&points1).filter(|(a, b)| a == b).count();
        assert!(
            shared * 100 < points0.len(),
            "{shared} of {} points alike",
            points0.len()
        );
        let total: f64 = c0.iter().sum();
        let diff: f64 = c0.iter().zip(&c1).map(|(a, b)| a - b).sum();
        // The two sums differ by their samples' noise alone: per pixel the half-differences
        // measure it; summed over the pixels the relative difference is far under 1 %.
        assert!(total > 0.0);
        assert!(
            (diff / total).abs() < 0.005,
            "sums {total} and {}",
            total - diff
        );
        // Not the same numbers: the pixels' values differ.
        let differing = c0.iter().zip(&c1).filter(|(a, b)| a != b).count();
        assert!(differing * 2 > c0.iter().filter(|c| **c != 0.0).count());
    }
}
