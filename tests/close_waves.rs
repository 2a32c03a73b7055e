//! The statistical water model in the paper's close geometry (camera 0.2 m above the water,
//! Table 1's light on a wall 10 m away, its reflections 0.4-1 m in front of the camera):
//! the model's expected light against brute force over wave fields, and where the sample
//! photos' light goes (docs/method.md §10).
//!
//! The brute force traces the ripples themselves, not a mesh of them: each camera ray is
//! followed to the height field (Newton's method on the field's own heights and gradient),
//! reflected there by the scene's microfacet lobe about the field's normal, and counted where
//! it meets the light. Over a realisation of the samples' ripples this is the render a perfect
//! mesh would give; with the sample meshes' prefilter applied to the field (their grid's
//! spacing, which grows with the distance from the camera) it is the sample photos' render.

mod common;

use common::pipeline::{sample_photo, sample_scene};
use common::water::flattened;
use glam::{DVec3, Vec2, Vec3};
use rayon::prelude::*;
use streaklight::optics::ReflectionModel;
use streaklight::random::Rng;
use streaklight::render::{render_with_lights, RenderOptions};
use streaklight::samples::streak_slopes::water_pixels;
use streaklight::samples::{self, ripples_of, water_surface::GridSpec, water_surface::RippleField};
use streaklight::scene_in::{AreaLight, Scene};
use streaklight::water_model::{water_statistics, StatisticalSurface, WaterModel};

/// How far from the camera (horizontally) the comparisons count the water. Farther out the
/// water holds little of Table 1's light (under 1 % of the model's, checked below), and the
/// ripples' slopes are steep against a camera ray a couple of degrees above the water, where
/// the brute force has to step along each ray. Both sides of each comparison count the same
/// pixels.
const FARTHEST_WATER: f32 = 5.0;

/// The pixels of a `w` x `h` image whose centre ray meets the mean water level within
/// [`FARTHEST_WATER`] of the camera (horizontally), as indices `y * w + x`.
fn near_water(scene: &Scene, w: u32, h: u32) -> Vec<u32> {
    let level = -scene.origin.y as f32;
    let cam = scene.camera.position;
    (0..w * h)
        .filter(|&i| {
            let d = scene
                .camera
                .direction((i % w) as f32 + 0.5, (i / w) as f32 + 0.5, w, h);
            let t = (level - cam.y) / d.y;
            d.y < 0.0 && (d * t).with_y(0.0).length() < FARTHEST_WATER
        })
        .collect()
}

