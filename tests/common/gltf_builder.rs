//! Builds small glTF documents for tests, so no large data is committed: [`TestScene`] (a
//! document with one binary buffer, written as .gltf or .glb), the paper's setup in miniature,
//! and the pieces every hand-made document needs (byte packing, `data:` URIs, GLB containers,
//! appending to a document's top-level arrays).

use std::path::Path;

use base64::Engine;
use serde_json::{json, Value};

/// The GLB chunk type of the JSON chunk (`JSON`).
pub const GLB_JSON: u32 = 0x4E4F_534A;
/// The GLB chunk type of the binary chunk (`BIN\0`).
pub const GLB_BIN: u32 = 0x004E_4942;

/// The paper setup's wall at z = 0: a quad from x = -40 to 40, y = -1 to 25.
pub const WALL: [[f32; 3]; 4] = [
    [-40.0, -1.0, 0.0],
    [40.0, -1.0, 0.0],
    [40.0, 25.0, 0.0],
    [-40.0, 25.0, 0.0],
];
/// The wall's two triangles.
pub const WALL_INDICES: [u32; 6] = [0, 1, 2, 0, 2, 3];

/// `bytes` as a `data:` URI of media type `mime`, base64-encoded.
pub fn data_uri_of(mime: &str, bytes: &[u8]) -> String {
    format!(
        "data:{mime};base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bytes)
    )
}

/// `bytes` as an `application/octet-stream` `data:` URI, as a buffer's `uri`.
pub fn data_uri(bytes: &[u8]) -> String {
    data_uri_of("application/octet-stream", bytes)
}

/// Little-endian f32s, as glTF stores them.
pub fn f32_bytes(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|c| c.to_le_bytes()).collect()
}

/// Little-endian VEC3 f32s.
pub fn vec3_bytes(values: &[[f32; 3]]) -> Vec<u8> {
    f32_bytes(values.as_flattened())
}

/// Little-endian u32s (unsigned int indices).
pub fn u32_bytes(values: &[u32]) -> Vec<u8> {
    values.iter().flat_map(|c| c.to_le_bytes()).collect()
}

/// The per-component minimum and maximum of `points`, as a POSITION accessor's `min`, `max`.
pub use streaklight::samples::gltf_doc::vec3_bounds;

/// Pads `bin` with zeros to a multiple of 4, appends `bytes` and returns their offset.
pub fn append_aligned(bin: &mut Vec<u8>, bytes: &[u8]) -> usize {
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let offset = bin.len();
    bin.extend_from_slice(bytes);
    offset
}

/// Appends `value` to the top-level array `key` of `doc` (made when missing); returns its index.
pub fn push(doc: &mut Value, key: &str, value: Value) -> usize {
    let root = doc.as_object_mut().expect("a glTF document is an object");
    let arr = root
        .entry(key)
        .or_insert(json!([]))
        .as_array_mut()
        .expect("a glTF top-level array");
    arr.push(value);
    arr.len() - 1
}

/// Appends `light` to the document's `EXT_lights_area` lights (made when missing); returns
/// its index. Leaves `extensionsUsed` alone.
pub fn push_area_light(doc: &mut Value, light: Value) -> usize {
    let root = doc.as_object_mut().expect("a glTF document is an object");
    let lights = root
        .entry("extensions")
        .or_insert(json!({}))
        .as_object_mut()
        .unwrap()
        .entry("EXT_lights_area")
        .or_insert(json!({"lights": []}))["lights"]
        .as_array_mut()
        .unwrap();
    lights.push(light);
    lights.len() - 1
}

