//! Classes 5 and 6: no wrong result with exit 0 (an already lit scene, an overflowing nits
//! scale, an IOR no water has, negative EXR values told), and messages in words that name the
//! file, with names escaped and no file's bytes quoted.

use serde_json::{json, Value};

use crate::common::cli::arg;
use crate::support::{case, fit, refused, run_with};

fn edit_scene(path: &std::path::Path, change: impl FnOnce(&mut Value)) {
    let mut doc: Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    change(&mut doc);
    std::fs::write(path, serde_json::to_vec(&doc).unwrap()).unwrap();
}

#[test]
fn fitting_a_scene_streaklight_already_lit_is_refused() {
    let c = case("hostile-lit-twice");
    let lit = c.dir.join("lit.gltf");
    let first = run_with(&fit(&c.scene, &c.photo, &["-o", &arg(&lit)]), &[], 60.0);
    assert_eq!(first.code, Some(0), "{}", first.stderr);
    let again = c.dir.join("again.gltf");
    let ran = refused(
        &fit(&lit, &c.photo, &["-o", &arg(&again)]),
        &[],
        &[&c.dir],
        &[
            "lit.gltf",
            "already holds 1 light(s) that streaklight fitted",
            "streaklight_light_0",
        ],
    );
    assert!(ran.seconds < 1.0, "{} s", ran.seconds);
    assert!(!ran.stderr.contains("load scene"), "{}", ran.stderr);
}

#[test]
fn a_nits_scale_whose_intensity_would_overflow_is_refused() {
    let c = case("hostile-nits");
    let out = arg(&c.dir.join("out.gltf"));
    let args = fit(&c.scene, &c.photo, &["-o", &out, "--nits-scale", "1e30"]);
    refused(&args, &[], &[&c.dir], &["--nits-scale", "at most 1e9"]);
}

#[test]
fn a_material_ior_no_water_has_is_refused_naming_the_material() {
    let c = case("hostile-ior");
    let out = arg(&c.dir.join("out.gltf"));
    for ior in [0.0, 1e30] {
        edit_scene(&c.scene, |doc| {
            doc["materials"][0]["extensions"] = json!({"KHR_materials_ior": {"ior": ior}});
            doc["extensionsUsed"] = json!(["KHR_materials_ior"]);
        });
        let args = fit(&c.scene, &c.photo, &["-o", &out]);
        refused(
            &args,
            &[],
            &[&c.dir],
            &["scene.gltf", "material \"water\"", "1 < IOR <= 3"],
        );
    }
}

#[test]
fn negative_exr_values_are_read_as_zero_with_a_warning() {
    let c = case("hostile-negative-exr");
    let mut img = image::open(&c.photo).unwrap().into_rgb32f();
    for x in 0..10 {
        img.put_pixel(x, 0, image::Rgb([-0.5, 0.1, 0.1]));
    }
    let exr = c.dir.join("photo.exr");
    img.save(&exr).unwrap();
    let ran = run_with(
        &fit(&c.scene, &exr, &["-o", &arg(&c.dir.join("out.gltf"))]),
        &[],
        60.0,
    );
    assert_eq!(ran.code, Some(0), "{}", ran.stderr);
    assert!(
        ran.stderr
            .contains("photo.exr: 10 negative value(s) (the lowest -0.5) were read as 0"),
        "{}",
        ran.stderr
    );
}

#[test]
fn a_far_camera_is_a_camera_problem_and_its_name_is_escaped() {
    let c = case("hostile-far-camera");
    edit_scene(&c.scene, |doc| {
        for node in doc["nodes"].as_array_mut().unwrap() {
            if node.get("camera").is_some() {
                node["name"] = "cam\u{1b}[2J\u{7}".into();
                node["translation"] = json!([1e308, 0.0, 0.0]);
            }
        }
    });
    let args = fit(&c.scene, &c.photo, &["-o", &arg(&c.dir.join("out.gltf"))]);
    let ran = refused(
        &args,
        &[],
        &[&c.dir],
        &["scene.gltf", "the camera", "cam\\u{1b}[2J\\u{7}"],
    );
    assert!(
        !ran.stderr.contains('\u{1b}') && !ran.stderr.contains('\u{7}'),
        "{}",
        ran.stderr
    );
    assert!(!ran.stderr.contains("triangles"), "{}", ran.stderr);
}

