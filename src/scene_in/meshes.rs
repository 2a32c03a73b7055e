//! Every triangle of the scene, in the camera-centred frame.
//!
//! Positions are transformed to world space in f64 and only then recentred on the camera and
//! rounded to f32: far from the origin f32 spacing is as large as a ripple (method §5 step 1).

use glam::{DMat3, DMat4, DVec3, Vec3};
use rayon::prelude::*;
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
    /// Vertices read so far, over every instance, against [`MAX_SCENE_VERTICES`].
    pub vertices_read: usize,
}

/// Most triangles a scene may have, over every instance and counting those left out: a few
/// bytes of glTF can instance a mesh many times, or declare a sparse accessor of any count.
pub const MAX_SCENE_TRIANGLES: usize = 1 << 24;
/// Largest distance from the camera, in metres along any axis, of a triangle kept: ten
/// thousand kilometres is past any scene this tool is for.
pub const MAX_COORDINATE: f32 = 1.0e7;
/// Most vertices read over every instance, for the same reason.
pub const MAX_SCENE_VERTICES: usize = 1 << 25;

/// True when the node carries the marker of a fallback quad written by this tool: such quads
/// stand in for area lights in viewers without them and must not count as geometry.
pub fn is_fallback_quad(json: &Value, node: usize) -> bool {
    json.pointer(&format!("/nodes/{node}/extras/streaklight/role"))
        .and_then(Value::as_str)
        == Some("fallback-quad")
}

