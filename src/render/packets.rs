//! Rays traced in packets ([`crate::tracing::Tracer::closest_hits`]): the camera rays of a
//! pixel, and the reflected rays of a pixel's water points, which run close together.
//!
//! Most of a render's time is its camera rays' (a reflected ray is traced only when it meets
//! a light). A camera ray's random numbers follow the ones before it in the pixel's stream, and how
//! many those are depends on what each ray saw (a ray that meets the water draws its lobe
//! samples, one that meets a wall draws nothing more). The packet guesses that every ray meets
//! the water, traces the rays where that puts them, and keeps each result only while the
//! guess held: the pixel's generator, after shading a ray, must be where the guess put the
//! next ray. From the first ray it did not hold for, the rest of the pixel is traced one ray
//! at a time. So every pixel is the one tracing ray by ray gives, to the bit.

use glam::{Vec2, Vec3};

use super::{
    nearest_light, pixel_sample, shade, water_point_of, CameraHit, PixelSample, WaterPoint,
    LIGHT_TIE_MARGIN,
};
use crate::optics::ReflectionModel;
use crate::random::Rng;
use crate::scene_in::{AreaLight, Scene};
use crate::tracing::{Hit, PACKET_RAYS};
use crate::water_model::WaterModel;

/// [`super::camera_hit`] for each image position of `positions` (pixel units), into `hits`
/// (as long), the rays traced in packets.
pub(super) fn camera_hits(
    scene: &Scene,
    lights: &[AreaLight],
    positions: &[Vec2],
    (w, h): (u32, u32),
    hits: &mut [CameraHit],
) {
    let origin = scene.camera.position;
    for (positions, hits) in positions
        .chunks(PACKET_RAYS)
        .zip(hits.chunks_mut(PACKET_RAYS))
    {
        let n = positions.len();
        let mut dirs = [Vec3::ZERO; PACKET_RAYS];
        let mut light = [None; PACKET_RAYS];
        let mut tmax = [f32::INFINITY; PACKET_RAYS];
        for r in 0..n {
            dirs[r] = scene.camera.direction(positions[r].x, positions[r].y, w, h);
            light[r] = nearest_light(lights, origin, dirs[r], 0.0);
            if let Some((_, t)) = light[r] {
                tmax[r] = t * (1.0 - LIGHT_TIE_MARGIN);
            }
        }
        let mut found = [None; PACKET_RAYS];
        scene
            .tracer
            .closest_hits(origin, &dirs[..n], 0.0, &tmax[..n], &mut found[..n]);
        for r in 0..n {
            hits[r] = match (&found[r], light[r]) {
                (Some(hit), _) => match water_point_of(scene, dirs[r], hit) {
                    Some(water) => CameraHit::Water(water),
                    None => CameraHit::Other,
                },
                (None, Some((i, _))) => CameraHit::Light(i),
                (None, None) => CameraHit::Other,
            };
        }
    }
}

/// [`super::camera_hit`]'s water point, without lights, for each image position of `positions`
/// (pixel units, fractional), into `points` (as long; `None` where the ray sees anything
/// else first, or nothing). The rays are traced in packets ([`crate::tracing::Tracer::closest_hits`]):
/// a pixel's camera rays run close together.
pub fn camera_water_points(
    scene: &Scene,
    positions: &[Vec2],
    width: u32,
    height: u32,
    points: &mut [Option<WaterPoint>],
) {
    let origin = scene.camera.position;
    for (positions, points) in positions
        .chunks(PACKET_RAYS)
        .zip(points.chunks_mut(PACKET_RAYS))
    {
        let n = positions.len();
        let mut dirs = [Vec3::ZERO; PACKET_RAYS];
        for (dir, p) in dirs.iter_mut().zip(positions) {
            *dir = scene.camera.direction(p.x, p.y, width, height);
        }
        let mut hits = [None; PACKET_RAYS];
        scene.tracer.closest_hits(
            origin,
            &dirs[..n],
            0.0,
            &[f32::INFINITY; PACKET_RAYS][..n],
            &mut hits[..n],
        );
        for ((point, hit), dir) in points.iter_mut().zip(&hits).zip(&dirs) {
            *point = hit
                .as_ref()
                .and_then(|hit| water_point_of(scene, *dir, hit));
        }
    }
}

/// [`WaterPoint::reflected_hit`] of ray `i` leaving `points[i]` in direction `wi[i]` within
/// `tmax[i]`, into `hits[i]` (all as long as `points`). The exact model's rays, which leave
/// nearby points in nearly one direction when the points are a pixel's, are traced in
/// packets ([`crate::tracing::Tracer::closest_hits_from`]).
pub fn reflected_hits_of(
    scene: &Scene,
    points: &[WaterPoint],
    wi: &[Vec3],
    tmax: &[f32],
    hits: &mut [Option<Hit>],
) {
    if points.iter().all(|p| p.clear == 0.0) {
        for (((points, wi), tmax), hits) in points
            .chunks(PACKET_RAYS)
            .zip(wi.chunks(PACKET_RAYS))
            .zip(tmax.chunks(PACKET_RAYS))
            .zip(hits.chunks_mut(PACKET_RAYS))
        {
            let mut origins = [Vec3::ZERO; PACKET_RAYS];
            for (origin, point) in origins.iter_mut().zip(points) {
                *origin = point.start;
            }
            let origins = &origins[..points.len()];
            scene.tracer.closest_hits_from(origins, wi, 0.0, tmax, hits);
        }
    } else {
        for (((point, &wi), &tmax), hit) in points.iter().zip(wi).zip(tmax).zip(hits) {
            *hit = point.reflected_hit(scene, wi, tmax);
        }
    }
}

