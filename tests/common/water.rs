//! Water for the water-model tests: a scene's mesh flattened to its mean level, which pixels
//! see the water, the harbour waves' expectation, and the slopes of a wave mesh under the
//! streaks.

use streaklight::render::{camera_hit, render_with_lights, CameraHit, RenderOptions};
use streaklight::scene_in::Scene;
use streaklight::tracing::{Tracer, Triangle};
use streaklight::water_model::{water_statistics, StatisticalSurface};

/// `scene` with its water flattened onto its mean level (world y = 0), normals straight up.
pub fn flattened(mut scene: Scene) -> Scene {
    let level = -scene.origin.y as f32;
    for ((t, n), &w) in scene
        .triangles
        .iter_mut()
        .zip(scene.normals.iter_mut())
        .zip(&scene.is_water)
    {
        if w {
            for v in t.iter_mut() {
                v.y = level;
            }
            *n = [glam::Vec3::Y; 3];
        }
    }
    let triangles: Vec<Triangle> = scene
        .triangles
        .iter()
        .map(|&vertices| Triangle { vertices })
        .collect();
    scene.tracer = Tracer::new(&triangles);
    scene
}

/// Per pixel of a `w` x `h` image, whether the camera ray through its centre meets the
/// water first.
pub fn water_pixels(scene: &Scene, w: u32, h: u32) -> Vec<bool> {
    (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32 + 0.5, (i / w) as f32 + 0.5);
            matches!(camera_hit(scene, &[], x, y, w, h), CameraHit::Water(_))
        })
        .collect()
}

/// The statistical water over `scene`'s mean plane with the harbour waves' own slope
/// variances (the spectrum the harbour samples' meshes are drawn from), for a `w` x `h`
/// image.
pub fn harbour_expectation(scene: &Scene, w: u32, h: u32) -> StatisticalSurface {
    let spectrum = streaklight::samples::harbour_waves::harbour_spectrum();
    StatisticalSurface {
        surface: water_statistics(scene, w, h).unwrap().surface,
        waves: [
            spectrum.rms_slope_along.powi(2) as f32,
            spectrum.rms_slope_across.powi(2) as f32,
        ],
    }
}

/// The pixels of a `w`-wide image `image` among `keep` where `value` passes `share` of its
/// largest value there: a streak's footprint in its expected image.
pub fn footprint(
    image: &[[f32; 3]],
    keep: impl Fn(usize) -> bool,
    value: impl Fn([f32; 3]) -> f32,
    share: f32,
) -> Vec<usize> {
    let peak = (0..image.len())
        .filter(|&i| keep(i))
        .map(|i| value(image[i]))
        .fold(0f32, f32::max);
    (0..image.len())
        .filter(|&i| keep(i) && value(image[i]) >= share * peak)
        .collect()
}

/// The union of the footprints of `scene`'s lights in the harbour waves' expected image
/// ([`harbour_expectation`], 16 rays a pixel, each light alone): the water pixels where a
/// light's image passes 2 % of its peak in its strongest channel.
pub fn streak_footprints(scene: &Scene, w: u32, h: u32) -> Vec<usize> {
    let water = harbour_expectation(scene, w, h);
    let sees_water = water_pixels(scene, w, h);
    let mut union = vec![false; (w * h) as usize];
    for light in &scene.area_lights {
        let options = RenderOptions {
            width: w,
            height: h,
            samples_per_pixel: 16,
            water: Some(&water),
            ..Default::default()
        };
        let image = render_with_lights(scene, std::slice::from_ref(light), &options).unwrap();
        let strongest = |p: [f32; 3]| p[0].max(p[1]).max(p[2]);
        for i in footprint(&image.pixels, |i| sees_water[i], strongest, 0.02) {
            union[i] = true;
        }
    }
    (0..union.len()).filter(|&i| union[i]).collect()
}

/// The slope variances of `scene`'s water mesh (its shading normals against `water`'s mean
/// plane), along and across its axes, over `pixels` of a `w` x `h` image: four camera rays
/// a pixel, each slope the normal's rise over run.
pub fn mesh_slope_variances(
    scene: &Scene,
    water: &StatisticalSurface,
    pixels: &[usize],
    w: u32,
    h: u32,
) -> [f64; 2] {
    let (n0, along, across) = (
        water.surface.normal,
        water.surface.along,
        water.surface.across(),
    );
    let (mut n, mut s, mut s2) = (0f64, [0f64; 2], [0f64; 2]);
    for &i in pixels {
        for k in 0..4u32 {
            let x = (i as u32 % w) as f32 + 0.25 + 0.5 * (k % 2) as f32;
            let y = (i as u32 / w) as f32 + 0.25 + 0.5 * (k / 2) as f32;
            if let CameraHit::Water(p) = camera_hit(scene, &[], x, y, w, h) {
                for (a, axis) in [along, across].into_iter().enumerate() {
                    let slope = -(p.normal.dot(axis) / p.normal.dot(n0)) as f64;
                    s[a] += slope;
                    s2[a] += slope * slope;
                }
                n += 1.0;
            }
        }
    }
    [0, 1].map(|a| s2[a] / n - (s[a] / n).powi(2))
}
