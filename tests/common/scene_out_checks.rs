//! What every output of the glTF writer must satisfy: nothing of the input lost (values, and
//! bytes wherever they are stored), the lights read back as written, the extension's JSON
//! Schema, the Khronos glTF-Validator, and self-containment (no file outside the output's
//! folder).

use std::path::Path;

use glam::{DQuat, DVec3};
use serde_json::{json, Value};
use streaklight::scene_out::{InputFiles, LightToWrite, WriteOptions, WriteSummary};

use super::gltf_builder::{GLB_BIN, GLB_JSON};
use super::gltf_check::{
    assert_buffers_kept, assert_same_data, is_storage_change, load, resolve, Doc,
};
use super::json::json_diff;
use super::validator::assert_no_new_problems;

/// Positions of every primitive of meshes `0..count`, read with the `gltf` crate.
pub fn positions(loaded: &Doc, count: usize) -> Vec<Vec<[f32; 3]>> {
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

/// Asserts that `output` holds all of `input`, changed only where the writer is meant to: new
/// objects appended, and the storage of the data (which then reads the same bytes).
pub fn assert_lossless(input: &Path, output: &Path, summary: &WriteSummary) {
    let a = load(input);
    let b = load(output);
    // A key or array element only in the output is an addition, a differing value a change.
    let diff = json_diff(&a.json, &b.json);
    for c in &diff.changed {
        assert!(
            is_storage_change(c),
            "{}: unexpected change at {c}",
            output.display()
        );
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
            _ => is_storage_change(p),
        };
        assert!(ok, "{}: unexpected addition at {p}", output.display());
    }
    // Every buffer view and image reads the same bytes; buffers kept apart keep their bytes.
    assert_same_data(&a, &b);
    assert_buffers_kept(&a, &b);
    // Unknown GLB chunks survive a .glb output.
    if b.is_glb() {
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

/// Asserts that `output` needs nothing outside its folder: a `.glb` has no URI at all (no
/// file, no `data:` URI), a `.gltf` refers only to `data:` URIs and to files beside it.
pub fn assert_self_contained(output: &Path) {
    let doc = load(output);
    for key in ["buffers", "images"] {
        for (i, item) in doc.json[key].as_array().into_iter().flatten().enumerate() {
            let Some(uri) = item["uri"].as_str() else {
                continue;
            };
            let beside = !uri.starts_with("data:")
                && !uri.contains(['/', '\\'])
                && resolve(output, uri).is_some_and(|p| p.is_file());
            assert!(
                !doc.is_glb() && (uri.starts_with("data:") || beside),
                "{}: {key}[{i}] is at {}",
                output.display(),
                &uri[..uri.len().min(60)]
            );
        }
    }
}

pub fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0)
}

pub fn vec3(v: &Value) -> DVec3 {
    DVec3::new(
        v[0].as_f64().unwrap(),
        v[1].as_f64().unwrap(),
        v[2].as_f64().unwrap(),
    )
}

/// Recomputes every written light from the output file and compares with what was asked: the
/// node sits `options.light_offset` in front of the asked centre, along the normal.
pub fn assert_lights_read_back(
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
        let marker = &node["extras"]["streaklight"];
        assert_eq!(marker["role"], "light");
        assert_eq!(marker["wall_offset"].as_f64(), Some(options.light_offset));
        assert_eq!(
            marker.get("streak").and_then(Value::as_u64),
            want.streak_id.map(|s| s as u64)
        );
        let light = &json["extensions"]["EXT_lights_area"]["lights"][summary.light_indices[k]];
        assert_eq!(light["type"], "rect");
        assert_eq!(light["name"], want.name.as_str());
        let translation = vec3(&node["translation"]);
        assert_eq!(translation.to_array(), summary.node_translations[k]);
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
        // The rectangle itself is where it was fitted; only its node is moved off the wall.
        let center = translation - normal * options.light_offset;
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
                light,
                want,
                options.light_offset,
            );
        } else {
            assert!(node.get("children").is_none());
        }
    }
}

/// The emissive quad under a light: its material, its geometry, and the copy of its light
/// (object and node transform) that `restore-lights` reads.
fn assert_fallback_quad(
    loaded: &Doc,
    index: usize,
    light_node: &Value,
    light: &Value,
    want: &LightToWrite,
    light_offset: f64,
) {
    let json = &loaded.json;
    assert_eq!(light_node["children"], json!([index]));
    let node = &json["nodes"][index];
    let marker = &node["extras"]["streaklight"];
    assert_eq!(marker["role"], "fallback-quad");
    assert_eq!(&marker["light"], light);
    assert_eq!(
        marker["light_node"],
        json!({
            "translation": light_node["translation"],
            "rotation": light_node["rotation"],
            "wall_offset": light_offset,
        })
    );
    assert!(node.get("translation").is_none() && node.get("rotation").is_none());
    let bytes = serde_json::to_vec(json).unwrap();
    let doc = gltf::Gltf::from_slice_without_validation(&bytes).unwrap();
    let mesh = doc.nodes().nth(index).unwrap().mesh().unwrap();
    let prim = mesh.primitives().next().unwrap();
    let material = &json["materials"][prim.material().index().unwrap()];
    assert_eq!(vec3(&material["emissiveFactor"]), vec3(&light["color"]));
    assert_eq!(
        material["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"],
        light["intensity"]
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

/// A validator for definition `def` of `schema/ext_lights_area.schema.json`.
pub fn schema_validator(def: &str) -> jsonschema::Validator {
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

pub fn assert_matches_schema(output: &Path, summary: &WriteSummary) {
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

/// Everything about one write. The output adds no validator error or warning to those of the
/// input (for the generated inputs: none at all, which the tests check); a `.glb` holds no
/// `data:` URI, so not even `DATA_URI_GLB`.
pub fn check_output(
    input: &Path,
    output: &Path,
    lights: &[LightToWrite],
    options: &WriteOptions,
    s: &WriteSummary,
) {
    assert_lossless(input, output, s);
    assert_lights_read_back(output, lights, options, s);
    assert_matches_schema(output, s);
    assert_no_new_problems(input, output);
    if options.input_files == InputFiles::Copy {
        assert_self_contained(output);
    }
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
