//! The fallback for viewers without area lights (method §7): under each light node, an
//! emissive one-sided quad of the light's size, facing where the light emits, a little in
//! front of the wall the light sits on ([`QUAD_LIFT`]).
//!
//! Binary layout of the new data (placed by the caller at a 4-byte aligned offset of some
//! buffer): one vertex buffer view with `byteStride` 12 holding, per light, 4 positions then
//! 4 normals (f32 x 3), followed by one index buffer view holding 6 u16 indices per light.
//! A stride is required because several accessors share the vertex view (glTF 2.0 §3.6.2.4).

use std::path::Path;

use serde_json::{json, Map, Value};

use super::edit::{push, use_extension};
use super::lights::PreparedLight;
use crate::Result;

/// The extension that lets `emissiveFactor` (capped at 1) carry a real brightness.
const EMISSIVE_STRENGTH: &str = "KHR_materials_emissive_strength";

/// glTF component types and buffer view targets.
const FLOAT: u32 = 5126;
const UNSIGNED_SHORT: u32 = 5123;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// Bytes of vertex data per light: 4 positions + 4 normals, 3 f32 each.
const VERTEX_BYTES: usize = 2 * 4 * 12;
/// Bytes of index data per light: 2 triangles of u16.
const INDEX_BYTES: usize = 6 * 2;

/// Triangles whose counter-clockwise side faces local -Z, the emission side. With the corners
/// below, (c1 - c0) x (c2 - c0) = +Z for 0-1-2, so the triangles list them the other way.
const INDICES: [u16; 6] = [0, 2, 1, 0, 3, 2];

/// The bytes of the quads for `lights`, in the layout above.
pub(crate) fn bytes(lights: &[PreparedLight]) -> Vec<u8> {
    let mut vertices = Vec::with_capacity(lights.len() * VERTEX_BYTES);
    let mut indices = Vec::with_capacity(lights.len() * INDEX_BYTES);
    for light in lights {
        for corner in corners(light) {
            for c in corner {
                vertices.extend_from_slice(&c.to_le_bytes());
            }
        }
        for _ in 0..4 {
            for c in [0.0f32, 0.0, -1.0] {
                vertices.extend_from_slice(&c.to_le_bytes());
            }
        }
        for i in INDICES {
            indices.extend_from_slice(&i.to_le_bytes());
        }
    }
    vertices.extend_from_slice(&indices);
    vertices
}

/// How far in front of the light (towards local -Z, where it emits) its quad sits, in metres.
/// A fitted light lies on the wall it was found on, and a quad in the wall's own plane
/// z-fights with it in every rasteriser: both depths round to the same value and the wall's
/// texels show through in stripes. A 24-bit depth buffer with a 0.1 m near plane resolves
/// about 6 mm at 100 m, so 2 cm keeps the quad in front out to well beyond the distances a
/// photo's lights are fitted at, while no viewer can see the gap.
pub(crate) const QUAD_LIFT: f32 = 0.02;

/// The quad's corners in the light node's frame: width along X, height along Y, centred,
/// [`QUAD_LIFT`] in front.
fn corners(light: &PreparedLight) -> [[f32; 3]; 4] {
    let (x, y) = ((light.width / 2.0) as f32, (light.height / 2.0) as f32);
    let z = -QUAD_LIFT;
    [[-x, -y, z], [x, -y, z], [x, y, z], [-x, y, z]]
}

