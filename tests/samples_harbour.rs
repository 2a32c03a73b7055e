//! The harbour samples (`streaklight::samples::harbour`) and the fitting scenes with other
//! waves or flat water: every scene loads with the water, gloss, lights and framing it says,
//! and the committed harbour photos are what their truth scenes render.

mod common;

use glam::Vec3;
use streaklight::photo_in;
use streaklight::photo_out::{self, ImageFormat};
use streaklight::render::{render, render_with_lights, RenderOptions};
use streaklight::samples::harbour::{self, Framing};
use streaklight::samples::{self, SampleWater, Setup};
use streaklight::scene_in::{self, Scene};

use common::pipeline::{sample_photo_path, sample_scenes};

fn load(file: &str) -> Scene {
    scene_in::load(&sample_scenes().join(file), &Default::default()).unwrap()
}

fn water_triangles(scene: &Scene) -> usize {
    scene.is_water.iter().filter(|&&w| w).count()
}

/// Every harbour scene and every other-waves or flat scene: its water is the grid of the
/// waves or one flat quad as the catalogue says, its gloss is the catalogue's (the flat
/// water's matched to the waves' slopes by method §3), and its lights are the truth's.
#[test]
fn fitting_and_truth_scenes_load_as_described() {
    let catalogue = samples::catalogue();
    let grid = |setup: Setup| match setup {
        Setup::Paper => {
            let g = samples::water_grid();
            g.rows * g.columns * 2
        }
        Setup::Harbour(_) => (harbour::grid_rows().len() - 1) * harbour::HARBOUR_COLUMNS * 2,
    };
    let mut harbour_photos = 0;
    for spec in catalogue
        .iter()
        .filter(|s| s.water != SampleWater::Waves || matches!(s.setup, Setup::Harbour(_)))
    {
        let scene = load(&spec.file);
        let expected = match spec.water {
            SampleWater::Flat => 2,
            _ => grid(spec.setup),
        };
        assert_eq!(water_triangles(&scene), expected, "{}", spec.file);
        assert!(
            (scene.water.gloss as f64 / spec.gloss - 1.0).abs() < 1e-3,
            "{}: gloss {} for {}",
            spec.file,
            scene.water.gloss,
            spec.gloss
        );
        assert_eq!(scene.area_lights.len(), spec.lights.len(), "{}", spec.file);
        for (light, truth) in scene.area_lights.iter().zip(&spec.lights) {
            let centre = (light.center.as_dvec3() + scene.origin - truth.center()).length();
            assert!(
                centre < 1e-4,
                "{}: {} is {centre} m off",
                spec.file,
                truth.name
            );
            assert!((light.width() as f64 - truth.width).abs() < 1e-4);
            assert!((light.height() as f64 - truth.height).abs() < 1e-4);
        }
        harbour_photos += usize::from(spec.photo.is_some());
    }
    // Three layouts in two framings, and the pair in frame under a dim sky.
    assert_eq!(harbour_photos, 7);
    // The flat water's roughness matches the waves': alpha^2 = 2 / (e + 2) is the
    // micro-roughness's plus the waves' slope variance over both axes (0.06^2 + 0.04^2).
    let flat = catalogue
        .iter()
        .find(|s| s.file == "harbour-flat.gltf")
        .unwrap();
    let alpha2 = 2.0 / (flat.gloss + 2.0);
    let expected = 2.0 / (harbour::HARBOUR_GLOSS + 2.0) + 0.0036 + 0.0016;
    assert!(
        (alpha2 / expected - 1.0).abs() < 1e-9,
        "{alpha2} vs {expected}"
    );
    let paper_flat = catalogue
        .iter()
        .find(|s| s.file == "scene-flat.gltf")
        .unwrap();
    let alpha2 = 2.0 / (paper_flat.gloss + 2.0);
    let expected = 2.0 / (samples::DEFAULT_GLOSS + 2.0) + 0.05f64.powi(2);
    assert!(
        (alpha2 / expected - 1.0).abs() < 1e-9,
        "{alpha2} vs {expected}"
    );
}

/// In frame, every light's corners are in the photo above the horizon; above the frame,
/// every corner is above the photo's top while its mirror image in the water plane (where
/// its reflection is centred) is inside the photo.
#[test]
fn framings_put_the_lights_in_and_above_the_photo() {
    let size = samples::PHOTO_SIZE;
    for spec in samples::catalogue() {
        let Setup::Harbour(framing) = spec.setup else {
            continue;
        };
        if spec.lights.is_empty() {
            continue;
        }
        let scene = load(&spec.file);
        let inside =
            |x: f32, y: f32| (0.0..size as f32).contains(&x) && (0.0..size as f32).contains(&y);
        for light in &scene.area_lights {
            for (su, sv) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                let corner = light.center + light.half_width * su + light.half_height * sv;
                let world = corner.as_dvec3() + scene.origin;
                let mirror = (world * glam::DVec3::new(1.0, -1.0, 1.0) - scene.origin).as_vec3();
                let (x, y) = scene.camera.project(corner, size, size).unwrap();
                let (mx, my) = scene.camera.project(mirror, size, size).unwrap();
                // The horizon: the projection of a point far along -z at the camera's height.
                let (_, horizon) = scene
                    .camera
                    .project(Vec3::new(0.0, 0.0, -1e5), size, size)
                    .unwrap();
                match framing {
                    Framing::InFrame => {
                        assert!(inside(x, y) && y < horizon, "{}: {x}, {y}", spec.file)
                    }
                    Framing::Above => assert!(y < 0.0, "{}: corner at row {y}", spec.file),
                }
                assert!(inside(mx, my), "{}: mirror at {mx}, {my}", spec.file);
            }
        }
    }
}