/// The sum of pixel (`x`, `y`)'s camera rays' values under a black night (no environment),
/// and how many reflected rays they traced: what [`super::pixel_sample`] gives ray by ray,
/// the rays traced in packets while the guess of the module doc holds.
#[allow(clippy::too_many_arguments)]
pub(super) fn black_night_pixel(
    scene: &Scene,
    lights: &[AreaLight],
    model: &ReflectionModel,
    water_model: Option<&dyn WaterModel>,
    (x, y): (u32, u32),
    (camera_rays, lobe_samples): (u32, u32),
    (w, h): (u32, u32),
    rng: &mut Rng,
) -> ([f64; 3], u64) {
    let strata = (camera_rays as f32).sqrt() as u32;
    let sample = |stratum| PixelSample {
        x,
        y,
        stratum,
        strata,
        lobe_samples,
    };
    let mut sum = [0f64; 3];
    let mut traced = 0u64;
    let mut add = |(value, n): ([f32; 3], u32)| {
        traced += n as u64;
        for c in 0..3 {
            sum[c] += value[c] as f64;
        }
    };
    let mut positions = [Vec2::ZERO; PACKET_RAYS];
    let mut after = [const { None::<Rng> }; PACKET_RAYS];
    let mut hits = [CameraHit::Other; PACKET_RAYS];
    let mut k = 0;
    let mut guessing = true;
    while k < camera_rays {
        if !guessing {
            add(pixel_sample(
                scene,
                lights,
                model,
                water_model,
                None,
                sample(k),
                w,
                h,
                rng,
            ));
            k += 1;
            continue;
        }
        // Where the next rays go if each before it meets the water and draws its lobe's
        // numbers, and where the generator is after each.
        let n = (camera_rays - k).min(PACKET_RAYS as u32) as usize;
        let mut guess = rng.clone();
        for j in 0..n {
            let (px, py) = sample(k + j as u32).jittered(&mut guess);
            positions[j] = Vec2::new(px, py);
            for _ in 0..2 * lobe_samples {
                guess.next_f32();
            }
            after[j] = Some(guess.clone());
        }
        camera_hits(scene, lights, &positions[..n], (w, h), &mut hits[..n]);
        for j in 0..n {
            let (px, py) = sample(k).jittered(rng);
            add(shade(
                scene,
                lights,
                model,
                water_model,
                None,
                (px, py, hits[j]),
                lobe_samples,
                (w, h),
                rng,
            ));
            k += 1;
            if after[j].as_ref() != Some(&*rng) {
                // This ray drew less than the guess: the rays after it go elsewhere.
                guessing = false;
                break;
            }
        }
    }
    (sum, traced)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::camera_hit;

    /// Pixels that see the water, a light directly, the wall and the sky, each rendered in
    /// packets and ray by ray: the same sums and counts to the bit, for several splits of a
    /// pixel's samples.
    #[test]
    fn a_pixel_in_packets_is_the_pixel_ray_by_ray() {
        let scene = &crate::samples::fixture("table1.png").scene;
        let camera = &scene.camera;
        // A light facing the camera a little above the middle of the view: some pixels see
        // it, the water below reflects it.
        let light = AreaLight {
            name: "test".into(),
            node: 0,
            center: camera.position + camera.forward * 4.0 + camera.up * 0.6,
            half_width: camera.right * 0.8,
            half_height: camera.up * 0.4,
            normal: -camera.forward,
            radiance: [3.0, 2.0, 1.0],
        };
        let lights = [light];
        let model = ReflectionModel {
            gloss: scene.water.gloss,
            ior: scene.water.ior,
            shadowing: Default::default(),
        };
        let (w, h) = (300u32, 300u32);
        let mut seen = [0usize; 3];
        for (camera_rays, lobe_samples) in [(16, 4), (3, 1), (9, 2)] {
            for y in (0..h).step_by(11) {
                for x in (0..w).step_by(11) {
                    match camera_hit(scene, &lights, x as f32 + 0.5, y as f32 + 0.5, w, h) {
                        CameraHit::Water(_) => seen[0] += 1,
                        CameraHit::Light(_) => seen[1] += 1,
                        CameraHit::Other => seen[2] += 1,
                    }
                    let index = (y * w + x) as u64;
                    let mut rng = Rng::new(7, index);
                    let packets = black_night_pixel(
                        scene,
                        &lights,
                        &model,
                        None,
                        (x, y),
                        (camera_rays, lobe_samples),
                        (w, h),
                        &mut rng,
                    );
                    let mut rng = Rng::new(7, index);
                    let strata = (camera_rays as f32).sqrt() as u32;
                    let mut sum = [0f64; 3];
                    let mut traced = 0u64;
                    for k in 0..camera_rays {
                        let sample = PixelSample {
                            x,
                            y,
                            stratum: k,
                            strata,
                            lobe_samples,
                        };
                        let (value, n) = pixel_sample(
                            scene, &lights, &model, None, None, sample, w, h, &mut rng,
                        );
                        traced += n as u64;
                        for c in 0..3 {
                            sum[c] += value[c] as f64;
                        }
                    }
                    assert_eq!(packets, (sum, traced), "pixel ({x}, {y})");
                }
            }
        }
        assert!(
            seen.iter().all(|&n| n > 50),
            "water, light, other: {seen:?}"
        );
    }
}