/// Appends the buffer views, accessors, materials, meshes and quad nodes for `lights` to the
/// document, for data that [`bytes`] made and the caller stores at `byte_offset` of buffer
/// `buffer`. Returns the quad node of each light.
pub(crate) fn append(
    root: &mut Map<String, Value>,
    lights: &[PreparedLight],
    buffer: usize,
    byte_offset: usize,
    input: &Path,
) -> Result<Vec<usize>> {
    let n = lights.len();
    let vertex_view = push(
        root,
        "bufferViews",
        json!({
            "buffer": buffer,
            "byteOffset": byte_offset,
            "byteLength": n * VERTEX_BYTES,
            "byteStride": 12,
            "target": ARRAY_BUFFER,
            "name": "streaklight fallback quads: vertices",
        }),
        input,
    )?;
    let index_view = push(
        root,
        "bufferViews",
        json!({
            "buffer": buffer,
            "byteOffset": byte_offset + n * VERTEX_BYTES,
            "byteLength": n * INDEX_BYTES,
            "target": ELEMENT_ARRAY_BUFFER,
            "name": "streaklight fallback quads: indices",
        }),
        input,
    )?;
    let mut nodes = Vec::with_capacity(n);
    for (k, light) in lights.iter().enumerate() {
        let c = corners(light);
        // min/max must equal the stored f32 values exactly; f32 -> f64 is exact.
        let min = [c[0][0] as f64, c[0][1] as f64, c[0][2] as f64];
        let max = [c[2][0] as f64, c[2][1] as f64, c[2][2] as f64];
        let position = push(
            root,
            "accessors",
            json!({
                "bufferView": vertex_view,
                "byteOffset": k * VERTEX_BYTES,
                "componentType": FLOAT,
                "count": 4,
                "type": "VEC3",
                "min": min,
                "max": max,
            }),
            input,
        )?;
        let normal = push(
            root,
            "accessors",
            json!({
                "bufferView": vertex_view,
                "byteOffset": k * VERTEX_BYTES + VERTEX_BYTES / 2,
                "componentType": FLOAT,
                "count": 4,
                "type": "VEC3",
            }),
            input,
        )?;
        let index = push(
            root,
            "accessors",
            json!({
                "bufferView": index_view,
                "byteOffset": k * INDEX_BYTES,
                "componentType": UNSIGNED_SHORT,
                "count": 6,
                "type": "SCALAR",
            }),
            input,
        )?;
        let label = format!("{} (streaklight fallback quad)", light.name);
        let material = push(
            root,
            "materials",
            json!({
                "name": label,
                "pbrMetallicRoughness": {
                    "baseColorFactor": [0.0, 0.0, 0.0, 1.0],
                    "metallicFactor": 0.0,
                    "roughnessFactor": 1.0,
                },
                "emissiveFactor": light.color,
                "extensions": { EMISSIVE_STRENGTH: { "emissiveStrength": light.intensity } },
            }),
            input,
        )?;
        let mesh = push(
            root,
            "meshes",
            json!({
                "name": label,
                "primitives": [{
                    "attributes": { "POSITION": position, "NORMAL": normal },
                    "indices": index,
                    "material": material,
                    "mode": 4,
                }],
            }),
            input,
        )?;
        nodes.push(push(
            root,
            "nodes",
            json!({
                "name": label,
                "mesh": mesh,
                // What restore-lights needs to rebuild the light from the quad alone: the
                // light object and its node's transform in the world. Tools that drop the
                // extension may flatten, move or requantise the quad itself.
                "extras": { "streaklight": {
                    "role": "fallback-quad",
                    "light": super::lights::light_json(light),
                    "light_node": {
                        "translation": light.translation,
                        "rotation": light.rotation,
                        "wall_offset": light.offset,
                    },
                } },
            }),
            input,
        )?);
    }
    use_extension(root, EMISSIVE_STRENGTH, input)?;
    Ok(nodes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn front_faces_look_down_local_minus_z() {
        let light = PreparedLight {
            name: "l".into(),
            translation: [0.0; 3],
            rotation: [0.0, 0.0, 0.0, 1.0],
            width: 3.0,
            height: 1.0,
            color: [1.0; 3],
            intensity: 1.0,
            streak: None,
            offset: 0.0,
        };
        let c = corners(&light).map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64));
        for t in INDICES.chunks(3) {
            let (a, b, d) = (c[t[0] as usize], c[t[1] as usize], c[t[2] as usize]);
            let n = (b - a).cross(d - a);
            assert!(n.normalize().distance(DVec3::NEG_Z) < 1e-12, "{n}");
        }
        assert_eq!(bytes(&[light]).len(), VERTEX_BYTES + INDEX_BYTES);
    }
}
