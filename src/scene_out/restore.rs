//! `restore-lights`: bring back the `EXT_lights_area` lights that a tool without the extension
//! dropped (glTF-Transform without its Extension class drops unknown extensions, but keeps
//! nodes, meshes and extras). Every fallback quad carries its light's object and its light
//! node's world transform in `extras.streaklight` (`light`, `light_node`), so the quad alone
//! rebuilds the light, wherever a tool moved or requantised the quad itself:
//!
//! - its parent is a streaklight light node without the extension (the hierarchy is as
//!   written): the light goes back on it;
//! - otherwise (a tool flattened the hierarchy or removed the parent): a new light node with
//!   the recorded transform, in the default scene.
//!
//! A quad whose light is still in the document (on its parent, or on a node whose light has
//! the same name) is left alone.

use std::path::Path;

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
    let nodes: Vec<Value> = staged
        .json
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
    // Names of the lights the document's nodes still have.
    let present: Vec<Value> = nodes
        .iter()
        .filter_map(|n| {
            n.pointer(&format!("/extensions/{EXTENSION}/light"))?
                .as_u64()
        })
        .filter_map(|i| {
            staged
                .json
                .pointer(&format!("/extensions/{EXTENSION}/lights/{i}/name"))
                .cloned()
        })
        .collect();
    let root = root_mut(&mut staged.json, input)?;
    let mut summary = RestoreSummary {
        restored_nodes: Vec::new(),
        already_present: 0,
        resources: ResourceHandling::default(),
    };
    for (quad, light) in quads {
        let parent = parents[quad];
        if parent.is_some_and(has_light) || light.get("name").is_some_and(|n| present.contains(n)) {
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
                let (translation, rotation) = recorded_transform(&nodes[quad], quad, input)?;
                let name = light.get("name").cloned().unwrap_or(json!("light"));
                let offset = nodes[quad].pointer("/extras/streaklight/light_node/wall_offset");
                let mut node = light_node(name, lights.len(), rotation, translation);
                if let Some(offset) = offset.filter(|o| o.is_number()) {
                    node["extras"]["streaklight"]["wall_offset"] = offset.clone();
                }
                lights.push(light);
                let node = push(root, "nodes", node, input)?;
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
    summary.resources = staged.write(output, Vec::new())?;
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

/// A new light node: no scale, marked as streaklight's.
fn light_node(name: Value, index: usize, rotation: [f64; 4], translation: [f64; 3]) -> Value {
    json!({
        "name": name,
        "translation": translation,
        "rotation": rotation,
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

/// The light node's world translation and rotation recorded in a fallback quad's extras.
fn recorded_transform(
    quad_node: &Value,
    quad: usize,
    input: &Path,
) -> Result<([f64; 3], [f64; 4])> {
    let numbers = |key: &str| -> Option<Vec<f64>> {
        quad_node
            .pointer(&format!("/extras/streaklight/light_node/{key}"))?
            .as_array()?
            .iter()
            .map(Value::as_f64)
            .collect()
    };
    let t = numbers("translation").and_then(|v| <[f64; 3]>::try_from(v).ok());
    let r = numbers("rotation").and_then(|v| <[f64; 4]>::try_from(v).ok());
    match (t, r) {
        (Some(t), Some(r)) => Ok((t, r)),
        _ => Err(Error::scene(
            input,
            format!(
                "node {quad} is a fallback quad whose parent is not its light's node, and its \
                 extras.streaklight.light_node has no translation and rotation to place the light"
            ),
        )),
    }
}