/// A GLB container: the JSON chunk (`json`, padded with spaces), the BIN chunk when `bin` is
/// given (padded with zeros), then the `extra` chunks (type, bytes) as they are.
pub fn glb(json: &Value, bin: Option<&[u8]>, extra: &[(u32, &[u8])]) -> Vec<u8> {
    let mut text = serde_json::to_vec(json).unwrap();
    text.resize(text.len().div_ceil(4) * 4, b' ');
    let mut chunks: Vec<(u32, Vec<u8>)> = vec![(GLB_JSON, text)];
    if let Some(bin) = bin {
        let mut b = bin.to_vec();
        b.resize(b.len().div_ceil(4) * 4, 0);
        chunks.push((GLB_BIN, b));
    }
    for (kind, data) in extra {
        chunks.push((*kind, data.to_vec()));
    }
    let total = 12 + chunks.iter().map(|(_, d)| 8 + d.len()).sum::<usize>();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    for (kind, data) in chunks {
        out.extend_from_slice(&(data.len() as u32).to_le_bytes());
        out.extend_from_slice(&kind.to_le_bytes());
        out.extend_from_slice(&data);
    }
    out
}

/// Writes `value` as pretty-printed JSON.
pub fn write_json(path: &Path, value: &Value) {
    std::fs::write(path, serde_json::to_vec_pretty(value).unwrap()).unwrap();
}

/// A glTF document under construction, with one binary buffer.
pub struct TestScene {
    pub json: Value,
    pub bin: Vec<u8>,
}

impl TestScene {
    pub fn new() -> Self {
        TestScene {
            json: json!({
                "asset": {"version": "2.0", "generator": "streaklight tests"},
                "scene": 0,
                "scenes": [{"nodes": []}],
                "nodes": [], "meshes": [], "accessors": [], "bufferViews": [],
                "buffers": [], "materials": [], "cameras": []
            }),
            bin: Vec::new(),
        }
    }

    fn push(&mut self, key: &str, value: Value) -> usize {
        push(&mut self.json, key, value)
    }

    /// Adds a node at the scene root; returns its index.
    pub fn add_root_node(&mut self, node: Value) -> usize {
        let i = self.push("nodes", node);
        self.json["scenes"][0]["nodes"]
            .as_array_mut()
            .unwrap()
            .push(json!(i));
        i
    }

