//! The renderer is deterministic: the same seed gives the same image whatever the thread
//! count, and a pixel rendered alone is the image's pixel.

mod common;

use common::threads::on_threads;
use streaklight::environment::Environment;
use streaklight::optics::ReflectionModel;
use streaklight::render::{render, render_pixels, RenderOptions};
use streaklight::scene_in::load;

#[test]
fn same_seed_same_image_on_one_and_two_threads() {
    let dir = common::temp_dir("determinism");
    let mut s = common::paper_setup(Some(
        serde_json::json!({"pbrMetallicRoughness": {"roughnessFactor": 0.3}}),
    ));
    s.add_light_facing_z("Light", [-2.5, 3.5, 0.0], 3.0, 3.0, [20.0, 20.0, 5.0]);
    s.write_gltf(&dir.join("d.gltf"));
    let scene = load(&dir.join("d.gltf"), &Default::default()).unwrap();
    let options = RenderOptions {
        width: 64,
        height: 64,
        samples_per_pixel: 8,
        seed: 9,
        ..Default::default()
    };
    let run = |threads: usize| on_threads(threads, || render(&scene, &options).unwrap());
    let one = run(1);
    let two = run(2);
    assert_eq!(one.pixels, two.pixels);
    assert!(
        one.pixels.iter().any(|p| p[0] > 0.0),
        "the image should not be black"
    );
    let other_seed = render(
        &scene,
        &RenderOptions {
            seed: 10,
            ..options.clone()
        },
    )
    .unwrap();
    assert_ne!(one.pixels, other_seed.pixels, "the seed should matter");
}

/// `render_pixels` gives each pixel asked for the value the whole image has there, to the
/// bit, under a black night (the camera rays in packets) and under a sky (one at a time),
/// in any order and with repeats; and under another reflection model than the scene's, the
/// image a scene of that material would give.
#[test]
fn pixels_rendered_alone_are_the_images() {
    let dir = common::temp_dir("render-pixels");
    let scene_with = |roughness: f64, name: &str| {
        let mut s = common::paper_setup(Some(
            serde_json::json!({"pbrMetallicRoughness": {"roughnessFactor": roughness}}),
        ));
        s.add_light_facing_z("Light", [-2.5, 3.5, 0.0], 3.0, 3.0, [20.0, 20.0, 5.0]);
        s.write_gltf(&dir.join(name));
        load(&dir.join(name), &Default::default()).unwrap()
    };
    let scene = scene_with(0.3, "a.gltf");
    let (w, h) = (48u32, 40u32);
    let options = |environment| RenderOptions {
        width: w,
        height: h,
        samples_per_pixel: 8,
        seed: 5,
        environment,
        ..Default::default()
    };
    // The reflection model `render` takes from a scene's material.
    let model_of = |s: &streaklight::scene_in::Scene| ReflectionModel {
        gloss: s.water.gloss,
        ior: s.water.ior,
        shadowing: RenderOptions::default().shadowing,
    };
    // `scene_from`'s image at `pixels` against `render_pixels` of `scene` under its model.
    let check = |scene_from: &streaklight::scene_in::Scene, environment, pixels: &[u32]| {
        let image = render(scene_from, &options(environment)).unwrap();
        let alone = render_pixels(
            &scene,
            &scene.area_lights,
            &model_of(scene_from),
            &options(environment),
            pixels,
        )
        .unwrap();
        let want: Vec<[f32; 3]> = pixels.iter().map(|&p| image.pixels[p as usize]).collect();
        assert_eq!(alone, want, "environment {environment:?}");
        want
    };
    let night = render(&scene, &options(None)).unwrap();
    let brightest = (0..w * h)
        .max_by(|&a, &b| night.pixels[a as usize][0].total_cmp(&night.pixels[b as usize][0]))
        .unwrap();
    let pixels: Vec<u32> = vec![w * h - 1, brightest, 0, 17, 5 * w + 3, 17, 30 * w + 40];
    let sky = Environment {
        sky: [0.3, 0.2, 0.1],
        albedo: 0.4,
    };
    for environment in [None, Some(sky)] {
        let want = check(&scene, environment, &pixels);
        assert!(want.iter().any(|p| p[0] > 0.0), "a lit pixel is asked for");
    }
    // Another gloss: the image of the scene whose material has it.
    let rough = scene_with(0.6, "b.gltf");
    assert_ne!(rough.water.gloss, scene.water.gloss);
    check(&rough, None, &pixels);
}