#[test]
fn damaged_and_unsupported_photos_get_worded_errors_naming_the_file() {
    let c = case("hostile-photo-words");
    let out = arg(&c.dir.join("out.gltf"));
    // A PNG whose first IDAT byte is changed: its checksum no longer matches.
    let mut png = std::fs::read(&c.photo).unwrap();
    let idat = png.windows(4).position(|w| w == b"IDAT").unwrap();
    png[idat + 6] ^= 0x55;
    let bad = c.dir.join("bad-crc.png");
    std::fs::write(&bad, &png).unwrap();
    let ran = refused(
        &fit(&c.scene, &bad, &["-o", &out]),
        &[],
        &[&c.dir],
        &["bad-crc.png", "damaged"],
    );
    assert!(
        !ran.stderr.contains('{') && !ran.stderr.contains("Crc"),
        "{}",
        ran.stderr
    );
    // A float TIFF whose sample format is one the decoder does not know (32): the decoder's
    // own text is `Unknown(32)`.
    let img = image::open(&c.photo).unwrap().into_rgb32f();
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.write_to(&mut bytes, image::ImageFormat::Tiff).unwrap();
    let mut tiff = bytes.into_inner();
    set_sample_format(&mut tiff, 32);
    let path = c.dir.join("float.tiff");
    std::fs::write(&path, &tiff).unwrap();
    let ran = refused(
        &fit(&c.scene, &path, &["-o", &out]),
        &[],
        &[&c.dir],
        &["float.tiff", "TIFF"],
    );
    assert!(!ran.stderr.contains("Unknown("), "{}", ran.stderr);
}

/// Sets every value of the SampleFormat tag (339) of the first IFD of a little-endian TIFF.
fn set_sample_format(tiff: &mut [u8], value: u16) {
    let u16_at = |b: &[u8], i: usize| u16::from_le_bytes([b[i], b[i + 1]]);
    let u32_at =
        |b: &[u8], i: usize| u32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]) as usize;
    assert_eq!(&tiff[..2], b"II");
    let ifd = u32_at(tiff, 4);
    let mut found = false;
    for k in 0..u16_at(tiff, ifd) as usize {
        let entry = ifd + 2 + 12 * k;
        if u16_at(tiff, entry) == 339 {
            let count = u32_at(tiff, entry + 4);
            let at = if count <= 2 {
                entry + 8
            } else {
                u32_at(tiff, entry + 8)
            };
            for i in 0..count {
                tiff[at + 2 * i..at + 2 * i + 2].copy_from_slice(&value.to_le_bytes());
            }
            found = true;
        }
    }
    assert!(found, "no SampleFormat tag");
}

#[test]
fn an_error_about_a_buffer_never_quotes_the_files_bytes() {
    let c = case("hostile-buffer-text");
    let secret = c
        .dir
        .parent()
        .unwrap()
        .join(format!("secret-{}.txt", std::process::id()));
    std::fs::write(&secret, "TOP SECRET password=hunter2\n").unwrap();
    edit_scene(&c.scene, |doc| {
        doc["buffers"][0]["uri"] =
            format!("../{}", secret.file_name().unwrap().to_str().unwrap()).into();
    });
    let args = fit(&c.scene, &c.photo, &["-o", &arg(&c.dir.join("out.gltf"))]);
    let ran = refused(&args, &[], &[&c.dir], &["scene.gltf", "buffer 0"]);
    std::fs::remove_file(&secret).unwrap();
    assert!(
        !ran.stderr.contains("hunter2") && !ran.stderr.contains("SECRET"),
        "{}",
        ran.stderr
    );
}
