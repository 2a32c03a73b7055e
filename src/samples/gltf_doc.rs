//! The glTF text of a sample scene: a camera, the water (a generated mesh in an external
//! buffer, or one flat quad), solid quads (walls, quays) and the truth lights as
//! `EXT_lights_area`.

use base64::Engine;
use serde_json::{json, Value};

use super::water_surface::WaterMesh;
use super::SampleLight;
use crate::scene_in::{roughness_from_gloss, WATER_IOR};

/// A water mesh as the bytes of its glTF buffer: positions, normals (f32 x 3 each), then
/// u32 triangle indices.
pub struct WaterBuffer {
    /// The buffer's bytes.
    pub bytes: Vec<u8>,
    vertex_count: usize,
    index_count: usize,
    min: [f32; 3],
    max: [f32; 3],
}

impl WaterBuffer {
    /// The buffer of `mesh`.
    pub fn new(mesh: &WaterMesh) -> Self {
        let mut bytes = Vec::with_capacity(mesh.positions.len() * 24 + mesh.indices.len() * 4);
        let (min, max) = vec3_bounds(&mesh.positions);
        for p in &mesh.positions {
            for c in p {
                bytes.extend_from_slice(&c.to_le_bytes());
            }
        }
        for n in &mesh.normals {
            for c in n {
                bytes.extend_from_slice(&c.to_le_bytes());
            }
        }
        for i in &mesh.indices {
            bytes.extend_from_slice(&i.to_le_bytes());
        }
        WaterBuffer {
            bytes,
            vertex_count: mesh.positions.len(),
            index_count: mesh.indices.len(),
            min,
            max,
        }
    }
}

/// The per-component minimum and maximum of `points`, as a POSITION accessor's `min`, `max`.
pub fn vec3_bounds(points: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in points {
        for c in 0..3 {
            min[c] = min[c].min(p[c]);
            max[c] = max[c].max(p[c]);
        }
    }
    (min, max)
}

/// A planar quad: corners counter-clockwise seen from the side `normal` points to.
#[derive(Clone, Copy, Debug)]
pub struct Quad {
    /// The four corners.
    pub corners: [[f32; 3]; 4],
    /// The unit normal.
    pub normal: [f32; 3],
}

impl Quad {
    /// Level water at y = 0 from z = `near` to z = `far` (the camera looks down -z), `half`
    /// to either side of x = 0, facing up.
    pub fn level_water(near: f32, far: f32, half: f32) -> Quad {
        Quad {
            corners: [
                [-half, 0.0, near],
                [half, 0.0, near],
                [half, 0.0, far],
                [-half, 0.0, far],
            ],
            normal: [0.0, 1.0, 0.0],
        }
    }
}

/// A named mesh of quads, written as one data-URI buffer.
#[derive(Clone, Debug)]
pub struct Solid {
    /// Node and mesh name.
    pub name: String,
    /// Its quads.
    pub quads: Vec<Quad>,
}

/// The water of a scene.
pub enum WaterGeometry<'a> {
    /// A generated mesh in the external buffer file `uri`.
    Mesh {
        uri: &'a str,
        buffer: &'a WaterBuffer,
    },
    /// One flat quad, in a data URI.
    Flat(Quad),
}

/// The camera: at `translation`, looking down -z, pitched down by `pitch_degrees`.
#[derive(Clone, Debug)]
pub struct CameraPose {
    /// The camera's (not its node's) name.
    pub name: String,
    /// Position.
    pub translation: [f64; 3],
    /// Rotation down about +x; 0 writes no rotation at all.
    pub pitch_degrees: f64,
    /// Vertical field of view.
    pub yfov_degrees: f64,
}

/// Everything a sample scene file holds.
pub struct SceneParts<'a> {
    /// The scene's name.
    pub description: &'a str,
    /// The camera.
    pub camera: CameraPose,
    /// The water.
    pub water: WaterGeometry<'a>,
    /// The water material's Blinn-Phong gloss e (written as glTF roughness).
    pub gloss: f64,
    /// Walls and quays (non-emitting, dark).
    pub solids: Vec<Solid>,
    /// Truth lights, facing +z.
    pub lights: &'a [SampleLight],
}

fn data_uri(bytes: &[u8]) -> String {
    format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bytes)
    )
}

/// Appends `value` to the JSON array `list`, returning its index.
fn push(list: &mut Vec<Value>, value: Value) -> usize {
    list.push(value);
    list.len() - 1
}

