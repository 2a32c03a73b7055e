//! `restore-lights`: bring back the `EXT_lights_area` lights that a tool without the extension
//! dropped (glTF-Transform without its Extension class drops unknown extensions, but keeps
//! nodes, meshes and extras). Every fallback quad carries its light's object in
//! `extras.streaklight.light`, and the quad's node frame is the light's (it is a child of the
//! light's node without a transform of its own), so the quad alone rebuilds the light:
//!
//! - its parent is a streaklight light node without the extension: the light goes back on it;
//! - otherwise (a tool flattened the hierarchy or removed the parent): a new light node at the
//!   quad's world transform, in the default scene.
//!
//! A quad whose parent still has its light is left alone.

use std::path::Path;

use glam::{DMat4, DQuat, DVec3};
use serde_json::{json, Value};

use super::edit::{array_mut, object_mut, push, root_mut, use_extension};
use super::{staged, target_scene, InputFiles, ResourceHandling, EXTENSION};
use crate::{Error, Result};

/// What [`restore_lights`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct RestoreSummary {
    /// The node of each light put back (on its old node, or a new one).
    pub restored_nodes: Vec<usize>,
    /// Fallback quads whose light was still there.
    pub already_present: usize,
    /// Binary data and external files, as for [`super::write_lit_scene`].
    pub resources: ResourceHandling,
}

/// Reads `input`, puts back every light its streaklight fallback quads describe (see the
/// module docs) and writes the result as `output`, self-contained like every output.
pub fn restore_lights(input: &Path, output: &Path, files: InputFiles) -> Result<RestoreSummary> {
    let mut staged = staged::stage(input, output, files)?;
    let root = root_mut(&mut staged.json, input)?;
    let nodes: Vec<Value> = root
        .get("nodes")
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    let quads: Vec<(usize, Value)> = nodes
        .iter()
        .enumerate()
        .filter(|(_, n)| n.pointer("/extras/streaklight/role") == Some(&json!("fallback-quad")))
        .filter_map(|(i, n)| Some((i, n.pointer("/extras/streaklight/light")?.clone())))
        .collect();
    if quads.is_empty() {
        return Err(Error::scene(
            input,
            "it holds no streaklight fallback quad with its light's data in extras, so there is \
             nothing to restore the lights from (was it written with --no-fallback-quads, or \
             did a tool drop the nodes' extras?)",
        ));
    }
    let parents = parents(&nodes);
    let has_light = |n: usize| {
        nodes[n]
            .pointer(&format!("/extensions/{EXTENSION}/light"))
            .is_some()
    };
    let mut summary = RestoreSummary {
        restored_nodes: Vec::new(),
        already_present: 0,
        resources: ResourceHandling::default(),
    };
    for (quad, light) in quads {
        let parent = parents[quad];
        if parent.is_some_and(has_light) {
            summary.already_present += 1;
            continue;
        }
        check_light(&light, quad, input)?;
        let lights = array_mut(
            object_mut(object_mut(root, "extensions", input)?, EXTENSION, input)?,
            "lights",
            input,
        )?;
        let parent_is_ours = parent
            .filter(|&p| nodes[p].pointer("/extras/streaklight/role") == Some(&json!("light")));
        let node = match parent_is_ours {
            Some(p) => {
                lights.push(light);
                let index = lights.len() - 1;
                let node = array_mut(root, "nodes", input)?
                    .get_mut(p)
                    .and_then(Value::as_object_mut)
                    .ok_or_else(|| Error::scene(input, format!("node {p} is not an object")))?;
                object_mut(node, "extensions", input)?
                    .insert(EXTENSION.into(), json!({ "light": index }));
                p
            }
            None => {
                let world = world_matrix(&nodes, &parents, quad, input)?;
                let (scale, rotation, translation) = world.to_scale_rotation_translation();
                let mut light = light;
                scale_light(&mut light, scale);
                let name = light.get("name").cloned().unwrap_or(json!("light"));
                lights.push(light);
                let index = lights.len() - 1;
                let node = push(
                    root,
                    "nodes",
                    light_node(name, index, rotation, translation),
                    input,
                )?;
                let scene = target_scene(root, input)?;
                if let Some(list) = root
                    .get_mut("scenes")
                    .and_then(|s| s.get_mut(scene))
                    .and_then(Value::as_object_mut)
                {
                    array_mut(list, "nodes", input)?.push(Value::from(node));
                }
                node
            }
        };
        summary.restored_nodes.push(node);
    }
    if !summary.restored_nodes.is_empty() {
        use_extension(root, EXTENSION, input)?;
    }
    summary.resources = staged.write(output)?;
    Ok(summary)
}

