//! The node hierarchy baked to world space, in f64.

use glam::DMat4;

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
pub fn world_instances(doc: &gltf::Document) -> Result<Vec<NodeInstance>, String> {
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
    for root in roots {
        visit(root, DMat4::IDENTITY, 0, &mut out)?;
    }
    Ok(out)
}

fn visit(
    node: gltf::Node,
    parent: DMat4,
    depth: usize,
    out: &mut Vec<NodeInstance>,
) -> Result<(), String> {
    if depth > MAX_DEPTH {
        return Err(format!(
            "the node hierarchy is deeper than {MAX_DEPTH} levels at node {}: is there a cycle?",
            node.index()
        ));
    }
    let local = node.transform().matrix();
    let local = DMat4::from_cols_array_2d(&local.map(|c| c.map(f64::from)));
    let world = parent * local;
    out.push(NodeInstance {
        node: node.index(),
        world,
    });
    for child in node.children() {
        visit(child, world, depth + 1, out)?;
    }
    Ok(())
}