/// The buffers, views and accessors being built.
#[derive(Default)]
struct Buffers {
    buffers: Vec<Value>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Buffers {
    /// A primitive's attributes from one buffer holding positions, normals, then indices
    /// (`index_type` 5123 = u16 or 5125 = u32).
    fn primitive(
        &mut self,
        buffer: Value,
        vertices: usize,
        indices: usize,
        index_type: u32,
        (min, max): ([f32; 3], [f32; 3]),
        material: usize,
    ) -> Value {
        let b = push(&mut self.buffers, buffer);
        let index_bytes = if index_type == 5123 { 2 } else { 4 };
        let v = self.views.len();
        self.views.extend([
            json!({"buffer": b, "byteOffset": 0, "byteLength": vertices * 12, "target": 34962}),
            json!({"buffer": b, "byteOffset": vertices * 12, "byteLength": vertices * 12, "target": 34962}),
            json!({"buffer": b, "byteOffset": vertices * 24, "byteLength": indices * index_bytes, "target": 34963}),
        ]);
        let a = self.accessors.len();
        self.accessors.extend([
            json!({"bufferView": v, "componentType": 5126, "count": vertices, "type": "VEC3", "min": min, "max": max}),
            json!({"bufferView": v + 1, "componentType": 5126, "count": vertices, "type": "VEC3"}),
            json!({"bufferView": v + 2, "componentType": index_type, "count": indices, "type": "SCALAR"}),
        ]);
        json!({"attributes": {"POSITION": a, "NORMAL": a + 1}, "indices": a + 2, "material": material})
    }

    /// A primitive of quads in a data-URI buffer.
    fn quads(&mut self, quads: &[Quad], material: usize) -> Value {
        let positions: Vec<[f32; 3]> = quads.iter().flat_map(|q| q.corners).collect();
        let mut bytes = Vec::new();
        for p in &positions {
            for c in p {
                bytes.extend_from_slice(&c.to_le_bytes());
            }
        }
        for q in quads {
            for _ in 0..4 {
                for c in q.normal {
                    bytes.extend_from_slice(&c.to_le_bytes());
                }
            }
        }
        for k in 0..quads.len() as u16 {
            for i in [0u16, 1, 2, 0, 2, 3] {
                bytes.extend_from_slice(&(4 * k + i).to_le_bytes());
            }
        }
        let buffer = json!({"uri": data_uri(&bytes), "byteLength": bytes.len()});
        let n = quads.len();
        self.primitive(
            buffer,
            4 * n,
            6 * n,
            5123,
            vec3_bounds(&positions),
            material,
        )
    }
}

/// The camera node's rotation for a pitch down by `degrees` (a turn about +x).
fn pitch_rotation(degrees: f64) -> [f64; 4] {
    let half = -0.5 * degrees.to_radians();
    [half.sin(), 0.0, 0.0, half.cos()]
}

/// The glTF document of `parts`.
pub fn scene_json(parts: &SceneParts) -> Value {
    let cam = &parts.camera;
    let mut camera_node = json!({"name": "Camera", "camera": 0, "translation": cam.translation});
    if cam.pitch_degrees != 0.0 {
        camera_node["rotation"] = json!(pitch_rotation(cam.pitch_degrees));
    }
    let mut nodes = vec![camera_node, json!({"name": "Water", "mesh": 0})];
    let mut buffers = Buffers::default();
    let water = match &parts.water {
        WaterGeometry::Mesh { uri, buffer } => buffers.primitive(
            json!({"uri": uri, "byteLength": buffer.bytes.len()}),
            buffer.vertex_count,
            buffer.index_count,
            5125,
            (buffer.min, buffer.max),
            0,
        ),
        WaterGeometry::Flat(quad) => buffers.quads(&[*quad], 0),
    };
    let mut meshes = vec![json!({"name": "Water", "primitives": [water]})];
    for solid in &parts.solids {
        let primitive = buffers.quads(&solid.quads, 1);
        let mesh = push(
            &mut meshes,
            json!({"name": solid.name, "primitives": [primitive]}),
        );
        nodes.push(json!({"name": solid.name, "mesh": mesh}));
    }
    let mut root_nodes: Vec<usize> = (0..nodes.len()).collect();
    let mut lights = Vec::new();
    for (i, light) in parts.lights.iter().enumerate() {
        let max = light.radiance.iter().cloned().fold(0.0, f64::max);
        let color = if max > 0.0 {
            light.radiance.map(|c| c / max)
        } else {
            [1.0; 3]
        };
        lights.push(json!({
            "name": light.name, "type": "rect", "color": color, "intensity": max,
            "size": light.height, "rect": {"aspect": light.width / light.height}
        }));
        root_nodes.push(nodes.len());
        // Emission is along local -Z; a half turn about Y makes it face +z, the water.
        nodes.push(json!({
            "name": light.name,
            "translation": light.center().to_array(),
            "rotation": [0.0, 1.0, 0.0, 0.0],
            "extensions": {"EXT_lights_area": {"light": i}}
        }));
    }
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": "streaklight samples"},
        "extensionsUsed": ["KHR_materials_ior"],
        "scene": 0,
        "scenes": [{"name": parts.description, "nodes": root_nodes}],
        "nodes": nodes,
        "cameras": [{"name": cam.name, "type": "perspective", "perspective": {
            "yfov": cam.yfov_degrees.to_radians(), "aspectRatio": 1.0, "znear": 0.01, "zfar": 200.0}}],
        "materials": [
            {"name": "Water", "pbrMetallicRoughness": {"baseColorFactor": [0.02, 0.03, 0.04, 1.0],
                "metallicFactor": 0.0, "roughnessFactor": roughness_from_gloss(parts.gloss as f32)},
             "extensions": {"KHR_materials_ior": {"ior": WATER_IOR}}},
            {"name": "Wall", "pbrMetallicRoughness": {"baseColorFactor": [0.05, 0.05, 0.05, 1.0],
                "metallicFactor": 0.0, "roughnessFactor": 1.0}}
        ],
        "meshes": meshes,
        "buffers": buffers.buffers,
        "bufferViews": buffers.views,
        "accessors": buffers.accessors
    });
    if !lights.is_empty() {
        if let Some(root) = doc.as_object_mut() {
            root.insert(
                "extensions".into(),
                json!({"EXT_lights_area": {"lights": lights}}),
            );
            if let Some(used) = root.get_mut("extensionsUsed").and_then(Value::as_array_mut) {
                used.push(json!("EXT_lights_area"));
            }
        }
    }
    doc
}