/// A light object must at least be a rectangle with a size to be written back.
fn check_light(light: &Value, quad: usize, input: &Path) -> Result<()> {
    let ok = light.get("type") == Some(&json!("rect"))
        && light
            .get("size")
            .and_then(Value::as_f64)
            .is_some_and(|s| s > 0.0)
        && light
            .pointer("/rect/aspect")
            .and_then(Value::as_f64)
            .is_some_and(|a| a > 0.0);
    if ok {
        Ok(())
    } else {
        Err(Error::scene(
            input,
            format!("node {quad}'s extras.streaklight.light is not a rect light with a size and aspect: {light}"),
        ))
    }
}

/// A light whose quad a tool scaled (e.g. by flattening under a scaled parent) keeps its size
/// in the world: the rectangle's height scales with local Y, its width with local X.
fn scale_light(light: &mut Value, scale: DVec3) {
    if (scale - DVec3::ONE).abs().max_element() < 1e-12 {
        return;
    }
    let size = light["size"].as_f64().unwrap_or(1.0);
    let aspect = light["rect"]["aspect"].as_f64().unwrap_or(1.0);
    light["size"] = json!(size * scale.y);
    light["rect"]["aspect"] = json!(aspect * scale.x / scale.y);
}

/// A new light node: no scale, marked as streaklight's.
fn light_node(name: Value, index: usize, rotation: DQuat, translation: DVec3) -> Value {
    let q = if rotation.w < 0.0 {
        -rotation
    } else {
        rotation
    };
    json!({
        "name": name,
        "translation": translation.to_array(),
        "rotation": q.normalize().to_array(),
        "extensions": { EXTENSION: { "light": index } },
        "extras": { "streaklight": { "role": "light" } },
    })
}

/// Each node's parent.
fn parents(nodes: &[Value]) -> Vec<Option<usize>> {
    let mut out = vec![None; nodes.len()];
    for (p, node) in nodes.iter().enumerate() {
        for child in node
            .get("children")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
        {
            if let Some(c) = child.as_u64().and_then(|c| usize::try_from(c).ok()) {
                if let Some(slot) = out.get_mut(c) {
                    *slot = Some(p);
                }
            }
        }
    }
    out
}

/// A node's local transform (`matrix`, or translation/rotation/scale).
fn local_matrix(node: &Value) -> DMat4 {
    let floats = |key: &str| -> Option<Vec<f64>> {
        node.get(key)?
            .as_array()?
            .iter()
            .map(Value::as_f64)
            .collect()
    };
    if let Some(m) = floats("matrix").filter(|m| m.len() == 16) {
        return DMat4::from_cols_slice(&m);
    }
    let t = floats("translation")
        .filter(|v| v.len() == 3)
        .map_or(DVec3::ZERO, |v| DVec3::from_slice(&v));
    let r = floats("rotation")
        .filter(|v| v.len() == 4)
        .map_or(DQuat::IDENTITY, |v| DQuat::from_slice(&v).normalize());
    let s = floats("scale")
        .filter(|v| v.len() == 3)
        .map_or(DVec3::ONE, |v| DVec3::from_slice(&v));
    DMat4::from_scale_rotation_translation(s, r, t)
}

/// A node's world transform, through its parents.
fn world_matrix(
    nodes: &[Value],
    parents: &[Option<usize>],
    node: usize,
    input: &Path,
) -> Result<DMat4> {
    let mut m = local_matrix(&nodes[node]);
    let mut at = node;
    for _ in 0..nodes.len() {
        let Some(p) = parents[at] else {
            return Ok(m);
        };
        m = local_matrix(&nodes[p]) * m;
        at = p;
    }
    Err(Error::scene(
        input,
        format!("node {node}'s parents form a cycle"),
    ))
}
