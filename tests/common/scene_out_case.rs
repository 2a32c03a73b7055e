//! The glTF writer's test inputs: lights to write, small generated scenes in every storage
//! form (external files, `data:` URIs, a GLB BIN chunk, nothing), and copies of the published
//! samples.

use std::path::{Path, PathBuf};

use glam::DVec3;
use serde_json::{json, Value};
use streaklight::scene_out::LightToWrite;

use super::gltf_builder::{data_uri, data_uri_of, f32_bytes, glb};
use super::gltf_check::{real_files, REAL};

/// Two lights: one with round numbers, one with a long decimal, an oblique normal, no streak.
pub fn two_lights() -> Vec<LightToWrite> {
    let n1 = DVec3::new(-1.0, -0.2, 0.3).normalize();
    vec![
        LightToWrite {
            name: "facade light".into(),
            center: DVec3::new(1.5, 2.25, -3.0),
            normal: DVec3::new(0.0, -0.6, 0.8),
            up: DVec3::new(0.0, 0.8, 0.6),
            width: 3.0,
            height: 1.5,
            radiance: [20.0, 10.0, 2.5],
            streak_id: Some(0),
        },
        LightToWrite {
            name: "pole light".into(),
            center: DVec3::new(-40.125, 7.0, 123.456_789_012_345_6),
            normal: n1,
            up: n1.any_orthonormal_vector(),
            width: 0.7,
            height: 2.2,
            radiance: [0.0, 5.5, 11.0],
            streak_id: None,
        },
    ]
}

/// A triangle: 3 positions (36 bytes) then 3 u16 indices (6 bytes); 42 bytes, so a GLB's BIN
/// chunk needs padding and our data an aligned offset after it.
pub fn triangle_bytes() -> Vec<u8> {
    let mut b = f32_bytes(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    for i in [0u16, 1, 2] {
        b.extend_from_slice(&i.to_le_bytes());
    }
    b
}

pub fn png_bytes() -> Vec<u8> {
    let img = image::RgbImage::from_pixel(2, 2, image::Rgb([200, 30, 30]));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// The JSON of a small scene with a textured triangle, a camera, extras, an unknown
/// extension, numbers that need care (long decimals, `1.0` vs `1`), and one existing area
/// light, with buffer 0 stored as `buffer_uri` (None = GLB BIN chunk).
pub fn scene_json(buffer_uri: Option<&str>, image: Value) -> Value {
    let mut buffer = json!({ "byteLength": 42 });
    if let Some(uri) = buffer_uri {
        buffer["uri"] = Value::from(uri);
    }
    json!({
        "asset": { "version": "2.0", "generator": "streaklight test", "extras": { "k": [1, 2.0] } },
        "extensionsUsed": ["EXT_test_unknown", "EXT_lights_area"],
        "extensions": {
            "EXT_test_unknown": { "deep": { "x": 0.30000000000000004 } },
            "EXT_lights_area": { "lights": [
                { "type": "rect", "color": [1.0, 1.0, 1.0], "intensity": 3.0, "size": 1.0,
                  "rect": { "aspect": 2.0 }, "name": "existing" }
            ] }
        },
        "scene": 0,
        "scenes": [{ "name": "main", "nodes": [0, 1, 2] }],
        "nodes": [
            { "name": "water", "mesh": 0,
              "translation": [0.30000000000000004, 1.7484555314695172e-07, 1.0],
              "extras": { "note": "keep me", "n": 12345678901234567u64 },
              "extensions": { "EXT_test_unknown": { "a": 1 } } },
            { "name": "camera", "camera": 0, "translation": [0, 1, 10] },
            { "name": "existing light", "extensions": { "EXT_lights_area": { "light": 0 } } }
        ],
        "cameras": [{ "type": "perspective",
                      "perspective": { "yfov": 1.0471975511965976, "znear": 0.01, "aspectRatio": 1.5 } }],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0, "TEXCOORD_0": 2 },
                                      "indices": 1, "material": 0 }] }],
        "materials": [{ "name": "tex", "pbrMetallicRoughness": { "baseColorTexture": { "index": 0 },
                                                                "metallicFactor": 0.0 } }],
        "textures": [{ "source": 0 }],
        "images": [image],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
              "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0] },
            { "bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR" },
            { "bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2" }
        ],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": 36, "target": 34962 },
            { "buffer": 0, "byteOffset": 36, "byteLength": 6, "target": 34963 },
            { "buffer": 1, "byteLength": 24, "target": 34962 }
        ],
        "buffers": [buffer, { "byteLength": 24, "uri": data_uri(&uv_bytes()) }]
    })
}