/// The flux (channel 0, summed over `pixels` of a `w` x `h` image, each pixel the mean of
/// `spp` jittered rays) of `light` reflected by the height field `field` (world metres,
/// mean level y = 0), traced as the module doc says, with the sample meshes' prefilter of
/// `grid` when given. Also the rays whose Newton steps did not meet the field.
#[allow(clippy::too_many_arguments)]
fn traced_flux(
    scene: &Scene,
    light: &AreaLight,
    field: &RippleField,
    grid: Option<&GridSpec>,
    (w, h): (u32, u32),
    pixels: &[u32],
    spp: u32,
    seed: u64,
) -> (f64, usize) {
    let model = ReflectionModel::new(scene.water.gloss, scene.water.ior);
    let origin = scene.origin;
    let cam = scene.camera.position;
    // Height and gradient at a point of the scene frame, prefiltered as the mesh is there.
    let heights = |p: Vec3| {
        let world = origin + p.as_dvec3();
        let (dx, dz) = grid.map_or((0.0, 0.0), |g| g.prefilter_at(g.eye_z - world.z));
        field.sample(world.x, world.z, dx, dz)
    };
    // No height exceeds the ripples' summed amplitudes.
    let crest: f64 = field.ripples().iter().map(|r| r.amplitude).sum();
    // The ray's height above the field at `t`, and its derivative.
    let above = |o: Vec3, d: Vec3, t: f32| {
        let p = o + d * t;
        let (hh, hx, hz) = heights(p);
        (
            origin.y + p.y as f64 - hh,
            d.y as f64 - (hx * d.x as f64 + hz * d.z as f64),
        )
    };
    // Where the ray first meets the field: Newton from the mean level, which converges where
    // the ray is steep against the slopes; else steps of 4 mm from above the crests, to the
    // first step below the field, then bisection.
    let first_hit = |o: Vec3, d: Vec3, crest: f64| -> Option<f32> {
        let mut t = ((-origin.y) as f32 - o.y) / d.y;
        for _ in 0..8 {
            let (g, slope) = above(o, d, t);
            t -= (g / slope) as f32;
        }
        if above(o, d, t).0.abs() < 1e-6 {
            return Some(t);
        }
        let level = |y: f64| ((y - origin.y) as f32 - o.y) / d.y;
        let (start, end) = (level(crest), level(-crest));
        let step = 0.004 / d.with_y(0.0).length();
        let mut a = start;
        while a < end {
            let b = a + step;
            if above(o, d, b).0 < 0.0 {
                let (mut lo, mut hi) = (a, b);
                for _ in 0..40 {
                    let mid = 0.5 * (lo + hi);
                    if above(o, d, mid).0 < 0.0 {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                return Some(hi);
            }
            a = b;
        }
        None
    };
    pixels
        .par_chunks(w as usize)
        .enumerate()
        .map(|(chunk, pixels)| {
            let mut rng = Rng::new(seed, chunk as u64);
            let (mut sum, mut missed) = (0.0f64, 0usize);
            for &i in pixels {
                for _ in 0..spp {
                    let x = (i % w) as f32 + rng.next_f32();
                    let y = (i / w) as f32 + rng.next_f32();
                    let d = scene.camera.direction(x, y, w, h);
                    let Some(t) = first_hit(cam, d, crest) else {
                        missed += 1;
                        continue;
                    };
                    let p = cam + d * t;
                    let (_, hx, hz) = heights(p);
                    let n = DVec3::new(-hx, 1.0, -hz).normalize().as_vec3();
                    let u = Vec2::new(rng.next_f32(), rng.next_f32());
                    let Some(s) = model.sample(n, -d, u) else {
                        continue;
                    };
                    if light.intersect(p, s.wi, 0.0, f32::INFINITY).is_some() {
                        sum += (s.weight * light.radiance[0]) as f64 / spp as f64;
                    }
                }
            }
            (sum, missed)
        })
        .reduce(|| (0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
}

/// The statistical model's expected light in the close geometry is the mean over wave fields
/// of their light. Brute force (module doc) over 24 realisations of the samples' ripples
/// (`samples::ripples_of`, seeds 1-24: 24 ripples of 3-50 cm, rms slope 0.05), against the
/// model's expected image of Table 1's light at each field's own slope variances, both over
/// the water within 5 m of the camera:
/// - a field traced as it is (stationary, as real water is) holds on average 0.99 of the
///   expectation (measured when this was written: 0.994, each field 0.90-1.07 about it, the
///   realisation's long waves; the mean of 24 is known to 0.9 %);
/// - the same fields with the sample meshes' prefilter hold 6 % less (4.3-7.2 % on each
///   field), as the sample photos do. The prefilter's scale grows with the distance from the
///   camera, so the short ripples' slopes fade along the streak: its near end keeps them, its
///   far end loses them. The model has one slope variance for the whole water, and a field
///   whose slopes change from the near end of a streak to its far end does not spread its
///   light as the model's waves do;
/// - Table 1's photo is its own field (seed 2018) traced with the prefilter, to 1 % (0.2 %
///   when this was written): the brute force is the renderer's photo.
///
/// So the statistical fits of the close-geometry sample photos come out low (Table 1's by 5 %
/// on average over 16 fields, `cargo bench --bench realisations`) because of how the samples'
/// water is meshed, not because of the model.
#[test]
fn close_to_the_water_the_model_is_the_mean_over_wave_fields() {
    let scene = flattened(sample_scene("table1-truth.gltf", None));
    let light = &scene.area_lights[0];
    let (w, h) = (300, 300);
    let pixels = near_water(&scene, w, h);
    let on_water = water_pixels(&scene, w, h);
    let grid = samples::water_grid();
    let stats = water_statistics(&scene, w, h).unwrap();
    let axis = [stats.surface.along.x as f64, stats.surface.along.z as f64];
    let expected = |field: &RippleField| {
        let v = field.slope_variances(axis);
        let water = StatisticalSurface {
            surface: stats.surface,
            waves: [v.along as f32, v.across as f32],
        };
        let image = render_with_lights(
            &scene,
            std::slice::from_ref(light),
            &RenderOptions {
                width: w,
                height: h,
                samples_per_pixel: 64,
                water: Some(&water as &dyn WaterModel),
                ..Default::default()
            },
        )
        .unwrap();
        let flux = |pixels: &mut dyn Iterator<Item = usize>| {
            pixels.map(|i| image.pixels[i][0] as f64).sum::<f64>()
        };
        let near = flux(&mut pixels.iter().map(|&i| i as usize));
        let all = flux(&mut (0..on_water.len()).filter(|&i| on_water[i]));
        assert!(
            near > 0.99 * all,
            "{near} of {all} within {FARTHEST_WATER} m"
        );
        near
    };
    let (mut stationary, mut prefiltered) = (Vec::new(), Vec::new());
    for seed in 1..=24u64 {
        let field = ripples_of(seed);
        let model = expected(&field);
        let (a, missed_a) = traced_flux(&scene, light, &field, None, (w, h), &pixels, 2, seed);
        let (b, missed_b) =
            traced_flux(&scene, light, &field, Some(&grid), (w, h), &pixels, 2, seed);
        println!(
            "seed {seed}: stationary / expected {:.4}, prefiltered {:.4} ({missed_a} and \
             {missed_b} rays missed the field)",
            a / model,
            b / model
        );
        assert!(missed_a + missed_b < pixels.len() / 1000, "seed {seed}");
        stationary.push(a / model);
        prefiltered.push(b / model);
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let sd =
        |v: &[f64]| (v.iter().map(|x| (x - mean(v)).powi(2)).sum::<f64>() / v.len() as f64).sqrt();
    let lost: Vec<f64> = stationary
        .iter()
        .zip(&prefiltered)
        .map(|(a, b)| a - b)
        .collect();
    println!(
        "stationary: mean {:.4}, sd {:.4}; the prefilter loses {:.4} (from {:.4} to {:.4})",
        mean(&stationary),
        sd(&stationary),
        mean(&lost),
        lost.iter().cloned().fold(f64::INFINITY, f64::min),
        lost.iter().cloned().fold(0.0, f64::max),
    );
    // The mean of 24 fields scattering 4 % each is known to 0.8 %: 2.5 % is three of that.
    assert!(
        (mean(&stationary) - 1.0).abs() < 0.025,
        "{}",
        mean(&stationary)
    );
    assert!((0.03..0.08).contains(&mean(&lost)), "{}", mean(&lost));
    assert!(lost.iter().all(|&l| l > 0.02), "{lost:?}");

    // The photo: its flux per pixel over the same water against its own field's, traced with
    // the prefilter at the photo's size.
    let photo = sample_photo("table1.png");
    let (pw, ph) = (photo.width, photo.height);
    let photo_pixels = near_water(&scene, pw, ph);
    let in_photo = photo_pixels
        .iter()
        .map(|&i| photo.radiance[i as usize][0] as f64)
        .sum::<f64>();
    let (traced, _) = traced_flux(
        &scene,
        light,
        &samples::ripples(),
        Some(&grid),
        (pw, ph),
        &photo_pixels,
        1,
        2018,
    );
    println!(
        "Table 1's photo / its field traced with the prefilter: {:.4}",
        in_photo / traced
    );
    assert!(
        (in_photo / traced - 1.0).abs() < 0.01,
        "{}",
        in_photo / traced
    );
}

/// Table 1's photo against flat water and the model. Over a flat quad the model without
/// waves is the exact model's flat water (Gaussian slopes of the gloss's variance, Smith's
/// masking, against Blinn-Phong and the paper's geometry term), band by band of 20 rows; the
/// exact render of Table 1's light over the photo's own waves is the photo; and those waves
/// reflect 9 % less light than flat water of the same gloss: 15 % less over the nearer half
/// of the streak, 4 % over the farther, the farthest rows brighter than flat water makes them.
/// The model's waves move its flux by under half a percent. Of the 9 %, about 6 is the sample
/// mesh's prefilter and the rest this field's long waves
/// (`close_to_the_water_the_model_is_the_mean_over_wave_fields`).
#[test]
fn close_to_the_water_the_photos_waves_hold_less_light_than_their_expectation() {
    use streaklight::render::{render_with_lights, RenderOptions};
    use streaklight::water_model::{StatisticalSurface, WaterModel};

    let truth = sample_scene("table1-truth.gltf", None);
    let photo = sample_photo("table1.png");
    let (w, h) = (photo.width, photo.height);
    let flat = flattened(sample_scene("table1-truth.gltf", None));
    let lights = &truth.area_lights;
    fn options(w: u32, h: u32, water: Option<&dyn WaterModel>) -> RenderOptions<'_> {
        RenderOptions {
            width: w,
            height: h,
            samples_per_pixel: 64,
            water,
            ..Default::default()
        }
    }
    let surface = water_statistics(&flat, w, h).unwrap().surface;
    let expected = |waves: [f32; 2]| {
        let water = StatisticalSurface { surface, waves };
        render_with_lights(&flat, lights, &options(w, h, Some(&water)))
            .unwrap()
            .pixels
    };
    let statistical = expected([0.0, 0.0]);
    let wavy = expected([2e-3, 1e-3]);
    let exact_flat = render_with_lights(&flat, lights, &options(w, h, None))
        .unwrap()
        .pixels;
    let exact_waves = render_with_lights(&truth, lights, &options(w, h, None))
        .unwrap()
        .pixels;
    // Flux per band of 20 rows over the water.
    let on_water = water_pixels(&flat, w, h);
    let bands = |img: &[[f32; 3]]| {
        let mut out = vec![0f64; (h as usize).div_ceil(20)];
        for (i, p) in img.iter().enumerate() {
            if on_water[i] {
                out[i / w as usize / 20] += (p[0] + p[1] + p[2]) as f64;
            }
        }
        out
    };
    let total = |b: &[f64]| b.iter().sum::<f64>();
    let (p, s, e, ew) = (
        bands(&photo.radiance),
        bands(&statistical),
        bands(&exact_flat),
        bands(&exact_waves),
    );
    let all = total(&e);
    for (k, (sk, ek)) in s.iter().zip(&e).enumerate() {
        if *ek > 0.02 * all {
            println!("rows {}: statistical / exact {:.4}", 20 * k, sk / ek);
            assert!(
                (sk / ek - 1.0).abs() < 0.03,
                "rows {}: {:.4}",
                20 * k,
                sk / ek
            );
        }
    }
    let model = total(&s) / total(&e);
    let slopes = total(&bands(&wavy)) / total(&s);
    let own = total(&ew) / total(&p);
    let waves = total(&p) / total(&e);
    println!(
        "flux: statistical / exact flat {model:.4}, with slopes {slopes:.4}, exact over the \
         photo's waves / photo {own:.4}, photo / exact flat {waves:.4}"
    );
    assert!((model - 1.0).abs() < 0.01, "{model}");
    assert!((slopes - 1.0).abs() < 0.01, "{slopes}");
    assert!((own - 1.0).abs() < 0.005, "{own}");
    assert!((0.87..0.94).contains(&waves), "{waves}");
    // The near rows (the lower half of the streak) lose most.
    let rows_with_light: Vec<usize> = (0..e.len()).filter(|&k| e[k] > 0.02 * all).collect();
    let half = rows_with_light.len() / 2;
    let ratio = |ks: &[usize]| {
        ks.iter().map(|&k| p[k]).sum::<f64>() / ks.iter().map(|&k| e[k]).sum::<f64>()
    };
    let (far, near) = (
        ratio(&rows_with_light[..half]),
        ratio(&rows_with_light[half..]),
    );
    println!("photo / exact flat: far rows {far:.3}, near rows {near:.3}");
    assert!(
        near < 0.9 && far > near + 0.08,
        "far {far:.3}, near {near:.3}"
    );
}
