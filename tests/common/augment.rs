//! Turns a glTF file we did not write into a `fit` input by APPENDING a camera, a water plane and
//! a wall (new nodes, meshes, a material, accessors, buffer views and a NEW buffer as a `data:`
//! URI), leaving every existing value as it was. Optionally a truth light too, to render the
//! photo from.

use serde_json::{json, Value};

use super::gltf_builder::{
    append_aligned, data_uri, flat_grid, push, push_area_light, u32_bytes, vec3_bounds, vec3_bytes,
    WALL, WALL_INDICES,
};

/// The name of the camera node the augmentation adds (pass it as `--camera`).
pub const CAMERA: &str = "StreaklightTestCamera";

/// Where the added setup sits: far enough along -Z that the original content (a few units
/// around the origin) is behind the camera and out of the picture.
const OFFSET: [f32; 3] = [0.0, 0.0, -60.0];

/// Appends the setup to `original` (a parsed glTF document); with `light`, also a 3 x 3 m
/// `EXT_lights_area` light of radiance 20 on the wall.
pub fn augment(original: &Value, light: bool) -> Value {
    let mut doc = original.clone();
    let mut bin: Vec<u8> = Vec::new();
    let buffer = doc["buffers"].as_array().map_or(0, Vec::len);
    let mut views: Vec<(usize, usize, u32)> = Vec::new();
    let mut add_view = |bin: &mut Vec<u8>, bytes: &[u8], target: u32| {
        views.push((append_aligned(bin, bytes), bytes.len(), target));
        views.len() - 1
    };
    let shift = |v: Vec<[f32; 3]>| -> Vec<[f32; 3]> {
        v.into_iter()
            .map(|p| [p[0] + OFFSET[0], p[1] + OFFSET[1], p[2] + OFFSET[2]])
            .collect()
    };

    let (wp, wn, wi) = flat_grid(-12.0, 12.0, -1.0, 10.5, 24, 12, 0.0);
    let wp = shift(wp);
    let wall = shift(WALL.to_vec());
    let v_wp = add_view(&mut bin, &vec3_bytes(&wp), 34962);
    let v_wn = add_view(&mut bin, &vec3_bytes(&wn), 34962);
    let v_wi = add_view(&mut bin, &u32_bytes(&wi), 34963);
    let v_lp = add_view(&mut bin, &vec3_bytes(&wall), 34962);
    let v_li = add_view(&mut bin, &u32_bytes(&WALL_INDICES), 34963);

    push(
        &mut doc,
        "buffers",
        json!({"uri": data_uri(&bin), "byteLength": bin.len()}),
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
    let (wmin, wmax) = vec3_bounds(&wp);
    let (lmin, lmax) = vec3_bounds(&wall);
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
        let index = push_area_light(
            &mut doc,
            json!({"name": "truth", "type": "rect", "color": [1.0, 1.0, 1.0], "intensity": 20.0, "size": 3.0, "rect": {"aspect": 1.0}}),
        );
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
