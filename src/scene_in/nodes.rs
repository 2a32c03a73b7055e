//! The node hierarchy baked to world space, in f64.

use glam::{DMat4, DQuat, DVec3};
use serde_json::Value;

/// One appearance of a node in the scene, with its world matrix.
#[derive(Clone, Debug)]
pub struct NodeInstance {
    /// Index of the node in the document.
    pub node: usize,
    /// Local-to-world matrix, composed in f64.
    pub world: DMat4,
}

/// Deeper hierarchies than this are treated as a cycle (glTF forbids cycles; a broken file
/// must not recurse without end).
const MAX_DEPTH: usize = 256;

/// Every node instance of the document's default scene (or its first scene; or, with no
/// scenes at all, every node that is nobody's child), parents before children, in file order.
pub fn world_instances(doc: &gltf::Document, json: &Value) -> Result<Vec<NodeInstance>, String> {
    let roots: Vec<gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(scene) => scene.nodes().collect(),
        None => {
            let mut is_child = vec![false; doc.nodes().len()];
            for node in doc.nodes() {
                for child in node.children() {
                    is_child[child.index()] = true;
                }
            }
            doc.nodes().filter(|n| !is_child[n.index()]).collect()
        }
    };
    let mut out = Vec::new();
    // glTF gives a node at most one parent. A node reached twice would be instanced twice,
    // and a chain of nodes each listing the next one twice would double the count at every
    // level: 2^256 instances from a few hundred bytes.
    let mut seen = vec![false; doc.nodes().len()];
    for root in roots {
        visit(root, json, DMat4::IDENTITY, 0, &mut seen, &mut out)?;
    }
    Ok(out)
}

/// The node's local matrix in f64, read from the JSON: the `gltf` crate stores translations
/// as f32, which at 1e5 m from the origin loses centimetres.
fn local_matrix(node: &gltf::Node, json: &Value) -> DMat4 {
    let obj = json.pointer(&format!("/nodes/{}", node.index()));
    let numbers = |key: &str, n: usize| -> Option<Vec<f64>> {
        let arr = obj?.get(key)?.as_array()?;
        let v: Vec<f64> = arr.iter().filter_map(Value::as_f64).collect();
        (v.len() == n && v.iter().all(|x| x.is_finite())).then_some(v)
    };
    if let Some(m) = numbers("matrix", 16) {
        return DMat4::from_cols_slice(&m);
    }
    let t = numbers("translation", 3).map_or(DVec3::ZERO, |v| DVec3::new(v[0], v[1], v[2]));
    let r = numbers("rotation", 4)
        .map(|v| DQuat::from_xyzw(v[0], v[1], v[2], v[3]))
        .and_then(|q| (q.length_squared() > 0.0).then(|| q.normalize()))
        .unwrap_or(DQuat::IDENTITY);
    let s = numbers("scale", 3).map_or(DVec3::ONE, |v| DVec3::new(v[0], v[1], v[2]));
    DMat4::from_scale_rotation_translation(s, r, t)
}

fn visit(
    node: gltf::Node,
    json: &Value,
    parent: DMat4,
    depth: usize,
    seen: &mut [bool],
    out: &mut Vec<NodeInstance>,
) -> Result<(), String> {
    if depth > MAX_DEPTH {
        return Err(format!(
            "the node hierarchy is deeper than {MAX_DEPTH} levels at node {}: is there a cycle?",
            node.index()
        ));
    }
    match seen.get_mut(node.index()) {
        Some(s) if *s => {
            return Err(format!(
                "node {} is reached more than once in the scene (a node may have only one parent, and no cycles)",
                node.index()
            ))
        }
        Some(s) => *s = true,
        None => {}
    }
    let world = parent * local_matrix(&node, json);
    out.push(NodeInstance {
        node: node.index(),
        world,
    });
    for child in node.children() {
        visit(child, json, world, depth + 1, seen, out)?;
    }
    Ok(())
}