/// Vertices or triangles a task of the parallel loops takes at least.
const PER_TASK: usize = 4096;

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
                json,
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
    json: &Value,
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
    // The `gltf` reader trusts the accessors it reads: it panics on a byteStride smaller than
    // an element, on an index accessor of floats, and overflows on a huge count. Check first.
    let position = primitive
        .get(&gltf::Semantic::Positions)
        .ok_or_else(|| format!("{}: it has no POSITION attribute", where_()))?;
    check_accessor(&position, Kind::Vec3F32, json, buffers)
        .map_err(|m| format!("{}: {m}", where_()))?;
    if let Some(normal) = primitive.get(&gltf::Semantic::Normals) {
        check_accessor(&normal, Kind::Vec3F32, json, buffers)
            .map_err(|m| format!("{}: {m}", where_()))?;
    }
    if let Some(indices) = primitive.indices() {
        check_accessor(&indices, Kind::Index, json, buffers)
            .map_err(|m| format!("{}: {m}", where_()))?;
    }
    out.vertices_read = out.vertices_read.saturating_add(position.count());
    if out.vertices_read > MAX_SCENE_VERTICES {
        return Err(format!(
            "{}: the scene has more than {MAX_SCENE_VERTICES} vertices (counting every instance); streaklight does not read scenes this large",
            where_()
        ));
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
    let triangle_count = match mode {
        Mode::Triangles => indices.len() / 3,
        _ => indices.len().saturating_sub(2),
    };
    if out.positions.len() + out.dropped + triangle_count > MAX_SCENE_TRIANGLES {
        return Err(format!(
            "{}: the scene has more than {MAX_SCENE_TRIANGLES} triangles (counting every instance); streaklight does not read scenes this large",
            where_()
        ));
    }
    // Per vertex and per triangle on every core: the harbour's and Table 1's water meshes hold
    // half a million triangles, whose corners took 60 ms of the 0.1 s load on one core.
    let world_positions: Vec<Vec3> = positions
        .par_iter()
        .with_min_len(PER_TASK)
        .map(|p| (world.transform_point3(DVec3::from(p.map(f64::from))) - origin).as_vec3())
        .collect();
    // Normals transform with the inverse transpose; a mirroring matrix flips the winding.
    let normal_matrix = DMat3::from_mat4(*world).inverse().transpose();
    let world_normals: Option<Vec<Vec3>> = normals.map(|ns| {
        ns.par_iter()
            .with_min_len(PER_TASK)
            .map(|n| {
                (normal_matrix * DVec3::from(n.map(f64::from)))
                    .normalize_or_zero()
                    .as_vec3()
            })
            .collect()
    });
    let corners = |t: usize| -> [u32; 3] {
        match mode {
            Mode::Triangles => [indices[3 * t], indices[3 * t + 1], indices[3 * t + 2]],
            Mode::TriangleStrip => {
                let i = t + 2;
                if i.is_multiple_of(2) {
                    [indices[i - 2], indices[i - 1], indices[i]]
                } else {
                    [indices[i - 1], indices[i - 2], indices[i]]
                }
            }
            _ => [indices[0], indices[t + 1], indices[t + 2]],
        }
    };
    let kept = |t: usize| -> Option<([Vec3; 3], [Vec3; 3])> {
        let [a, b, c] = corners(t);
        let v = [
            world_positions[a as usize],
            world_positions[b as usize],
            world_positions[c as usize],
        ];
        let face = (v[1] - v[0]).cross(v[2] - v[0]);
        // Farther than MAX_COORDINATE counts as non-finite: the BVH builder's surface areas
        // overflow on such extents and it panics (found by fuzzing).
        let finite = v
            .iter()
            .all(|p| p.is_finite() && p.abs().max_element() <= MAX_COORDINATE);
        if !finite || !face.is_finite() || face.length_squared() <= 0.0 {
            return None;
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
        Some((v, n))
    };
    // In the primitive's order whatever the cores do, written in place (a filter would
    // gather the cores' parts and copy them again); a triangle left out is marked by a NaN
    // corner and taken out after, which few scenes need.
    let (mut kept_positions, mut kept_normals) = (Vec::new(), Vec::new());
    (0..triangle_count)
        .into_par_iter()
        .with_min_len(PER_TASK)
        .map(|t| kept(t).unwrap_or(([Vec3::NAN; 3], [Vec3::NAN; 3])))
        .unzip_into_vecs(&mut kept_positions, &mut kept_normals);
    let dropped = kept_positions.iter().filter(|v| v[0].is_nan()).count();
    if dropped > 0 {
        let mut kept = kept_positions.iter().map(|v| !v[0].is_nan());
        kept_normals.retain(|_| kept.next().unwrap_or(false));
        kept_positions.retain(|v| !v[0].is_nan());
    }
    out.dropped += dropped;
    out.sources
        .extend(std::iter::repeat_n(source, kept_positions.len()));
    if out.positions.is_empty() {
        out.positions = kept_positions;
        out.normals = kept_normals;
    } else {
        out.positions.append(&mut kept_positions);
        out.normals.append(&mut kept_normals);
    }
    Ok(())
}

/// What an accessor must hold to be read by this module.
#[derive(Clone, Copy)]
enum Kind {
    /// POSITION and NORMAL: three floats.
    Vec3F32,
    /// Indices: unsigned integer scalars.
    Index,
}

/// Checks what the `gltf` reader assumes of an accessor: its type, and that every element it
/// reads lies inside its buffer view and buffer, with a stride no smaller than an element.
fn check_accessor(
    accessor: &gltf::Accessor,
    kind: Kind,
    json: &Value,
    buffers: &[Vec<u8>],
) -> Result<(), String> {
    use gltf::accessor::{DataType, Dimensions};
    let index = accessor.index();
    let (data_type, dimensions) = (accessor.data_type(), accessor.dimensions());
    match kind {
        Kind::Vec3F32 if (data_type, dimensions) != (DataType::F32, Dimensions::Vec3) => {
            return Err(format!(
                "accessor {index} is {dimensions:?} of {data_type:?}; positions and normals must be Vec3 of F32"
            ));
        }
        Kind::Index
            if dimensions != Dimensions::Scalar
                || !matches!(data_type, DataType::U8 | DataType::U16 | DataType::U32) =>
        {
            return Err(format!(
                "accessor {index} is {dimensions:?} of {data_type:?}; indices must be unsigned integer scalars"
            ));
        }
        _ => {}
    }
    let count = accessor.count();
    let size = accessor.size();
    let what = format!("accessor {index}");
    if let Some(view) = accessor.view() {
        check_span(&what, &view, accessor.offset(), count, size, buffers)?;
    }
    let Some(sparse) = accessor.sparse() else {
        return Ok(());
    };
    if accessor.view().is_none() && count > MAX_SCENE_VERTICES {
        // Without a buffer view the count is not backed by any data: bound it.
        return Err(format!(
            "{what} declares {count} elements with no buffer view; streaklight reads at most {MAX_SCENE_VERTICES}"
        ));
    }
    let sparse_count = sparse.count();
    if sparse_count == 0 || sparse_count > count {
        return Err(format!(
            "{what}: its sparse count {sparse_count} is not between 1 and its count {count}"
        ));
    }
    // `Indices::index_type` panics on a float component type, which validation lets through.
    let index_size = match json
        .pointer(&format!("/accessors/{index}/sparse/indices/componentType"))
        .and_then(Value::as_u64)
    {
        Some(5121) => 1,
        Some(5123) => 2,
        Some(5125) => 4,
        other => {
            return Err(format!(
                "{what}: its sparse indices have component type {other:?}, not an unsigned integer"
            ))
        }
    };
    let indices = sparse.indices();
    check_span(
        &format!("{what}'s sparse indices"),
        &indices.view(),
        indices.offset(),
        sparse_count,
        index_size,
        buffers,
    )?;
    let values = sparse.values();
    check_span(
        &format!("{what}'s sparse values"),
        &values.view(),
        values.offset(),
        sparse_count,
        size,
        buffers,
    )
}

/// Checks that `count` elements of `size` bytes from `offset` in `view` lie inside the view
/// and the view inside its buffer, in checked arithmetic.
fn check_span(
    what: &str,
    view: &gltf::buffer::View,
    offset: usize,
    count: usize,
    size: usize,
    buffers: &[Vec<u8>],
) -> Result<(), String> {
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(format!(
            "{what}: buffer view {} has byteStride {stride}, smaller than one element ({size} bytes)",
            view.index()
        ));
    }
    let end = count
        .checked_sub(1)
        .and_then(|n| n.checked_mul(stride))
        .and_then(|n| n.checked_add(size))
        .and_then(|n| n.checked_add(offset));
    if end.is_none_or(|end| end > view.length()) {
        return Err(format!(
            "{what}: {count} elements from byte {offset} reach past the end of buffer view {} ({} bytes)",
            view.index(),
            view.length()
        ));
    }
    let buffer_len = buffers.get(view.buffer().index()).map_or(0, Vec::len);
    if view
        .offset()
        .checked_add(view.length())
        .is_none_or(|end| end > buffer_len)
    {
        return Err(format!(
            "{what}: buffer view {} (bytes {} to {} + {}) reaches past the end of buffer {} ({buffer_len} bytes)",
            view.index(),
            view.offset(),
            view.offset(),
            view.length(),
            view.buffer().index()
        ));
    }
    Ok(())
}
