//! Every triangle of the scene, in the camera-centred frame.
//!
//! Positions are transformed to world space in f64 and only then recentred on the camera and
//! rounded to f32: far from the origin f32 spacing is as large as a ripple (METHOD §5.1).

use glam::{DMat3, DMat4, DVec3, Vec3};
use serde_json::Value;

use super::nodes::NodeInstance;

/// Where a triangle came from in the document.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TriangleSource {
    /// Node index.
    pub node: u32,
    /// Mesh index.
    pub mesh: u32,
    /// Primitive index within the mesh.
    pub primitive: u32,
}

/// The scene's triangles and their shading normals.
#[derive(Default)]
pub struct SceneTriangles {
    /// Corners in the scene frame.
    pub positions: Vec<[Vec3; 3]>,
    /// Unit shading normals at the corners (vertex normals where the mesh has them, else the
    /// face normal).
    pub normals: Vec<[Vec3; 3]>,
    /// Origin of each triangle.
    pub sources: Vec<TriangleSource>,
    /// Degenerate or non-finite triangles left out.
    pub dropped: usize,
    /// Primitives left out because they are not triangles, as messages.
    pub warnings: Vec<String>,
}

/// True when the node carries the marker of a fallback quad written by this tool: such quads
/// stand in for area lights in viewers without them and must not count as geometry.
pub fn is_fallback_quad(json: &Value, node: usize) -> bool {
    json.pointer(&format!("/nodes/{node}/extras/streaklight/role"))
        .and_then(Value::as_str)
        == Some("fallback-quad")
}

/// Collects the triangles of every mesh instance.
pub fn collect(
    doc: &gltf::Document,
    json: &Value,
    buffers: &[Vec<u8>],
    instances: &[NodeInstance],
    origin: DVec3,
) -> Result<SceneTriangles, String> {
    let mut out = SceneTriangles::default();
    for instance in instances {
        let Some(node) = doc.nodes().nth(instance.node) else {
            continue;
        };
        let Some(mesh) = node.mesh() else { continue };
        if is_fallback_quad(json, instance.node) {
            continue;
        }
        for primitive in mesh.primitives() {
            let source = TriangleSource {
                node: instance.node as u32,
                mesh: mesh.index() as u32,
                primitive: primitive.index() as u32,
            };
            add_primitive(
                &primitive,
                buffers,
                &instance.world,
                origin,
                source,
                &mut out,
            )?;
        }
    }
    Ok(out)
}

fn add_primitive(
    primitive: &gltf::Primitive,
    buffers: &[Vec<u8>],
    world: &DMat4,
    origin: DVec3,
    source: TriangleSource,
    out: &mut SceneTriangles,
) -> Result<(), String> {
    use gltf::mesh::Mode;
    let mode = primitive.mode();
    if !matches!(
        mode,
        Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
    ) {
        out.warnings.push(format!(
            "mesh {} primitive {} is {:?}, not triangles: skipped",
            source.mesh, source.primitive, mode
        ));
        return Ok(());
    }
    let where_ = || format!("mesh {} primitive {}", source.mesh, source.primitive);
    for accessor in primitive
        .attributes()
        .map(|(_, a)| a)
        .chain(primitive.indices())
    {
        if accessor.count() == 0 {
            return Err(format!(
                "{}: accessor {} is empty",
                where_(),
                accessor.index()
            ));
        }
    }
    let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let positions: Vec<[f32; 3]> = reader
        .read_positions()
        .ok_or_else(|| {
            format!(
                "{}: its POSITION data is missing or reaches past the end of its buffer",
                where_()
            )
        })?
        .collect();
    let normals: Option<Vec<[f32; 3]>> = match primitive.get(&gltf::Semantic::Normals) {
        Some(_) => Some(
            reader
                .read_normals()
                .ok_or_else(|| {
                    format!(
                        "{}: its NORMAL data reaches past the end of its buffer",
                        where_()
                    )
                })?
                .collect(),
        ),
        None => None,
    };
    let indices: Vec<u32> = match primitive.indices() {
        Some(_) => reader
            .read_indices()
            .ok_or_else(|| {
                format!(
                    "{}: its index data reaches past the end of its buffer",
                    where_()
                )
            })?
            .into_u32()
            .collect(),
        None => (0..positions.len() as u32).collect(),
    };
    if let Some(&bad) = indices.iter().find(|&&i| i as usize >= positions.len()) {
        return Err(format!(
            "{}: index {bad} is out of range ({} vertices)",
            where_(),
            positions.len()
        ));
    }
    if let Some(n) = &normals {
        if n.len() != positions.len() {
            return Err(format!(
                "{}: {} normals for {} positions",
                where_(),
                n.len(),
                positions.len()
            ));
        }
    }
    let world_positions: Vec<Vec3> = positions
        .iter()
        .map(|p| (world.transform_point3(DVec3::from(p.map(f64::from))) - origin).as_vec3())
        .collect();
    // Normals transform with the inverse transpose; a mirroring matrix flips the winding.
    let normal_matrix = DMat3::from_mat4(*world).inverse().transpose();
    let world_normals: Option<Vec<Vec3>> = normals.map(|ns| {
        ns.iter()
            .map(|n| {
                (normal_matrix * DVec3::from(n.map(f64::from)))
                    .normalize_or_zero()
                    .as_vec3()
            })
            .collect()
    });
    let triangle_list: Vec<[u32; 3]> = match mode {
        Mode::Triangles => indices
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect(),
        Mode::TriangleStrip => (2..indices.len())
            .map(|i| {
                if i % 2 == 0 {
                    [indices[i - 2], indices[i - 1], indices[i]]
                } else {
                    [indices[i - 1], indices[i - 2], indices[i]]
                }
            })
            .collect(),
        _ => (2..indices.len())
            .map(|i| [indices[0], indices[i - 1], indices[i]])
            .collect(),
    };
    for [a, b, c] in triangle_list {
        let v = [
            world_positions[a as usize],
            world_positions[b as usize],
            world_positions[c as usize],
        ];
        let face = (v[1] - v[0]).cross(v[2] - v[0]);
        let finite = v.iter().all(|p| p.is_finite());
        if !finite || !face.is_finite() || face.length_squared() <= 0.0 {
            out.dropped += 1;
            continue;
        }
        let face_normal = face.normalize();
        let n = match &world_normals {
            Some(ns) => {
                let corner = |i: u32| {
                    let n = ns[i as usize];
                    if n.is_finite() && n.length_squared() > 0.5 {
                        n
                    } else {
                        face_normal
                    }
                };
                [corner(a), corner(b), corner(c)]
            }
            None => [face_normal; 3],
        };
        out.positions.push(v);
        out.normals.push(n);
        out.sources.push(source);
    }
    Ok(())
}