pub fn uv_bytes() -> Vec<u8> {
    f32_bytes(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0])
}

/// The generated inputs, each in its own folder `dir/<name>/`, with any files it uses.
pub fn generated_inputs(dir: &Path) -> Vec<PathBuf> {
    let mut inputs = Vec::new();
    let folder = |name: &str| {
        let d = dir.join(name);
        std::fs::create_dir_all(&d).unwrap();
        d
    };
    // .gltf with an external .bin and an external image in a subfolder whose name needs escaping.
    let d = folder("external");
    std::fs::write(d.join("geometry.bin"), triangle_bytes()).unwrap();
    std::fs::create_dir_all(d.join("tex dir")).unwrap();
    std::fs::write(d.join("tex dir").join("my image.png"), png_bytes()).unwrap();
    let json = scene_json(
        Some("geometry.bin"),
        json!({ "uri": "tex%20dir/my%20image.png" }),
    );
    let p = d.join("external.gltf");
    std::fs::write(&p, serde_json::to_vec_pretty(&json).unwrap()).unwrap();
    inputs.push(p);
    // .gltf with data URIs only, no default scene, no extensionsUsed.
    let d = folder("embedded");
    let png = data_uri_of("image/png", &png_bytes());
    let mut json = scene_json(Some(&data_uri(&triangle_bytes())), json!({ "uri": png }));
    let root = json.as_object_mut().unwrap();
    root.remove("scene");
    root.remove("extensions");
    root["extensionsUsed"] = json!(["EXT_test_unknown"]);
    root["nodes"].as_array_mut().unwrap()[2] = json!({ "name": "empty" });
    let p = d.join("embedded.gltf");
    std::fs::write(&p, serde_json::to_vec(&json).unwrap()).unwrap();
    inputs.push(p);
    // .glb with everything in its BIN chunk: the 42-byte triangle (padded to 44), the UVs,
    // then the image, so the buffer's length is whatever the PNG makes it.
    let d = folder("binary");
    let mut bin = triangle_bytes();
    bin.resize(44, 0);
    bin.extend_from_slice(&uv_bytes());
    let png = png_bytes();
    let mut json = scene_json(None, json!({ "bufferView": 3, "mimeType": "image/png" }));
    json["bufferViews"][2] =
        json!({ "buffer": 0, "byteOffset": 44, "byteLength": 24, "target": 34962 });
    json["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(json!({ "buffer": 0, "byteOffset": bin.len(), "byteLength": png.len() }));
    bin.extend_from_slice(&png);
    json["buffers"] = json!([{ "byteLength": bin.len() }]);
    let p = d.join("binary.glb");
    std::fs::write(&p, glb(&json, Some(&bin), &[])).unwrap();
    inputs.push(p);
    // .glb without BIN chunk or buffers, and no scenes at all.
    let d = folder("bare");
    let json = json!({ "asset": { "version": "2.0" }, "nodes": [{ "name": "lonely" }] });
    let p = d.join("bare.glb");
    std::fs::write(&p, glb(&json, None, &[])).unwrap();
    inputs.push(p);
    inputs
}

/// Copies of the published samples, one folder each (the repository's copies stay untouched).
pub fn real_inputs(dir: &Path) -> Vec<PathBuf> {
    let names = real_files();
    assert!(names.len() >= 9, "the samples in {REAL} are missing");
    names
        .iter()
        .map(|src| {
            let d = dir.join(src.file_stem().unwrap());
            std::fs::create_dir_all(&d).unwrap();
            let p = d.join(src.file_name().unwrap());
            std::fs::copy(src, &p).unwrap();
            p
        })
        .collect()
}