/// Sums of linear radiance per channel over `block` x `block` pixel blocks.
fn block_sums(pixels: &[[f32; 3]], width: usize, block: usize) -> Vec<[f64; 3]> {
    let height = pixels.len() / width;
    let (bw, bh) = (width / block, height / block);
    let mut sums = vec![[0.0f64; 3]; bw * bh];
    for (i, p) in pixels.iter().enumerate() {
        let (x, y) = (i % width / block, i / width / block);
        for c in 0..3 {
            sums[y * bw + x][c] += p[c] as f64;
        }
    }
    sums
}

/// How far `small` (a render at a quarter of the photo's size) is from the committed photo
/// `photo`: the L1 difference over 10 x 10 blocks of the small render wholly below the
/// horizon (the reflections, where nothing clips), as a fraction of the photo's total there.
fn reflection_difference(scene: &Scene, small: &[[f32; 3]], photo: &str) -> f64 {
    let quarter = samples::PHOTO_SIZE / 4;
    let committed = photo_in::load(&sample_photo_path(photo), 1.0).unwrap();
    let (_, horizon) = scene
        .camera
        .project(Vec3::new(0.0, 0.0, -1e5), quarter, quarter)
        .unwrap();
    let first_row = (horizon / 10.0).ceil() as usize;
    let a = block_sums(small, quarter as usize, 10);
    let b = block_sums(&committed.radiance, samples::PHOTO_SIZE as usize, 40);
    let blocks_per_row = quarter as usize / 10;
    let (mut diff, mut total) = (0.0, 0.0);
    for (i, (a, b)) in a.iter().zip(&b).enumerate() {
        if i / blocks_per_row < first_row {
            continue;
        }
        for c in 0..3 {
            // A block of the photo holds 16 times the pixels of the small render's.
            diff += (a[c] * 16.0 - b[c]).abs();
            total += b[c];
        }
    }
    assert!(total > 0.0, "{photo}: no reflection below the horizon");
    diff / total
}

/// The committed harbour photos are what their truth scenes render: each is compared with a
/// render at a quarter of its resolution (150 x 150, 64 samples per pixel; rendering them at
/// full size takes minutes) by [`reflection_difference`]. Measured: 2.7 to 5.6 %, the small
/// render's noise; the same lights over the other waves differ from `harbour-pair.png` by
/// far more (asserted: at least twice the bound). Rendering the same scene twice gives the
/// same PNG bytes.
#[test]
fn committed_photos_are_what_the_truth_scenes_render() {
    let quarter = samples::PHOTO_SIZE / 4;
    let options = RenderOptions {
        width: quarter,
        height: quarter,
        samples_per_pixel: 64,
        exposure: samples::PHOTO_EXPOSURE,
        ..Default::default()
    };
    let bound = 0.08;
    for spec in samples::catalogue() {
        let (Setup::Harbour(_), Some(photo)) = (spec.setup, &spec.photo) else {
            continue;
        };
        let scene = load(&spec.file);
        let options = RenderOptions {
            environment: spec.environment,
            ..options.clone()
        };
        let small = render(&scene, &options).unwrap();
        let difference = reflection_difference(&scene, &small.pixels, photo);
        eprintln!("{photo}: blocks differ by {:.2} %", 100.0 * difference);
        assert!(difference < bound, "{photo}: {difference}");
        if photo != "harbour-pair.png" {
            continue;
        }
        let png = |p: &[[f32; 3]]| photo_out::encode(quarter, quarter, p, ImageFormat::Png);
        let again = render(&scene, &options).unwrap();
        assert_eq!(png(&small.pixels), png(&again.pixels), "{photo}");
        let other = load("harbour-other-waves.gltf");
        let wrong = render_with_lights(&other, &scene.area_lights, &options).unwrap();
        let difference = reflection_difference(&scene, &wrong.pixels, photo);
        eprintln!(
            "{photo} against the other waves: {:.2} %",
            100.0 * difference
        );
        assert!(difference > 2.0 * bound, "{difference}");
    }
}

/// The mean surface the statistical water model takes from a wave mesh is the waves' rest
/// level (y = 0 in the world, where the samples put it) whatever the realisation: its normal
/// within 1e-3 rad of up and its height within 5 mm (the waves' heights have an rms of 2 cm).
/// The plane of the camera's hits would lean towards this grazing camera (2 m above the
/// water) by 0.5-0.8 degrees, since it sees the wave faces turned towards it, and turn every
/// reflection by twice that.
#[test]
fn the_mean_surface_of_a_wave_mesh_is_its_rest_level() {
    for file in [
        "harbour-other-waves.gltf",
        "harbour-above.gltf",
        "scene-other-waves.gltf",
    ] {
        let scene = load(file);
        let stats = streaklight::water_model::water_statistics(&scene, 600, 600).unwrap();
        let n = stats.surface.normal;
        let tilt = n.cross(Vec3::Y).length();
        assert!(
            tilt < 1e-3,
            "{file}: the mean plane leans by {tilt} rad ({n:?})"
        );
        let rest = (-scene.origin.y) as f32; // world y = 0 in the camera-centred frame
        let height = stats.surface.point.y - rest;
        assert!(
            height.abs() < 5e-3,
            "{file}: the mean plane is {height} m off the rest level"
        );
        assert!(
            stats.surface.crest > 0.0 && stats.surface.crest < 0.2,
            "{file}: crest {}",
            stats.surface.crest
        );
    }
}