    fn add_view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        let offset = append_aligned(&mut self.bin, bytes);
        let mut view = json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()});
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        self.push("bufferViews", view)
    }

    fn add_vec3_accessor(&mut self, data: &[[f32; 3]], with_bounds: bool) -> usize {
        let view = self.add_view(&vec3_bytes(data), Some(34962));
        let mut acc =
            json!({"bufferView": view, "componentType": 5126, "count": data.len(), "type": "VEC3"});
        if with_bounds {
            let (min, max) = vec3_bounds(data);
            acc["min"] = json!(min);
            acc["max"] = json!(max);
        }
        self.push("accessors", acc)
    }

    /// Adds a mesh node; `mode` is the glTF primitive mode (4 = triangles).
    pub fn add_mesh(
        &mut self,
        name: &str,
        positions: &[[f32; 3]],
        normals: Option<&[[f32; 3]]>,
        indices: Option<&[u32]>,
        mode: u32,
        material: Option<Value>,
    ) -> usize {
        let pos = self.add_vec3_accessor(positions, true);
        let mut attributes = json!({"POSITION": pos});
        if let Some(n) = normals {
            attributes["NORMAL"] = json!(self.add_vec3_accessor(n, false));
        }
        let mut prim = json!({"attributes": attributes, "mode": mode});
        if let Some(idx) = indices {
            let view = self.add_view(&u32_bytes(idx), Some(34963));
            let acc = self.push(
                "accessors",
                json!({"bufferView": view, "componentType": 5125, "count": idx.len(), "type": "SCALAR"}),
            );
            prim["indices"] = json!(acc);
        }
        if let Some(m) = material {
            prim["material"] = json!(self.push("materials", m));
        }
        let mesh = self.push("meshes", json!({"name": name, "primitives": [prim]}));
        self.add_root_node(json!({"name": name, "mesh": mesh}))
    }

    /// Adds a perspective camera node looking down its local -Z.
    pub fn add_camera(&mut self, name: &str, translation: [f64; 3], yfov_degrees: f64) -> usize {
        let cam = self.push(
            "cameras",
            json!({"type": "perspective", "perspective": {"yfov": yfov_degrees.to_radians(), "aspectRatio": 1.0, "znear": 0.01}}),
        );
        self.add_root_node(json!({"name": name, "camera": cam, "translation": translation}))
    }

    /// Adds an EXT_lights_area rect light centred at `center`, emitting towards +z.
    pub fn add_light_facing_z(
        &mut self,
        name: &str,
        center: [f64; 3],
        width: f64,
        height: f64,
        radiance: [f64; 3],
    ) -> usize {
        let max = radiance.iter().cloned().fold(0.0, f64::max);
        let light = json!({"name": name, "type": "rect", "color": radiance.map(|c| c / max),
            "intensity": max, "size": height, "rect": {"aspect": width / height}});
        let index = push_area_light(&mut self.json, light);
        self.add_root_node(json!({"name": name, "translation": center,
            "rotation": [0.0, 1.0, 0.0, 0.0], "extensions": {"EXT_lights_area": {"light": index}}}))
    }

    /// The JSON with the buffer as a data URI.
    pub fn embedded_json(&self) -> Value {
        let mut j = self.json.clone();
        j["buffers"] = json!([{"uri": data_uri(&self.bin), "byteLength": self.bin.len()}]);
        j
    }

    /// Writes a `.gltf` with the buffer embedded.
    pub fn write_gltf(&self, path: &Path) {
        write_json(path, &self.embedded_json());
    }

    /// Writes a `.gltf` with the buffer in an external file `bin_name` beside it.
    pub fn write_gltf_external(&self, path: &Path, bin_name: &str) {
        let mut j = self.json.clone();
        j["buffers"] = json!([{"uri": bin_name, "byteLength": self.bin.len()}]);
        std::fs::write(path.parent().unwrap().join(bin_name), &self.bin).unwrap();
        write_json(path, &j);
    }

    /// Writes a `.glb` with the buffer in its BIN chunk.
    pub fn write_glb(&self, path: &Path) {
        let mut j = self.json.clone();
        j["buffers"] = json!([{"byteLength": self.bin.len()}]);
        std::fs::write(path, glb(&j, Some(&self.bin), &[])).unwrap();
    }
}

/// A flat grid at height `y` over [x0, x1] x [z0, z1] with `nx` x `nz` cells, normals up.
pub fn flat_grid(
    x0: f32,
    x1: f32,
    z0: f32,
    z1: f32,
    nx: usize,
    nz: usize,
    y: f32,
) -> (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<u32>) {
    let mut p = Vec::new();
    for j in 0..=nz {
        for i in 0..=nx {
            let x = x0 + (x1 - x0) * i as f32 / nx as f32;
            let z = z0 + (z1 - z0) * j as f32 / nz as f32;
            p.push([x, y, z]);
        }
    }
    let n = vec![[0.0, 1.0, 0.0]; p.len()];
    let mut idx = Vec::new();
    let w = (nx + 1) as u32;
    for j in 0..nz as u32 {
        for i in 0..nx as u32 {
            let a = j * w + i;
            // z grows with j, so (a, a+w+1, a+1) is counter-clockwise seen from +y.
            idx.extend_from_slice(&[a, a + w + 1, a + 1, a, a + w, a + w + 1]);
        }
    }
    (p, n, idx)
}

/// The paper's setup in miniature: camera at (0, 0.2, 10), a flat water grid, a wall at z = 0.
pub fn paper_setup(water_material: Option<Value>) -> TestScene {
    let mut s = TestScene::new();
    s.add_camera("Camera", [0.0, 0.2, 10.0], 60.0);
    let (p, n, i) = flat_grid(-12.0, 12.0, -1.0, 10.5, 48, 23, 0.0);
    s.add_mesh("Water", &p, Some(&n), Some(&i), 4, water_material);
    s.add_mesh("Wall", &WALL, None, Some(&WALL_INDICES), 4, None);
    s
}
