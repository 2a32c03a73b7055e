//! Per-pixel footprints on a light's plane (method §5 step 9): for each pixel, where its
//! lobe's sample rays land on the plane and with what weight. The reflection coefficient of the
//! pixel for any rectangle on the plane is then a sum over the samples inside it, so the
//! radiance and edge searches never trace a ray.

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use super::light_plane::{jittered, LightPlane};
use super::rect::Rect;
use super::PIXELS_PER_TASK;
use crate::optics::ReflectionModel;
use crate::random::Rng;
use crate::render::{reflected_hits_of, WaterPoint};
use crate::scene_in::Scene;
use crate::tracing::PACKET_RAYS;
use crate::water_model::{ExactSurface, WaterModel};

/// Stream tag of the footprints' random numbers: distinct from the renderer's (which uses the
/// bare pixel index), so a fit of a photo rendered with the same seed does not reuse the
/// photo's own noise.
const FOOTPRINT_STREAM: u64 = 2 << 48;

/// The samples of one pixel (or of a small box of pixels around it) that landed on the plane.
#[derive(Clone, Debug, Default)]
pub struct Footprint {
    /// Pixel index (`y * width + x`) of the box's centre.
    pub pixel: u32,
    /// The box is the (2 radius + 1)^2 pixels centred on `pixel`: camera rays are jittered
    /// uniformly over all of it, so the footprint models the box's mean value
    /// ([`Footprint::observed`]).
    pub radius: u32,
    /// Plane coordinates of the samples that hit the plane first.
    pub points: Vec<Vec2>,
    /// Their lobe weights (`f cos / pdf`, Fresnel included).
    pub weights: Vec<f32>,
    /// Samples drawn in all (hits or not): the divisor of every estimate.
    pub samples: u32,
}

impl Footprint {
    /// The reflection coefficient `c(p; rect)`: the mean over all samples of the weight of
    /// those landing inside `rect`.
    pub fn coefficient(&self, rect: &Rect) -> f32 {
        let sum: f64 = self
            .points
            .iter()
            .zip(&self.weights)
            .filter(|(p, _)| rect.contains(**p))
            .map(|(_, &w)| w as f64)
            .sum();
        (sum / self.samples.max(1) as f64) as f32
    }

    /// `c(p)` with the whole plane lit (paper eq. 7's assumption at the brightest pixel).
    pub fn whole_plane(&self) -> f32 {
        let sum: f64 = self.weights.iter().map(|&w| w as f64).sum();
        (sum / self.samples.max(1) as f64) as f32
    }

    /// The photo's value this footprint models: the mean radiance over its box.
    pub fn observed(&self, photo: &crate::photo_in::Photo) -> [f32; 3] {
        let (w, r) = (photo.width, self.radius as i32);
        let mut sum = [0f32; 3];
        let mut count = 0;
        for dy in -r..=r {
            for dx in -r..=r {
                if let Some(q) = super::observation::neighbour(self.pixel, dx, dy, w, photo.height)
                {
                    let c = photo.radiance[q as usize];
                    for k in 0..3 {
                        sum[k] += c[k];
                    }
                    count += 1;
                }
            }
        }
        sum.map(|s| s / count.max(1) as f32)
    }

    /// The weighted mean landing point: where the lobe's centre lands. `None` without hits.
    pub fn centroid(&self) -> Option<Vec2> {
        let total: f32 = self.weights.iter().sum();
        if total <= 0.0 {
            return None;
        }
        let s = self
            .points
            .iter()
            .zip(&self.weights)
            .fold(Vec2::ZERO, |acc, (p, &w)| acc + *p * w);
        Some(s / total)
    }
}

/// Computes the footprints of `probes` (centre pixel, box radius) on `plane`, `samples` lobe
/// samples each, in parallel, the water as `water_model` has it.
/// Each pixel draws from its own random stream (seed, pixel), so the result does not depend on
/// the number of threads.
#[allow(clippy::too_many_arguments)]
pub fn footprints(
    water_model: &dyn WaterModel,
    scene: &Scene,
    model: &ReflectionModel,
    plane: &LightPlane,
    probes: &[(u32, u32)],
    width: u32,
    height: u32,
    samples: u32,
    seed: u64,
) -> Vec<Footprint> {
    probes
        .par_iter()
        .with_max_len(PIXELS_PER_TASK)
        .map(|&(pixel, radius)| {
            footprint_with(
                water_model,
                scene,
                model,
                plane,
                (pixel, radius),
                width,
                height,
                samples,
                seed,
            )
        })
        .collect()
}

