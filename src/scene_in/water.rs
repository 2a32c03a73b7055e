//! Which node is the water (method §3), and its glossiness and index of refraction.

use serde_json::Value;

use super::meshes::is_fallback_quad;
use super::nodes::NodeInstance;
use crate::settings::Setting;

/// The water surface and its optical constants.
#[derive(Clone, Debug)]
pub struct Water {
    /// Index of the water's node in the document.
    pub node: usize,
    /// The node's name (or its mesh's name).
    pub name: String,
    /// Blinn-Phong exponent e of the paper.
    pub gloss: f32,
    /// Index of refraction.
    pub ior: f32,
    /// Where the gloss came from, for the report.
    pub gloss_source: String,
}

/// Water's index of refraction, used when the material does not state one (glTF's default
/// of 1.5 is for glass, not water).
pub const WATER_IOR: f32 = 1.33;
/// Gloss used when the water has no material to derive it from.
pub const DEFAULT_GLOSS: f32 = 500.0;
/// Upper bound on the gloss derived from a roughness near zero (a mirror).
pub const MAX_GLOSS: f32 = 100_000.0;

/// Blinn-Phong exponent for a glTF roughness r: alpha = r^2, e = 2/alpha^2 - 2 (Walter et
/// al. 2007's Beckmann correspondence; r = 0.2512 gives e = 500).
pub fn gloss_from_roughness(roughness: f32) -> f32 {
    let alpha = (roughness as f64).powi(2);
    if alpha <= 0.0 {
        return MAX_GLOSS;
    }
    ((2.0 / (alpha * alpha) - 2.0) as f32).min(MAX_GLOSS)
}

/// The roughness that gives gloss `e`, the inverse of [`gloss_from_roughness`].
pub fn roughness_from_gloss(gloss: f32) -> f32 {
    let alpha = (2.0 / (gloss as f64 + 2.0)).sqrt();
    alpha.sqrt() as f32
}

fn display_name(doc: &gltf::Document, node: usize) -> String {
    let Some(n) = doc.nodes().nth(node) else {
        return format!("node {node}");
    };
    n.name()
        .map(crate::names::escaped)
        .or_else(|| n.mesh().and_then(|m| m.name().map(crate::names::escaped)))
        .unwrap_or_else(|| format!("node {node}"))
}

/// Picks the water node: `requested` by exact node or mesh name, else the single mesh node
/// whose node or mesh name contains "water" (any case).
pub fn choose(
    doc: &gltf::Document,
    json: &Value,
    instances: &[NodeInstance],
    requested: Option<&str>,
) -> Result<usize, String> {
    let mut mesh_nodes: Vec<usize> = instances
        .iter()
        .map(|i| i.node)
        .filter(|&n| {
            doc.nodes().nth(n).is_some_and(|node| node.mesh().is_some())
                && !is_fallback_quad(json, n)
        })
        .collect();
    mesh_nodes.dedup();
    let names = |list: &[usize]| {
        list.iter()
            .map(|&n| format!("\"{}\"", display_name(doc, n)))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let node_and_mesh_names = |n: usize| -> Vec<String> {
        let Some(node) = doc.nodes().nth(n) else {
            return Vec::new();
        };
        node.name()
            .into_iter()
            .chain(node.mesh().and_then(|m| m.name()))
            .map(str::to_owned)
            .collect()
    };
    let candidates: Vec<usize> = match requested {
        Some(want) => mesh_nodes
            .iter()
            .copied()
            .filter(|&n| node_and_mesh_names(n).iter().any(|s| s == want))
            .collect(),
        None => mesh_nodes
            .iter()
            .copied()
            .filter(|&n| {
                node_and_mesh_names(n)
                    .iter()
                    .any(|s| s.to_lowercase().contains("water"))
            })
            .collect(),
    };
    match (candidates.len(), requested) {
        (1, _) => Ok(candidates[0]),
        (0, Some(want)) => Err(format!(
            "no mesh node is named \"{want}\"; the mesh nodes are: {}",
            names(&mesh_nodes)
        )),
        (0, None) => Err(format!(
            "no water node: no mesh node's name contains \"water\"; {} names it. The mesh nodes are: {}",
            Setting::Water,
            names(&mesh_nodes)
        )),
        (_, Some(want)) => Err(format!(
            "several mesh nodes are named \"{want}\": {}",
            names(&candidates)
        )),
        (_, None) => Err(format!(
            "several nodes could be the water: {}; {} chooses one",
            names(&candidates),
            Setting::Water
        )),
    }
}

/// The indices of refraction accepted: light reflects off a surface only above 1, and no
/// liquid (nor most solids) reaches 3; outside this, a material's value is a mistake.
pub const IOR_RANGE: (f32, f32) = (1.0, 3.0);

/// Reads the water's gloss and IOR from its material, with the user's overrides. An IOR
/// outside [`IOR_RANGE`] (1 excluded) is refused, naming where it came from.
pub fn optics(
    doc: &gltf::Document,
    node: usize,
    gloss_override: Option<f32>,
    ior_override: Option<f32>,
    warnings: &mut Vec<String>,
) -> std::result::Result<Water, String> {
    let name = display_name(doc, node);
    let material = doc
        .nodes()
        .nth(node)
        .and_then(|n| n.mesh())
        .and_then(|m| m.primitives().next())
        .map(|p| p.material())
        .filter(|m| m.index().is_some());
    let (gloss, gloss_source) = match (gloss_override, &material) {
        (Some(e), _) => (e, Setting::Gloss.to_string()),
        (None, Some(m)) => {
            let r = m.pbr_metallic_roughness().roughness_factor();
            (gloss_from_roughness(r), format!("material roughness {r}"))
        }
        (None, None) => {
            warnings.push(format!(
                "the water \"{name}\" has no material; using gloss e = {DEFAULT_GLOSS} ({} sets it)",
                Setting::Gloss
            ));
            (DEFAULT_GLOSS, "default".to_owned())
        }
    };
    let ior = ior_override
        .or_else(|| material.as_ref().and_then(|m| m.ior()))
        .unwrap_or(WATER_IOR);
    if !(ior > IOR_RANGE.0 && ior <= IOR_RANGE.1) {
        let source = match (ior_override, &material) {
            (Some(_), _) => Setting::Ior.to_string(),
            (None, Some(m)) => format!(
                "the water's material \"{}\" (KHR_materials_ior)",
                m.name()
                    .map(crate::names::escaped)
                    .unwrap_or_else(|| format!("{}", m.index().unwrap_or(0)))
            ),
            (None, None) => "the default".into(),
        };
        return Err(format!(
            "the index of refraction {ior} of {source} is outside {} < IOR <= {} (water: \
             {WATER_IOR}); light would not reflect as it does off water ({} overrides it)",
            IOR_RANGE.0,
            IOR_RANGE.1,
            Setting::Ior
        ));
    }
    Ok(Water {
        node,
        name,
        gloss,
        ior,
        gloss_source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roughness_gloss_correspondence() {
        // method §3: r = 0.2512 gives e = 500.
        assert!((gloss_from_roughness(0.2512) - 500.0).abs() < 1.0);
        for e in [50.0f32, 200.0, 500.0, 2000.0] {
            let back = gloss_from_roughness(roughness_from_gloss(e));
            assert!((back - e).abs() / e < 1e-4, "{e} -> {back}");
        }
    }
}
