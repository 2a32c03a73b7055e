//! Small end-to-end `fit` cases: a paper-style scene, a truth light, and a photo of it rendered
//! at low resolution, so the command line can be run in a test within seconds.

use std::path::{Path, PathBuf};

use serde_json::{json, Value};
use streaklight::render::{self, RenderOptions};
use streaklight::scene_in::{self, LoadOptions};

use super::TestScene;

/// Exposure of the test photos (as the samples': light radiance 20 times a Fresnel of a few %).
pub const EXPOSURE: f32 = 0.1;
/// Side of the test photos, in pixels.
pub const SIDE: u32 = 160;

/// The water material with roughness 0.2512, that is Blinn-Phong e = 500.
pub fn water_material() -> Value {
    json!({"name": "water", "pbrMetallicRoughness": {"roughnessFactor": 0.2512, "metallicFactor": 0.0}})
}

/// The truth light of the test scenes: 3 x 3 m on the wall, radiance 20, facing the camera.
pub fn add_truth_light(s: &mut TestScene) {
    s.add_light_facing_z("truth", [0.0, 3.5, 0.01], 3.0, 3.0, [20.0, 20.0, 20.0]);
}

/// Renders the water of the scene file `scene` (with its lights) to the PNG `photo`.
pub fn render_photo(scene: &Path, photo: &Path, width: u32, height: u32, spp: u32) {
    render_photo_from(scene, None, photo, width, height, spp)
}

/// [`render_photo`] from the camera named `camera` (default: the scene's first).
pub fn render_photo_from(
    scene: &Path,
    camera: Option<&str>,
    photo: &Path,
    width: u32,
    height: u32,
    spp: u32,
) {
    let options = LoadOptions {
        camera: camera.map(str::to_owned),
        ..Default::default()
    };
    let loaded = scene_in::load(scene, &options)
        .unwrap_or_else(|e| panic!("loading {}: {e}", scene.display()));
    let image = render::render(
        &loaded,
        &RenderOptions {
            width,
            height,
            samples_per_pixel: spp,
            exposure: EXPOSURE,
            seed: 7,
            ..Default::default()
        },
    )
    .unwrap();
    streaklight::photo_out::write(photo, width, height, &image.pixels).unwrap();
}

/// Renders the scene file `scene` (with its lights) to the PNG `photo` as the sample photos
/// are rendered (256 spp, the samples' exposure, seed 1), at `width` x `height`.
pub fn render_like_samples(scene: &Path, photo: &Path, width: u32, height: u32) {
    let loaded = scene_in::load(scene, &LoadOptions::default())
        .unwrap_or_else(|e| panic!("loading {}: {e}", scene.display()));
    let options = RenderOptions {
        width,
        height,
        samples_per_pixel: streaklight::samples::PHOTO_SPP,
        exposure: streaklight::samples::PHOTO_EXPOSURE,
        seed: 1,
        ..Default::default()
    };
    let image = render::render(&loaded, &options).expect("render");
    streaklight::photo_out::write(photo, width, height, &image.pixels).expect("write the photo");
}

/// A uniform 8-bit RGB PNG.
pub fn uniform_png(path: &Path, width: u32, height: u32, value: u8) {
    let img = image::RgbImage::from_pixel(width, height, image::Rgb([value; 3]));
    img.save(path).unwrap();
}

/// The files of one good case in `dir`: `scene.gltf` (paper setup, no light) and `photo.png`
/// (the same scene with the truth light, rendered). Returns (scene, photo).
pub fn good_case(dir: &Path) -> (PathBuf, PathBuf) {
    let scene = dir.join("scene.gltf");
    let photo = dir.join("photo.png");
    let mut lit = super::paper_setup(Some(water_material()));
    add_truth_light(&mut lit);
    let truth = dir.join("truth.gltf");
    lit.write_gltf(&truth);
    render_photo(&truth, &photo, SIDE, SIDE, 4);
    std::fs::remove_file(&truth).unwrap();
    super::paper_setup(Some(water_material())).write_gltf(&scene);
    (scene, photo)
}
