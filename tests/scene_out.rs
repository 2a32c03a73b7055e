//! Tests of the glTF writer (`streaklight::scene_out`, method §7): nothing of the input is
//! lost, the lights read back as written, the emitted extension matches its JSON Schema, and
//! the Khronos glTF-Validator finds no new error or warning in any output.
//!
//! Needs `node` and `npm ci --prefix tests/validator` for the validator tests.

use std::path::{Path, PathBuf};

mod common;

use common::dirs::{sorted_paths, temp_dir};
use common::gltf_builder::{data_uri, data_uri_of, f32_bytes, glb, GLB_BIN, GLB_JSON};
use common::gltf_check::{assert_buffers_kept, load, real_files, resolve, Doc, REAL};
use common::json::json_diff;
use common::validator::{assert_no_new_problems_except, validator_problems};
use glam::{DQuat, DVec3};
use serde_json::{json, Value};
use streaklight::scene_out::{
    write_lit_scene, BufferStorage, LightToWrite, NewData, WriteOptions, WriteSummary,
};

// ---------------------------------------------------------------------------------------------
// Fixtures

fn two_lights() -> Vec<LightToWrite> {
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
fn triangle_bytes() -> Vec<u8> {
    let mut b = f32_bytes(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    for i in [0u16, 1, 2] {
        b.extend_from_slice(&i.to_le_bytes());
    }
    b
}

fn png_bytes() -> Vec<u8> {
    let img = image::RgbImage::from_pixel(2, 2, image::Rgb([200, 30, 30]));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// The JSON of a small scene with a textured triangle, a camera, extras, an unknown
/// extension, numbers that need care (long decimals, `1.0` vs `1`), and one existing area
/// light, with buffer 0 stored as `buffer_uri` (None = GLB BIN chunk).
fn scene_json(buffer_uri: Option<&str>, image: Value) -> Value {
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

fn uv_bytes() -> Vec<u8> {
    f32_bytes(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0])
}

/// The generated inputs, each in its own folder `dir/<name>/`, with any files it uses.
fn generated_inputs(dir: &Path) -> Vec<PathBuf> {
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
fn real_inputs(dir: &Path) -> Vec<PathBuf> {
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

// ---------------------------------------------------------------------------------------------
// Reading documents back, independently of the writer

/// Positions of every primitive of meshes `0..count`, read with the `gltf` crate.
fn positions(loaded: &Doc, count: usize) -> Vec<Vec<[f32; 3]>> {
    let bytes = serde_json::to_vec(&loaded.json).unwrap();
    let doc = gltf::Gltf::from_slice_without_validation(&bytes).unwrap();
    let mut out = Vec::new();
    for mesh in doc.meshes().take(count) {
        for prim in mesh.primitives() {
            let reader = prim.reader(|b| Some(&loaded.buffers[b.index()][..]));
            out.push(
                reader
                    .read_positions()
                    .map(|p| p.collect())
                    .unwrap_or_default(),
            );
        }
    }
    out
}

// ---------------------------------------------------------------------------------------------
// The lossless check

/// Asserts that `output` holds all of `input`, changed only where the writer is meant to.
fn assert_lossless(input: &Path, output: &Path, summary: &WriteSummary) {
    let a = load(input);
    let b = load(output);
    // A key or array element only in the output is an addition, a differing value a change.
    let diff = json_diff(&a.json, &b.json);
    for c in &diff.changed {
        let ok = if let Some(rest) = c.strip_prefix("/buffers/") {
            let (i, field) = rest.split_once('/').unwrap();
            let i: usize = i.parse().unwrap();
            match field {
                // Rewritten to reach the same file from the output's folder.
                "uri" => {
                    let from = resolve(input, a.json["buffers"][i]["uri"].as_str().unwrap());
                    let to = resolve(output, b.json["buffers"][i]["uri"].as_str().unwrap());
                    from.unwrap().canonicalize().unwrap() == to.unwrap().canonicalize().unwrap()
                }
                // A data: buffer 0 moved into the output GLB's BIN chunk (same bytes, checked
                // below).
                "uri (removed)" => {
                    i == 0
                        && !b.glb_chunks.is_empty()
                        && a.json["buffers"][0]["uri"]
                            .as_str()
                            .is_some_and(|u| u.starts_with("data:"))
                        && summary.resources.data_uri_buffer0_moved_to_bin_chunk
                }
                // The BIN-chunk buffer grows by our data.
                "byteLength" => {
                    i == 0
                        && b.json["buffers"][0]["byteLength"].as_u64()
                            > a.json["buffers"][0]["byteLength"].as_u64()
                }
                _ => false,
            }
        } else if let Some(rest) = c.strip_prefix("/images/") {
            let i: usize = rest.strip_suffix("/uri").unwrap().parse().unwrap();
            let from = resolve(input, a.json["images"][i]["uri"].as_str().unwrap());
            let to = resolve(output, b.json["images"][i]["uri"].as_str().unwrap());
            from.unwrap().canonicalize().unwrap() == to.unwrap().canonicalize().unwrap()
        } else {
            false
        };
        assert!(ok, "{}: unexpected change at {c}", output.display());
    }
    assert!(
        diff.reordered.is_empty(),
        "{}: unexpected change of key order at {:?}",
        output.display(),
        diff.reordered
    );
    let top_arrays = [
        "nodes",
        "meshes",
        "materials",
        "accessors",
        "bufferViews",
        "buffers",
        "scenes",
        "extensionsUsed",
    ];
    let scene = summary.scene_index;
    for p in &diff.added {
        let parts: Vec<&str> = p.trim_start_matches('/').split('/').collect();
        let ok = match parts.as_slice() {
            [top] => top_arrays.contains(top) || *top == "extensions" || *top == "scene",
            ["extensions", "EXT_lights_area"] => true,
            [top, i] => top_arrays.contains(top) && i.parse::<usize>().is_ok(),
            ["extensions", "EXT_lights_area", "lights"] => true,
            ["extensions", "EXT_lights_area", "lights", _] => true,
            ["scenes", s, "nodes"] | ["scenes", s, "nodes", _] => *s == scene.to_string(),
            ["buffers", "0", "uri"] => a.glb_chunks.len() > 1,
            _ => false,
        };
        assert!(ok, "{}: unexpected addition at {p}", output.display());
    }
    // Every input buffer is a prefix of the output's buffer of the same index.
    assert_buffers_kept(input, &a, output, &b);
    // Unknown GLB chunks survive a .glb output.
    if !b.glb_chunks.is_empty() {
        let unknown = |c: &[(u32, Vec<u8>)]| -> Vec<(u32, Vec<u8>)> {
            c.iter()
                .filter(|(k, _)| *k != GLB_JSON && *k != GLB_BIN)
                .cloned()
                .collect()
        };
        assert_eq!(unknown(&a.glb_chunks), unknown(&b.glb_chunks));
    }
    // The original meshes read the same.
    let meshes = a.json["meshes"].as_array().map_or(0, Vec::len);
    assert_eq!(positions(&a, meshes), positions(&b, meshes));
    // extensionsRequired is never touched.
    assert_eq!(
        a.json.get("extensionsRequired"),
        b.json.get("extensionsRequired")
    );
}

// ---------------------------------------------------------------------------------------------
// Reading the lights back

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0)
}

fn vec3(v: &Value) -> DVec3 {
    DVec3::new(
        v[0].as_f64().unwrap(),
        v[1].as_f64().unwrap(),
        v[2].as_f64().unwrap(),
    )
}

/// Recomputes every written light from the output file and compares with what was asked.
fn assert_lights_read_back(
    output: &Path,
    lights: &[LightToWrite],
    options: &WriteOptions,
    summary: &WriteSummary,
) {
    let loaded = load(output);
    let json = &loaded.json;
    assert_eq!(summary.light_indices.len(), lights.len());
    assert!(
        json["extensionsUsed"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|e| *e == "EXT_lights_area")
            .count()
            == 1
    );
    let required = json["extensionsRequired"]
        .as_array()
        .cloned()
        .unwrap_or_default();
    assert!(!required.iter().any(|e| e == "EXT_lights_area"));
    let scene_nodes = &json["scenes"][summary.scene_index]["nodes"];
    for (k, want) in lights.iter().enumerate() {
        let node = &json["nodes"][summary.node_indices[k]];
        assert!(scene_nodes
            .as_array()
            .unwrap()
            .contains(&json!(summary.node_indices[k])));
        assert_eq!(
            node["extensions"]["EXT_lights_area"]["light"],
            json!(summary.light_indices[k])
        );
        assert!(node.get("scale").is_none() && node.get("matrix").is_none());
        assert_eq!(node["extras"]["streaklight"]["role"], "light");
        assert_eq!(
            node["extras"]["streaklight"]
                .get("streak")
                .and_then(Value::as_u64),
            want.streak_id.map(|s| s as u64)
        );
        let light = &json["extensions"]["EXT_lights_area"]["lights"][summary.light_indices[k]];
        assert_eq!(light["type"], "rect");
        assert_eq!(light["name"], want.name.as_str());
        let center = vec3(&node["translation"]);
        let r = &node["rotation"];
        let q = DQuat::from_xyzw(
            r[0].as_f64().unwrap(),
            r[1].as_f64().unwrap(),
            r[2].as_f64().unwrap(),
            r[3].as_f64().unwrap(),
        );
        assert!((q.length() - 1.0).abs() < 1e-12);
        let normal = -(q * DVec3::Z);
        let up = q * DVec3::Y;
        let height = light["size"].as_f64().unwrap();
        let width = height * light["rect"]["aspect"].as_f64().unwrap();
        let color = vec3(&light["color"]);
        let intensity = light["intensity"].as_f64().unwrap();
        let radiance = color * intensity / options.nits_scale;
        for (got, exp) in [(center, want.center), (normal, want.normal), (up, want.up)] {
            for i in 0..3 {
                assert!(close(got[i], exp[i]), "light {k}: {got} vs {exp}");
            }
        }
        assert!(close(width, want.width) && close(height, want.height));
        for i in 0..3 {
            assert!(
                close(radiance[i], want.radiance[i]),
                "{radiance} vs {:?}",
                want.radiance
            );
            assert!((0.0..=1.0).contains(&color[i]));
        }
        if options.fallback_quads {
            assert_fallback_quad(
                &loaded,
                summary.fallback_node_indices[k],
                node,
                want,
                color,
                intensity,
            );
        } else {
            assert!(node.get("children").is_none());
        }
    }
}

fn assert_fallback_quad(
    loaded: &Doc,
    index: usize,
    light_node: &Value,
    want: &LightToWrite,
    color: DVec3,
    intensity: f64,
) {
    let json = &loaded.json;
    assert_eq!(light_node["children"], json!([index]));
    let node = &json["nodes"][index];
    assert_eq!(node["extras"]["streaklight"]["role"], "fallback-quad");
    assert!(node.get("translation").is_none() && node.get("rotation").is_none());
    let bytes = serde_json::to_vec(json).unwrap();
    let doc = gltf::Gltf::from_slice_without_validation(&bytes).unwrap();
    let mesh = doc.nodes().nth(index).unwrap().mesh().unwrap();
    let prim = mesh.primitives().next().unwrap();
    let material = &json["materials"][prim.material().index().unwrap()];
    assert_eq!(vec3(&material["emissiveFactor"]), color);
    assert_eq!(
        material["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"].as_f64(),
        Some(intensity)
    );
    let reader = prim.reader(|b| Some(&loaded.buffers[b.index()][..]));
    let p: Vec<DVec3> = reader
        .read_positions()
        .unwrap()
        .map(|v| DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64))
        .collect();
    let n: Vec<[f32; 3]> = reader.read_normals().unwrap().collect();
    assert!(n.iter().all(|v| *v == [0.0, 0.0, -1.0]));
    let (lo, hi) = p
        .iter()
        .fold((DVec3::MAX, DVec3::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
    let size = hi - lo;
    assert!(
        (size.x - want.width).abs() < 1e-6 * want.width
            && (size.y - want.height).abs() < 1e-6 * want.height
    );
    // 2 cm in front of the light (towards -Z, where it emits), off the wall it sits on: a
    // quad in the wall's plane would z-fight with it.
    assert_eq!((lo.z, hi.z), (-0.02f32 as f64, -0.02f32 as f64));
    let idx: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
    assert_eq!(idx.len(), 6);
    for t in idx.chunks(3) {
        let face = (p[t[1] as usize] - p[t[0] as usize]).cross(p[t[2] as usize] - p[t[0] as usize]);
        assert!(
            face.normalize().distance(DVec3::NEG_Z) < 1e-9,
            "quad faces {face}"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// JSON Schema and glTF-Validator

fn schema_validator(def: &str) -> jsonschema::Validator {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/schema/ext_lights_area.schema.json"
    );
    let schema: Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    let root = json!({
        "$schema": schema["$schema"],
        "$defs": schema["$defs"],
        "$ref": format!("#/$defs/{def}"),
    });
    jsonschema::validator_for(&root).unwrap()
}

fn assert_matches_schema(output: &Path, summary: &WriteSummary) {
    let json = load(output).json;
    let check = |def: &str, v: &Value| {
        let errors: Vec<String> = schema_validator(def)
            .iter_errors(v)
            .map(|e| e.to_string())
            .collect();
        assert!(
            errors.is_empty(),
            "{}: {def} {v}: {errors:?}",
            output.display()
        );
    };
    check("topLevel", &json["extensions"]["EXT_lights_area"]);
    for &n in &summary.node_indices {
        check("node", &json["nodes"][n]["extensions"]["EXT_lights_area"]);
        check(
            "streaklightExtras",
            &json["nodes"][n]["extras"]["streaklight"],
        );
    }
    for &n in &summary.fallback_node_indices {
        check(
            "streaklightExtras",
            &json["nodes"][n]["extras"]["streaklight"],
        );
    }
}

/// The output adds no validator error or warning to those of the input (for our generated
/// inputs: none at all, which `generated_scenes_every_format_same_and_other_folder` checks).
/// One exception, inherent to the format change: a `.glb` written from a `.gltf` keeps the
/// input's `data:` buffers (other than buffer 0) and images, and the validator warns about
/// `data:` URIs in a GLB (`DATA_URI_GLB`). Such a warning is accepted only where the output
/// holds the very `data:` URI the input had.
fn assert_valid(input: &Path, output: &Path) {
    let (a, b) = (load(input).json, load(output).json);
    assert_no_new_problems_except(input, output, |code, pointer| {
        code == "DATA_URI_GLB"
            && a.pointer(pointer)
                .and_then(Value::as_str)
                .is_some_and(|u| u.starts_with("data:"))
            && a.pointer(pointer) == b.pointer(pointer)
    });
}

/// Everything about one write.
fn check_output(
    input: &Path,
    output: &Path,
    lights: &[LightToWrite],
    options: &WriteOptions,
    s: &WriteSummary,
) {
    assert_lossless(input, output, s);
    assert_lights_read_back(output, lights, options, s);
    assert_matches_schema(output, s);
    assert_valid(input, output);
    // The `gltf` crate's own validation (the scene loader's reader) accepts the output
    // whenever it accepted the input: no extensionsRequired, indices in range.
    let accepts = |p: &Path| gltf::Gltf::from_slice(&std::fs::read(p).unwrap()).is_ok();
    if accepts(input) {
        assert!(
            accepts(output),
            "{}: rejected by the gltf crate",
            output.display()
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Tests

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
            let rewritten = !s.resources.rewritten_uris.is_empty();
            assert_eq!(
                rewritten,
                folder == &other && stem == "external",
                "{stem} -> {}",
                output.display()
            );
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn new_data_goes_where_the_table_says() {
    let dir = temp_dir("placement");
    let inputs = generated_inputs(&dir);
    let lights = two_lights();
    let opts = WriteOptions::default();
    let write =
        |input: &Path, out: &str| write_lit_scene(input, &dir.join(out), &lights, &opts).unwrap();
    let (external, glb_in, bare) = (&inputs[0], &inputs[2], &inputs[3]);
    // .glb -> .glb: appended to the BIN chunk at an aligned offset after the 42-byte triangle.
    let s = write(glb_in, "a.glb");
    let in_len = load(glb_in).buffers[0].len();
    assert_eq!(
        s.resources.new_data,
        NewData::AppendedToBuffer {
            buffer: 0,
            byte_offset: in_len.div_ceil(4) * 4
        }
    );
    assert_eq!(load(&dir.join("a.glb")).buffers.len(), 1);
    // .glb -> .gltf: the BIN chunk and our data become <out>.streaklight.bin.
    let s = write(glb_in, "b.gltf");
    assert_eq!(
        s.resources.bin_chunk_moved_to,
        Some(dir.join("b.streaklight.bin"))
    );
    assert_eq!(
        load(&dir.join("b.gltf")).json["buffers"][0]["uri"],
        "b.streaklight.bin"
    );
    assert_eq!(
        s.resources.files_written,
        vec![dir.join("b.streaklight.bin"), dir.join("b.gltf")]
    );
    // .gltf with an external buffer 0 -> .glb: buffer 0 keeps its URI, ours is external too
    // (a data: URI in a GLB draws a validator warning).
    let s = write(external, "c.glb");
    assert_eq!(
        s.resources.new_data,
        NewData::NewBuffer {
            buffer: 2,
            storage: BufferStorage::ExternalFile(dir.join("c.streaklight.bin"))
        }
    );
    assert_eq!(
        s.resources.files_written,
        vec![dir.join("c.streaklight.bin"), dir.join("c.glb")]
    );
    // .gltf with a data: buffer 0 -> .glb: buffer 0 becomes the BIN chunk, ours appended.
    let s = write(&inputs[1], "c2.glb");
    assert!(s.resources.data_uri_buffer0_moved_to_bin_chunk);
    assert_eq!(
        s.resources.new_data,
        NewData::AppendedToBuffer {
            buffer: 0,
            byte_offset: 44
        }
    );
    let c2 = load(&dir.join("c2.glb"));
    assert!(c2.json["buffers"][0].get("uri").is_none());
    assert_eq!(&c2.buffers[0][..42], &triangle_bytes()[..]);
    // .gltf -> .gltf: a new external buffer.
    let s = write(external, "d.gltf");
    assert_eq!(
        s.resources.new_data,
        NewData::NewBuffer {
            buffer: 2,
            storage: BufferStorage::ExternalFile(dir.join("d.streaklight.bin"))
        }
    );
    // No buffers at all -> .glb: a new BIN chunk as buffer 0; the new scene is the default.
    let s = write(bare, "e.glb");
    assert_eq!(
        s.resources.new_data,
        NewData::NewBuffer {
            buffer: 0,
            storage: BufferStorage::GlbBinChunk
        }
    );
    let e = load(&dir.join("e.glb"));
    assert_eq!(e.json["scene"], json!(0));
    assert_eq!(e.json["scenes"][0]["nodes"], json!(s.node_indices));
    // Fallback quads off: no new binary data, no mesh, no emissive extension.
    let off = WriteOptions {
        fallback_quads: false,
        nits_scale: 683.0,
    };
    let s = write_lit_scene(external, &dir.join("f.gltf"), &lights, &off).unwrap();
    assert_eq!(s.resources.new_data, NewData::Nothing);
    assert!(!dir.join("f.streaklight.bin").exists());
    check_output(external, &dir.join("f.gltf"), &lights, &off, &s);
    let f = load(&dir.join("f.gltf"));
    assert!(!f.json["extensionsUsed"]
        .as_array()
        .unwrap()
        .iter()
        .any(|e| e == "KHR_materials_emissive_strength"));
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

/// Asserts `result` is an error whose message contains every one of `words`, and that the
/// folder `dir` holds exactly the files `before` (nothing written, no temporary left).
fn assert_refused<T: std::fmt::Debug>(
    result: streaklight::Result<T>,
    words: &[&str],
    dir: &Path,
    before: &[PathBuf],
) {
    let message = result.expect_err("must be refused").to_string();
    for w in words {
        assert!(
            message.contains(w),
            "message {message:?} should mention {w:?}"
        );
    }
    let now = sorted_paths(dir);
    assert_eq!(now, before, "files changed after: {message}");
}

#[test]
fn bad_inputs_are_refused_and_nothing_is_written() {
    let dir = temp_dir("bad");
    let good_json = json!({ "asset": { "version": "2.0" }, "buffers": [{ "byteLength": 42 }] });
    let good = glb(&good_json, Some(&triangle_bytes()), &[]);
    std::fs::write(dir.join("truncated.glb"), &good[..good.len() - 10]).unwrap();
    let mut magic = good.clone();
    magic[..4].copy_from_slice(b"glTX");
    std::fs::write(dir.join("magic.glb"), &magic).unwrap();
    let mut chunk = good.clone();
    chunk[12..16].copy_from_slice(&10_000u32.to_le_bytes());
    std::fs::write(dir.join("chunk.glb"), &chunk).unwrap();
    std::fs::write(dir.join("notgltf.gltf"), br#"{"hello": "world"}"#).unwrap();
    std::fs::write(dir.join("notjson.gltf"), b"solid cube\nendsolid\n").unwrap();
    std::fs::write(dir.join("gltf1.gltf"), br#"{"asset": {"version": "1.0"}}"#).unwrap();
    std::fs::write(dir.join("good.glb"), &good).unwrap();
    // A .gltf whose buffer file is named like our output's .bin.
    std::fs::write(dir.join("uses.gltf"), serde_json::to_vec(&json!({
        "asset": { "version": "2.0" }, "buffers": [{ "byteLength": 42, "uri": "out.streaklight.bin" }]
    })).unwrap()).unwrap();
    std::fs::write(dir.join("out.streaklight.bin"), triangle_bytes()).unwrap();
    let before = sorted_paths(&dir);
    let lights = two_lights();
    let o = WriteOptions::default();
    let out = dir.join("out.gltf");
    let cases: Vec<(&str, PathBuf, Vec<&str>)> = vec![
        ("missing.gltf", out.clone(), vec!["missing.gltf"]),
        (
            "truncated.glb",
            out.clone(),
            vec!["truncated.glb", "corrupt GLB"],
        ),
        ("magic.glb", out.clone(), vec!["magic.glb", "magic"]),
        ("chunk.glb", out.clone(), vec!["chunk.glb", "corrupt GLB"]),
        (
            "notgltf.gltf",
            out.clone(),
            vec!["notgltf.gltf", "not a glTF"],
        ),
        (
            "notjson.gltf",
            out.clone(),
            vec!["notjson.gltf", "not a glTF"],
        ),
        ("gltf1.gltf", out.clone(), vec!["gltf1.gltf", "2.x"]),
        ("good.glb", dir.join("good.glb"), vec!["good.glb", "input"]),
        ("good.glb", dir.join("good.obj"), vec!["good.obj", ".gltf"]),
        (
            "good.glb",
            dir.join("nowhere").join("x.glb"),
            vec!["nowhere", "does not exist"],
        ),
        (
            "uses.gltf",
            out.clone(),
            vec!["out.streaklight.bin", "input"],
        ),
    ];
    for (input, output, words) in cases {
        assert_refused(
            write_lit_scene(&dir.join(input), &output, &lights, &o),
            &words,
            &dir,
            &before,
        );
    }
    // Output named like the input but spelled differently.
    let other_spelling = dir.join(".").join("good.glb");
    assert_refused(
        write_lit_scene(&dir.join("good.glb"), &other_spelling, &lights, &o),
        &["input"],
        &dir,
        &before,
    );
    // A light that is not a rectangle, a bad nits scale.
    let mut bad = two_lights();
    bad[1].width = -1.0;
    assert_refused(
        write_lit_scene(&dir.join("good.glb"), &out, &bad, &o),
        &["pole light", "width"],
        &dir,
        &before,
    );
    let zero = WriteOptions {
        nits_scale: 0.0,
        ..WriteOptions::default()
    };
    assert_refused(
        write_lit_scene(&dir.join("good.glb"), &out, &lights, &zero),
        &["nits"],
        &dir,
        &before,
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_failed_scene_write_leaves_no_stray_bin() {
    let dir = temp_dir("stray");
    let input = generated_inputs(&dir).remove(2); // the .glb
                                                  // The output's name is taken by a folder, so writing the scene fails after the .bin.
    let output = dir.join("blocked.gltf");
    std::fs::create_dir_all(&output).unwrap();
    let err = write_lit_scene(&input, &output, &two_lights(), &WriteOptions::default());
    assert!(err.is_err());
    assert!(!dir.join("blocked.streaklight.bin").exists());
    // A .bin that was there before gets its old content back.
    std::fs::write(dir.join("blocked.streaklight.bin"), b"old").unwrap();
    assert!(write_lit_scene(&input, &output, &two_lights(), &WriteOptions::default()).is_err());
    assert_eq!(
        std::fs::read(dir.join("blocked.streaklight.bin")).unwrap(),
        b"old"
    );
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains("tmp-streaklight"))
        .collect();
    assert!(leftovers.is_empty());
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
