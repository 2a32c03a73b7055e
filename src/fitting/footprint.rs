//! Per-pixel footprints on a light's plane (METHOD §5 step 9): for each pixel, where its
//! lobe's sample rays land on the plane and with what weight. The reflection coefficient of the
//! pixel for any rectangle on the plane is then a sum over the samples inside it, so the
//! radiance and edge searches never trace a ray.

use glam::Vec2;
use rayon::prelude::*;

use super::light_plane::{reflected_sample, LightPlane};
use super::rect::Rect;
use crate::optics::ReflectionModel;
use crate::random::Rng;
use crate::render::{trace, SceneHit};
use crate::scene_in::Scene;

/// Stream tag of the footprints' random numbers: distinct from the renderer's (which uses the
/// bare pixel index), so a fit of a photo rendered with the same seed does not reuse the
/// photo's own noise.
const FOOTPRINT_STREAM: u64 = 2 << 48;

/// The samples of one pixel that landed on the plane.
#[derive(Clone, Debug, Default)]
pub struct Footprint {
    /// Pixel index (`y * width + x`).
    pub pixel: u32,
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

/// Computes the footprints of `pixels` on `plane`, `samples` lobe samples each, in parallel.
/// Each pixel draws from its own random stream (seed, pixel), so the result does not depend on
/// the number of threads.
pub fn footprints(
    scene: &Scene,
    model: &ReflectionModel,
    plane: &LightPlane,
    pixels: &[u32],
    width: u32,
    height: u32,
    samples: u32,
    seed: u64,
) -> Vec<Footprint> {
    pixels
        .par_iter()
        .map(|&pixel| footprint(scene, model, plane, pixel, width, height, samples, seed))
        .collect()
}

/// The footprint of one pixel. Mirrors the renderer's pixel sample: a jittered camera ray
/// that misses the water, or a lobe sample below the surface, counts as a sample of weight 0.
#[allow(clippy::too_many_arguments)]
pub fn footprint(
    scene: &Scene,
    model: &ReflectionModel,
    plane: &LightPlane,
    pixel: u32,
    width: u32,
    height: u32,
    samples: u32,
    seed: u64,
) -> Footprint {
    let mut rng = Rng::new(seed, FOOTPRINT_STREAM | pixel as u64);
    let (x, y) = (pixel % width, pixel / width);
    let mut fp = Footprint {
        pixel,
        samples,
        ..Default::default()
    };
    for _ in 0..samples {
        let Some((start, sample)) = reflected_sample(scene, model, x, y, width, height, &mut rng)
        else {
            continue;
        };
        if let SceneHit::Surface(hit) = trace(scene, &[], start, sample.wi, 0.0) {
            if plane.contains_triangle(scene, hit.triangle) {
                fp.points.push(plane.coords(start + sample.wi * hit.t));
                fp.weights.push(sample.weight);
            }
        }
    }
    fp
}