/// The footprint of one pixel box (`probe` = centre pixel, radius; the box must lie inside the
/// image) over the scene's water mesh ([`ExactSurface`]). Mirrors the renderer's pixel sample:
/// a jittered camera ray that misses the water, or a lobe sample below the surface, counts as
/// a sample of weight 0.
#[allow(clippy::too_many_arguments)]
pub fn footprint(
    scene: &Scene,
    model: &ReflectionModel,
    plane: &LightPlane,
    probe: (u32, u32),
    width: u32,
    height: u32,
    samples: u32,
    seed: u64,
) -> Footprint {
    footprint_with(
        &ExactSurface,
        scene,
        model,
        plane,
        probe,
        width,
        height,
        samples,
        seed,
    )
}

/// [`footprint`] with the water as `water_model` has it.
#[allow(clippy::too_many_arguments)]
pub fn footprint_with(
    water_model: &dyn WaterModel,
    scene: &Scene,
    model: &ReflectionModel,
    plane: &LightPlane,
    probe: (u32, u32),
    width: u32,
    height: u32,
    samples: u32,
    seed: u64,
) -> Footprint {
    let (pixel, radius) = probe;
    let mut rng = Rng::new(
        seed,
        FOOTPRINT_STREAM | (radius as u64) << 40 | pixel as u64,
    );
    let (x, y) = (pixel % width, pixel / width);
    let mut fp = Footprint {
        pixel,
        radius,
        samples,
        ..Default::default()
    };
    let side = 2 * radius + 1;
    // The samples in runs of a packet: their numbers drawn in order (each sample's box
    // pixel, jitter and lobe pair, whatever it hits), their camera rays traced together, then
    // their reflected rays, which leave the pixel's water in nearly one direction.
    let mut positions = [Vec2::ZERO; PACKET_RAYS];
    let mut pairs = [Vec2::ZERO; PACKET_RAYS];
    let mut water = [None; PACKET_RAYS];
    let mut points = [WaterPoint::default(); PACKET_RAYS];
    let mut wis = [Vec3::ZERO; PACKET_RAYS];
    let mut limits = [0.0f32; PACKET_RAYS];
    let mut lobe = [0.0f32; PACKET_RAYS];
    let mut hits = [None; PACKET_RAYS];
    let mut left = samples as usize;
    while left > 0 {
        let n = left.min(PACKET_RAYS);
        left -= n;
        for j in 0..n {
            // The box's pixels are equally likely: the mean of their values is modelled.
            let (bx, by) = if radius == 0 {
                (x, y)
            } else {
                let k = rng.next_u32() % (side * side);
                (
                    (x + k % side).saturating_sub(radius),
                    (y + k / side).saturating_sub(radius),
                )
            };
            let (jx, jy) = jittered(bx, by, &mut rng);
            positions[j] = Vec2::new(jx, jy);
            pairs[j] = Vec2::new(rng.next_f32(), rng.next_f32());
        }
        water_model.water_points(scene, &positions[..n], width, height, &mut water[..n]);
        let mut m = 0;
        for (water, &u) in water[..n].iter().zip(&pairs) {
            let Some(water) = water else {
                continue;
            };
            let Some(sample) = water_model.reflect(water, model, u) else {
                continue;
            };
            // A ray that cannot reach the plane cannot land on it: no need to trace it, and
            // one that can need not look beyond it (a thousandth further: the face's
            // triangles lie within a ten-thousandth of the distance of its plane). Area
            // lights already in the scene are not geometry and do not occlude: the fit asks
            // what a light on the plane would show, and an existing light coplanar with its
            // wall must not hide the wall (it would, by rounding, for about half the rays).
            let Some(t_plane) = plane.distance(water.start, sample.wi) else {
                continue;
            };
            points[m] = *water;
            wis[m] = sample.wi;
            limits[m] = t_plane * 1.001;
            lobe[m] = sample.weight;
            m += 1;
        }
        let hits = &mut hits[..m];
        reflected_hits_of(scene, &points[..m], &wis[..m], &limits[..m], hits);
        for (((water, wi), weight), hit) in points.iter().zip(&wis).zip(&lobe).zip(hits.iter()) {
            if let Some(hit) = hit {
                if plane.contains_triangle(scene, hit.triangle) {
                    fp.points.push(plane.coords(water.start + *wi * hit.t));
                    fp.weights.push(*weight);
                }
            }
        }
    }
    fp
}
