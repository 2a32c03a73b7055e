//! `fit` on glTF files we did not write loses nothing. Each published sample in
//! `tests/data/gltf-real/` gets a camera, a water plane and a wall appended
//! (`common::augment`); a small photo of that scene with a truth light is rendered; `fit` then
//! runs on the augmented scene without the light. The output must keep every JSON value of the
//! ORIGINAL published file at the same path, every original buffer's bytes as a prefix, and
//! the Khronos glTF-Validator must report no error or warning the original did not have.
//!
//! Needs `node` and `npm ci --prefix tests/validator`.

mod common;

use std::path::Path;

use common::cli::fit_args;
use common::gltf_builder::write_json;
use common::gltf_check::{self, real_files, REAL};
use common::json::read_json;
use common::{augment, fit_case, validator};

#[test]
fn published_samples_keep_every_value_and_byte_through_fit() {
    let files = real_files();
    assert_eq!(files.len(), 9, "{files:?}");
    let dir = common::temp_dir("gltf-real-fit");
    let side = 96;
    for original in &files {
        let stem = original.file_stem().unwrap().to_str().unwrap();
        let sub = dir.join(stem);
        std::fs::create_dir(&sub).unwrap();
        let published = read_json(original);
        let scene = sub.join("augmented.gltf");
        write_json(&scene, &augment::augment(&published, false));
        let truth = sub.join("truth.gltf");
        write_json(&truth, &augment::augment(&published, true));
        let photo = sub.join("photo.png");
        fit_case::render_photo_from(&truth, Some(augment::CAMERA), &photo, side, side, 4);

        let out = sub.join("out.gltf");
        let report = sub.join("report.json");
        let (ok, _, stderr) = common::run_cli(&fit_args(
            &scene,
            &photo,
            &out,
            &report,
            &["--camera", augment::CAMERA],
        ));
        assert!(ok, "{stem}: fit failed: {stderr}");
        let r = read_json(&report);
        assert!(
            !r["lights"].as_array().unwrap().is_empty(),
            "{stem}: no light fitted: {stderr}"
        );
        // Against the ORIGINAL published file: nothing lost, nothing changed.
        gltf_check::assert_keeps_everything(original, &out);
        // The light really is in the output.
        let doc = gltf_check::load(&out);
        assert!(
            doc.json["extensions"]["EXT_lights_area"]["lights"]
                .as_array()
                .is_some_and(|l| !l.is_empty()),
            "{stem}: no EXT_lights_area light in the output"
        );
        validator::assert_no_new_problems(original, &out);
    }
    // Sanity: the validator baseline is as published (so "no new problems" means something).
    let count = |name: &str, severity_code: fn(&str) -> bool| -> usize {
        validator::validator_problems(&Path::new(REAL).join(name))
            .iter()
            .filter(|((code, _), _)| severity_code(code))
            .map(|(_, n)| n)
            .sum()
    };
    assert_eq!(count("BoxTextured_pbrSpecularGlossiness.gltf", |_| true), 1);
    assert_eq!(count("SimpleSkin.gltf", |_| true), 2);
    std::fs::remove_dir_all(&dir).unwrap();
}
