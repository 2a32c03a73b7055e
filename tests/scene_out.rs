//! Tests of the glTF writer (`streaklight::scene_out`, method §7): nothing of the input is
//! lost, the lights read back as written, the emitted extension matches its JSON Schema, and
//! the Khronos glTF-Validator finds no new error or warning in any output. Where the files
//! go (self-contained outputs, refusals) is `scene_out_files.rs`.
//!
//! Needs `node` and `npm ci --prefix tests/validator` for the validator tests.

use std::path::Path;

mod common;

use common::dirs::temp_dir;
use common::gltf_builder::glb;
use common::gltf_check::{load, REAL};
use common::scene_out_case::{generated_inputs, real_inputs, triangle_bytes, two_lights};
use common::scene_out_checks::{
    assert_lights_read_back, assert_lossless, check_output, schema_validator,
};
use common::validator::validator_problems;
use glam::DVec3;
use serde_json::json;
use streaklight::scene_out::{write_lit_scene, LightToWrite, WriteOptions};

#[test]
fn generated_scenes_every_format_same_and_other_folder() {
    let dir = temp_dir("generated");
    let lights = two_lights();
    let options = WriteOptions::default();
    for input in generated_inputs(&dir.join("in")) {
        assert!(
            validator_problems(&input).is_empty(),
            "{}: fixture invalid",
            input.display()
        );
        let bytes = std::fs::read(&input).unwrap();
        assert!(
            gltf::Gltf::from_slice(&bytes).is_ok(),
            "{}: the gltf crate refuses the fixture",
            input.display()
        );
        let stem = input.file_stem().unwrap().to_str().unwrap().to_string();
        let other = dir.join("out").join(&stem);
        std::fs::create_dir_all(&other).unwrap();
        let same = input.parent().unwrap().to_path_buf();
        for (folder, ext) in [
            (&same, "gltf"),
            (&same, "glb"),
            (&other, "gltf"),
            (&other, "glb"),
        ] {
            let output = folder.join(format!("{stem}-lit.{ext}"));
            let s = write_lit_scene(&input, &output, &lights, &options)
                .unwrap_or_else(|e| panic!("{} -> {}: {e}", input.display(), output.display()));
            check_output(&input, &output, &lights, &options, &s);
            // Only the external files are copied, into whichever folder, and only beside a
            // .gltf (a .glb holds them).
            let external = stem == "external" && ext == "gltf";
            assert_eq!(s.resources.copied.len(), if external { 2 } else { 0 });
            assert!(s.resources.rewritten_uris.is_empty());
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn published_samples_lose_nothing_and_validate() {
    let dir = temp_dir("real");
    let lights = two_lights();
    let options = WriteOptions::default();
    for input in real_inputs(&dir.join("in")) {
        let stem = input.file_stem().unwrap().to_str().unwrap().to_string();
        let other = dir.join("out");
        std::fs::create_dir_all(&other).unwrap();
        for output in [
            other.join(format!("{stem}.gltf")),
            other.join(format!("{stem}.glb")),
        ] {
            let s = write_lit_scene(&input, &output, &lights, &options)
                .unwrap_or_else(|e| panic!("{}: {e}", input.display()));
            check_output(&input, &output, &lights, &options, &s);
        }
    }
    // The repository's copies are the published bytes (the README lists their sha256; here the
    // length of one with CRLF line endings, which a careless checkout would change).
    assert_eq!(
        std::fs::metadata(Path::new(REAL).join("SimpleSkin.gltf"))
            .unwrap()
            .len(),
        4274
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn numbers_keep_their_exact_value_and_kind() {
    let dir = temp_dir("numbers");
    let input = generated_inputs(&dir).remove(0);
    let output = dir.join("n.gltf");
    write_lit_scene(&input, &output, &two_lights(), &WriteOptions::default()).unwrap();
    let json = load(&output).json;
    let t = &json["nodes"][0]["translation"];
    assert_eq!(
        t[0].as_f64().unwrap().to_bits(),
        0.30000000000000004f64.to_bits()
    );
    assert_eq!(
        t[1].as_f64().unwrap().to_bits(),
        "1.7484555314695172e-07".parse::<f64>().unwrap().to_bits()
    );
    assert!(t[2].is_f64(), "1.0 must stay a float");
    assert!(
        json["nodes"][1]["translation"][1].is_u64(),
        "1 must stay an integer"
    );
    assert_eq!(
        json["nodes"][0]["extras"]["n"].as_u64(),
        Some(12345678901234567)
    );
    let light = &json["extensions"]["EXT_lights_area"]["lights"][1];
    assert_eq!(light["rect"]["aspect"].as_f64(), Some(3.0 / 1.5));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn round_trips_across_formats_and_folders() {
    let dir = temp_dir("roundtrip");
    let inputs = generated_inputs(&dir.join("in"));
    let lights = two_lights();
    let more: Vec<LightToWrite> = lights
        .iter()
        .map(|l| LightToWrite {
            name: format!("{} 2", l.name),
            center: l.center + DVec3::X,
            ..l.clone()
        })
        .collect();
    let opts = WriteOptions::default();
    std::fs::create_dir_all(dir.join("a")).unwrap();
    std::fs::create_dir_all(dir.join("b").join("deeper")).unwrap();
    // .gltf -> .glb (another folder) -> .gltf (yet another), adding lights each time.
    let first = dir.join("a").join("step1.glb");
    let second = dir.join("b").join("deeper").join("step2.gltf");
    let s1 = write_lit_scene(&inputs[0], &first, &lights, &opts).unwrap();
    check_output(&inputs[0], &first, &lights, &opts, &s1);
    let s2 = write_lit_scene(&first, &second, &more, &opts).unwrap();
    check_output(&first, &second, &more, &opts, &s2);
    assert_lossless(&inputs[0], &second, &s2);
    // The first step's lights are still there, read back the same.
    assert_lights_read_back(&second, &lights, &opts, &s1);
    assert_eq!(s2.light_indices, vec![3, 4]);
    // .glb -> .glb, twice.
    let g1 = dir.join("a").join("g1.glb");
    let g2 = dir.join("b").join("g2.glb");
    let s = write_lit_scene(&inputs[2], &g1, &lights, &opts).unwrap();
    check_output(&inputs[2], &g1, &lights, &opts, &s);
    let s = write_lit_scene(&g1, &g2, &more, &opts).unwrap();
    check_output(&g1, &g2, &more, &opts, &s);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn unknown_glb_chunks_are_kept_in_glb_output() {
    let dir = temp_dir("chunks");
    let json = json!({ "asset": { "version": "2.0" }, "buffers": [{ "byteLength": 42 }] });
    let input = dir.join("x.glb");
    std::fs::write(
        &input,
        glb(&json, Some(&triangle_bytes()), &[(0x5845_5400, b"abcd")]),
    )
    .unwrap();
    let s = write_lit_scene(
        &input,
        &dir.join("y.glb"),
        &two_lights(),
        &WriteOptions::default(),
    )
    .unwrap();
    assert_lossless(&input, &dir.join("y.glb"), &s);
    assert_eq!(
        load(&dir.join("y.glb")).glb_chunks[2],
        (0x5845_5400, b"abcd".to_vec())
    );
    let s = write_lit_scene(
        &input,
        &dir.join("z.gltf"),
        &two_lights(),
        &WriteOptions::default(),
    )
    .unwrap();
    assert_eq!(s.resources.dropped_glb_chunks, 1);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn schema_rejects_what_we_must_not_write() {
    let top = schema_validator("topLevel");
    let ok = json!({ "lights": [{ "type": "rect", "color": [1.0, 0.5, 0.0], "intensity": 2.0,
                                  "size": 1.0, "rect": { "aspect": 2.0 }, "name": "a" }] });
    assert!(top.is_valid(&ok));
    for (pointer, bad) in [
        ("/lights/0/color/0", json!(1.5)),
        ("/lights/0/size", json!(0.0)),
        ("/lights/0/type", json!("disk")),
        ("/lights/0/rect/aspect", json!(-1.0)),
    ] {
        let mut v = ok.clone();
        *v.pointer_mut(pointer).unwrap() = bad;
        assert!(!top.is_valid(&v), "{pointer}");
    }
    let mut missing = ok.clone();
    missing["lights"][0]
        .as_object_mut()
        .unwrap()
        .remove("intensity");
    assert!(!top.is_valid(&missing));
    assert!(!schema_validator("node").is_valid(&json!({ "light": -1 })));
    assert!(!schema_validator("streaklightExtras").is_valid(&json!({ "role": "lamp" })));
}

#[test]
fn the_light_offset_moves_only_the_node() {
    let dir = temp_dir("offset");
    let input = generated_inputs(&dir).remove(0);
    let lights = two_lights();
    let mut nodes = Vec::new();
    for (name, light_offset) in [("on.gltf", 0.0), ("off.gltf", 0.25)] {
        let options = WriteOptions {
            light_offset,
            ..WriteOptions::default()
        };
        let output = dir.join(name);
        let s = write_lit_scene(&input, &output, &lights, &options).unwrap();
        check_output(&input, &output, &lights, &options, &s);
        let json = load(&output).json;
        nodes.push((json["extensions"]["EXT_lights_area"].clone(), s));
    }
    let ((lights_on, on), (lights_off, off)) = (&nodes[0], &nodes[1]);
    assert_eq!(lights_on, lights_off, "the light objects do not move");
    for (k, l) in lights.iter().enumerate() {
        assert_eq!(on.node_translations[k], l.center.to_array());
        let moved = DVec3::from_array(off.node_translations[k]) - l.center;
        assert!((moved - l.normal * 0.25).length() < 1e-12, "{moved}");
    }
    for bad in [-0.001, f64::NAN, f64::INFINITY] {
        let options = WriteOptions {
            light_offset: bad,
            ..WriteOptions::default()
        };
        let e = write_lit_scene(&input, &dir.join("bad.gltf"), &lights, &options).unwrap_err();
        assert!(e.to_string().contains("light offset"), "{e}");
    }
    assert!(!dir.join("bad.gltf").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
