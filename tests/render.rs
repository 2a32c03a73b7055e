//! The renderer is deterministic: the same seed gives the same image whatever the thread count.

mod common;

use common::threads::on_threads;
use streaklight::render::{render, RenderOptions};
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
