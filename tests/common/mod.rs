//! Builds small glTF scenes for tests, so no large data is committed.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use base64::Engine;
use serde_json::{json, Value};

/// A glTF document under construction, with one binary buffer.
pub struct TestScene {
    pub json: Value,
    pub bin: Vec<u8>,
}

/// A fresh, empty folder for one test.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir()
        .join("streaklight-tests")
        .join(format!("{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
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
        let arr = self.json[key].as_array_mut().unwrap();
        arr.push(value);
        arr.len() - 1
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
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        let mut view = json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()});
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        self.push("bufferViews", view)
    }

    fn add_vec3_accessor(&mut self, data: &[[f32; 3]], with_bounds: bool) -> usize {
        let bytes: Vec<u8> = data
            .iter()
            .flatten()
            .flat_map(|c| c.to_le_bytes())
            .collect();
        let view = self.add_view(&bytes, Some(34962));
        let mut acc =
            json!({"bufferView": view, "componentType": 5126, "count": data.len(), "type": "VEC3"});
        if with_bounds {
            let mut min = [f32::INFINITY; 3];
            let mut max = [f32::NEG_INFINITY; 3];
            for p in data {
                for c in 0..3 {
                    min[c] = min[c].min(p[c]);
                    max[c] = max[c].max(p[c]);
                }
            }
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
            let bytes: Vec<u8> = idx.iter().flat_map(|i| i.to_le_bytes()).collect();
            let view = self.add_view(&bytes, Some(34963));
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
        let root = self.json.as_object_mut().unwrap();
        let ext = root
            .entry("extensions")
            .or_insert(json!({}))
            .as_object_mut()
            .unwrap()
            .entry("EXT_lights_area")
            .or_insert(json!({"lights": []}));
        let lights = ext["lights"].as_array_mut().unwrap();
        lights.push(light);
        let index = lights.len() - 1;
        self.add_root_node(json!({"name": name, "translation": center,
            "rotation": [0.0, 1.0, 0.0, 0.0], "extensions": {"EXT_lights_area": {"light": index}}}))
    }

    /// The JSON with the buffer as a data URI.
    pub fn embedded_json(&self) -> Value {
        let mut j = self.json.clone();
        let uri = format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&self.bin)
        );
        j["buffers"] = json!([{"uri": uri, "byteLength": self.bin.len()}]);
        j
    }

    /// Writes a `.gltf` with the buffer embedded.
    pub fn write_gltf(&self, path: &Path) {
        std::fs::write(
            path,
            serde_json::to_vec_pretty(&self.embedded_json()).unwrap(),
        )
        .unwrap();
    }

    /// Writes a `.gltf` with the buffer in an external file `bin_name` beside it.
    pub fn write_gltf_external(&self, path: &Path, bin_name: &str) {
        let mut j = self.json.clone();
        j["buffers"] = json!([{"uri": bin_name, "byteLength": self.bin.len()}]);
        std::fs::write(path.parent().unwrap().join(bin_name), &self.bin).unwrap();
        std::fs::write(path, serde_json::to_vec_pretty(&j).unwrap()).unwrap();
    }

    /// Writes a `.glb` with the buffer in its BIN chunk.
    pub fn write_glb(&self, path: &Path) {
        let mut j = self.json.clone();
        j["buffers"] = json!([{"byteLength": self.bin.len()}]);
        let mut json_bytes = serde_json::to_vec(&j).unwrap();
        while !json_bytes.len().is_multiple_of(4) {
            json_bytes.push(b' ');
        }
        let mut bin = self.bin.clone();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let total = 12 + 8 + json_bytes.len() + 8 + bin.len();
        let mut out = Vec::new();
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
        out.extend_from_slice(&0x4E4F534Au32.to_le_bytes());
        out.extend_from_slice(&json_bytes);
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(&0x004E4942u32.to_le_bytes());
        out.extend_from_slice(&bin);
        std::fs::write(path, out).unwrap();
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
    let wall = [
        [-40.0, -1.0, 0.0],
        [40.0, -1.0, 0.0],
        [40.0, 25.0, 0.0],
        [-40.0, 25.0, 0.0],
    ];
    s.add_mesh("Wall", &wall, None, Some(&[0, 1, 2, 0, 2, 3]), 4, None);
    s
}

/// Runs the streaklight binary; returns (exit success, stdout, stderr).
pub fn run_cli(args: &[&str]) -> (bool, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_streaklight"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Synthetic images with known regions (SLIC tests and benchmark).
pub mod shapes;

/// Small end-to-end `fit` cases (scene, truth light, rendered photo).
pub mod fit_case;

/// Lossless and glTF-Validator checks on outputs.
pub mod gltf_check;

/// Appends a fit setup (camera, water, wall, optional light) to glTF files we did not write.
pub mod augment;
