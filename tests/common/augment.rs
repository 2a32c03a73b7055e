//! Turns a glTF file we did not write into a `fit` input by APPENDING a camera, a water plane and
//! a wall (new nodes, meshes, a material, accessors, buffer views and a NEW buffer as a `data:`
//! URI), leaving every existing value as it was. Optionally a truth light too, to render the
//! photo from.
#![allow(dead_code)]

use base64::Engine;
use serde_json::{json, Value};

/// The name of the camera node the augmentation adds (pass it as `--camera`).
pub const CAMERA: &str = "StreaklightTestCamera";

/// Where the added setup sits: far enough along -Z that the original content (a few units
/// around the origin) is behind the camera and out of the picture.
const OFFSET: [f32; 3] = [0.0, 0.0, -60.0];

fn push(doc: &mut Value, key: &str, value: Value) -> usize {
    let root = doc.as_object_mut().expect("a glTF document is an object");
    let arr = root
        .entry(key)
        .or_insert(json!([]))
        .as_array_mut()
        .expect("a glTF top-level array");
    arr.push(value);
    arr.len() - 1
}

/// Appends the setup to `original` (a parsed glTF document); with `light`, also a 3 x 3 m
/// `EXT_lights_area` light of radiance 20 on the wall.
pub fn augment(original: &Value, light: bool) -> Value {
    let mut doc = original.clone();
    let mut bin: Vec<u8> = Vec::new();
    let buffer = doc["buffers"].as_array().map_or(0, Vec::len);
    let mut views: Vec<(usize, usize, u32)> = Vec::new();
    let mut add_view = |bin: &mut Vec<u8>, bytes: &[u8], target: u32| {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        views.push((bin.len(), bytes.len(), target));
        bin.extend_from_slice(bytes);
        views.len() - 1
    };
    let f32s =
        |v: &[[f32; 3]]| -> Vec<u8> { v.iter().flatten().flat_map(|c| c.to_le_bytes()).collect() };
    let u32s = |v: &[u32]| -> Vec<u8> { v.iter().flat_map(|c| c.to_le_bytes()).collect() };
    let shift = |v: Vec<[f32; 3]>| -> Vec<[f32; 3]> {
        v.into_iter()
            .map(|p| [p[0] + OFFSET[0], p[1] + OFFSET[1], p[2] + OFFSET[2]])
            .collect()
    };

    let (wp, wn, wi) = super::flat_grid(-12.0, 12.0, -1.0, 10.5, 24, 12, 0.0);
    let wp = shift(wp);
    let wall = shift(vec![
        [-40.0, -1.0, 0.0],
        [40.0, -1.0, 0.0],
        [40.0, 25.0, 0.0],
        [-40.0, 25.0, 0.0],
    ]);
    let wall_i = [0u32, 1, 2, 0, 2, 3];
    let v_wp = add_view(&mut bin, &f32s(&wp), 34962);
    let v_wn = add_view(&mut bin, &f32s(&wn), 34962);
    let v_wi = add_view(&mut bin, &u32s(&wi), 34963);
    let v_lp = add_view(&mut bin, &f32s(&wall), 34962);
    let v_li = add_view(&mut bin, &u32s(&wall_i), 34963);

    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bin)
    );
    push(
        &mut doc,
        "buffers",
        json!({"uri": uri, "byteLength": bin.len()}),
    );
    let view_index: Vec<usize> = views
        .iter()
        .map(|&(offset, len, target)| {
            push(
                &mut doc,
                "bufferViews",
                json!({"buffer": buffer, "byteOffset": offset, "byteLength": len, "target": target}),
            )
        })
        .collect();
    let bounds = |v: &[[f32; 3]]| {
        let mut min = [f32::INFINITY; 3];
        let mut max = [f32::NEG_INFINITY; 3];
        for p in v {
            for c in 0..3 {
                min[c] = min[c].min(p[c]);
                max[c] = max[c].max(p[c]);
            }
        }
        (min, max)
    };
    let (wmin, wmax) = bounds(&wp);
    let (lmin, lmax) = bounds(&wall);
    let a_wp = push(
        &mut doc,
        "accessors",
        json!({"bufferView": view_index[v_wp], "componentType": 5126, "count": wp.len(), "type": "VEC3", "min": wmin, "max": wmax}),
    );
    let a_wn = push(
        &mut doc,
        "accessors",
        json!({"bufferView": view_index[v_wn], "componentType": 5126, "count": wn.len(), "type": "VEC3"}),
    );
    let a_wi = push(
        &mut doc,
        "accessors",
        json!({"bufferView": view_index[v_wi], "componentType": 5125, "count": wi.len(), "type": "SCALAR"}),
    );
    let a_lp = push(
        &mut doc,
        "accessors",
        json!({"bufferView": view_index[v_lp], "componentType": 5126, "count": 4, "type": "VEC3", "min": lmin, "max": lmax}),
    );
    let a_li = push(
        &mut doc,
        "accessors",
        json!({"bufferView": view_index[v_li], "componentType": 5125, "count": 6, "type": "SCALAR"}),
    );
    let material = push(
        &mut doc,
        "materials",
        json!({"name": "StreaklightTestWater", "pbrMetallicRoughness": {"roughnessFactor": 0.2512, "metallicFactor": 0.0}}),
    );
    let water_mesh = push(
        &mut doc,
        "meshes",
        json!({"name": "StreaklightTestWater", "primitives": [{"attributes": {"POSITION": a_wp, "NORMAL": a_wn}, "indices": a_wi, "material": material, "mode": 4}]}),
    );
    let wall_mesh = push(
        &mut doc,
        "meshes",
        json!({"name": "StreaklightTestWall", "primitives": [{"attributes": {"POSITION": a_lp}, "indices": a_li, "mode": 4}]}),
    );
    let camera = push(
        &mut doc,
        "cameras",
        json!({"type": "perspective", "name": CAMERA, "perspective": {"yfov": 60f64.to_radians(), "aspectRatio": 1.0, "znear": 0.01}}),
    );
    let mut new_nodes = vec![
        push(
            &mut doc,
            "nodes",
            json!({"name": CAMERA, "camera": camera, "translation": [OFFSET[0], OFFSET[1] + 0.2, OFFSET[2] + 10.0]}),
        ),
        push(
            &mut doc,
            "nodes",
            json!({"name": "StreaklightTestWater", "mesh": water_mesh}),
        ),
        push(
            &mut doc,
            "nodes",
            json!({"name": "StreaklightTestWall", "mesh": wall_mesh}),
        ),
    ];
    if light {
        let root = doc.as_object_mut().unwrap();
        let lights = root
            .entry("extensions")
            .or_insert(json!({}))
            .as_object_mut()
            .unwrap()
            .entry("EXT_lights_area")
            .or_insert(json!({"lights": []}))["lights"]
            .as_array_mut()
            .unwrap();
        lights.push(json!({"name": "truth", "type": "rect", "color": [1.0, 1.0, 1.0], "intensity": 20.0, "size": 3.0, "rect": {"aspect": 1.0}}));
        let index = lights.len() - 1;
        push(&mut doc, "extensionsUsed", json!("EXT_lights_area"));
        new_nodes.push(push(
            &mut doc,
            "nodes",
            json!({"name": "truth", "translation": [OFFSET[0], OFFSET[1] + 3.5, OFFSET[2] + 0.01],
                "rotation": [0.0, 1.0, 0.0, 0.0], "extensions": {"EXT_lights_area": {"light": index}}}),
        ));
    }
    // Into the default scene (or a new one, when the file has none).
    let scene = doc["scene"].as_u64().unwrap_or(0) as usize;
    if doc["scenes"].as_array().is_none_or(|s| s.len() <= scene) {
        push(&mut doc, "scenes", json!({"nodes": []}));
    }
    let nodes = doc["scenes"][scene]
        .as_object_mut()
        .unwrap()
        .entry("nodes")
        .or_insert(json!([]))
        .as_array_mut()
        .unwrap();
    nodes.extend(new_nodes.into_iter().map(|n| json!(n)));
    doc
}
