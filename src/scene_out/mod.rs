//! Step 10 of the pipeline (method §5, §7): write the fitted lights into the user's glTF,
//! losslessly, as a self-contained output.
//!
//! The document is edited as JSON: every existing key, value and index stays as it was, and
//! new objects are appended (`extensionsUsed`, the top-level `EXT_lights_area.lights`, nodes
//! added to the scene, and for the fallback quads buffer views, accessors, materials and
//! meshes). Existing binary data is never rewritten; new data is appended after it.
//!
//! The output needs nothing outside its own folder (`staged`): a `.glb` holds every buffer
//! and image in its BIN chunk (`embed`), a `.gltf` gets copies of the input's files beside it
//! under names made from its own (`side_files`), unless [`InputFiles::Reference`] asks to
//! refer to them where they are. Only the container's storage changes: for a `.glb`, the
//! buffers merge into buffer 0 and images become buffer views; for a `.gltf`, URIs name the
//! copies. Every value read through them is the same.

mod ahead;
mod document;
mod edit;
mod embed;
mod fallback_quad;
mod lights;
mod resources;
mod restore;
mod side_files;
mod staged;

use std::path::{Path, PathBuf};

use glam::DVec3;
use serde_json::{json, Value};

use crate::{Error, Result};
use edit::{array_mut, len_of, object_mut, push, root_mut, use_extension};

pub use ahead::CopiesAhead;
pub use lights::EXTENSION;
pub use restore::{restore_lights, RestoreSummary};

/// What writing the scene `input` as `output` involves, known before any work.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Plan {
    /// The files it reads: the input and the local buffer and image files it refers to.
    pub reads: Vec<PathBuf>,
    /// The files it may write: the output and the files beside it.
    pub writes: Vec<PathBuf>,
    /// The names of the lights a run of streaklight already wrote into the input (nodes
    /// marked `extras.streaklight.role = "light"`).
    pub own_lights: Vec<String>,
}

/// Reads `input` and tells what writing it as `output` involves: the caller checks the files
/// against its own inputs and outputs before any work.
pub fn plan(input: &Path, output: &Path, files: InputFiles) -> Result<Plan> {
    staged::plan(input, output, files)
}

/// One fitted light, in world space, as the fitter hands it over.
#[derive(Debug, Clone, PartialEq)]
pub struct LightToWrite {
    /// Name of the light (and of its node).
    pub name: String,
    /// Centre of the rectangle, world space.
    pub center: DVec3,
    /// Unit vector: the direction the light emits (towards the water). Becomes the node's -Z.
    pub normal: DVec3,
    /// Unit vector perpendicular to `normal`: the rectangle's height axis. The node's +Y.
    pub up: DVec3,
    /// Extent along `up x (-normal)`, the node's local X.
    pub width: f64,
    /// Extent along `up`.
    pub height: f64,
    /// Linear scene radiance per channel, >= 0.
    pub radiance: [f64; 3],
    /// The streak the light was fitted to, recorded in the node's extras.
    pub streak_id: Option<usize>,
}

/// Where a `.gltf` output finds the input's buffer and image files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum InputFiles {
    /// Copied beside the output under names made from its own: the output's folder holds
    /// everything it needs.
    #[default]
    Copy,
    /// Referred to where they are, by relative URIs (a warning says so): nothing is copied,
    /// but the output breaks if they move, and a tool rewriting the output in place may write
    /// into them. Only for a `.gltf` output.
    Reference,
}

/// How far in front of its wall a light is written by default, in metres: a light exactly in
/// its wall's plane is shadowed by the wall in renderers that trace shadow rays (Cycles let 7 %
/// of such a light reach the water), and 1 mm is far below what a fit resolves.
pub const DEFAULT_LIGHT_OFFSET: f64 = 0.001;

/// How to write the lights.
#[derive(Debug, Clone, PartialEq)]
pub struct WriteOptions {
    /// Add an emissive quad under each light for viewers without area lights.
    pub fallback_quads: bool,
    /// Intensity in the file = largest radiance component times this (683 turns W/(sr m^2)
    /// into nits). Must be finite and > 0.
    pub nits_scale: f64,
    /// Each light's node is placed this far (metres, >= 0) in front of the fitted rectangle,
    /// along the direction it emits: off its wall, so no renderer's shadow rays see the wall
    /// first. [`DEFAULT_LIGHT_OFFSET`] by default.
    pub light_offset: f64,
    /// Where a `.gltf` output finds the input's files.
    pub input_files: InputFiles,
}

impl Default for WriteOptions {
    fn default() -> Self {
        WriteOptions {
            fallback_quads: true,
            nits_scale: 1.0,
            light_offset: DEFAULT_LIGHT_OFFSET,
            input_files: InputFiles::Copy,
        }
    }
}

/// Which kind of object a rewritten URI belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ResourceKind {
    /// `buffers[index].uri`
    Buffer,
    /// `images[index].uri`
    Image,
}

/// A relative URI changed so it still reaches its file from the output's folder
/// ([`InputFiles::Reference`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UriRewrite {
    /// Buffer or image.
    pub kind: ResourceKind,
    /// Its index in `buffers` or `images`.
    pub index: usize,
    /// The URI in the input.
    pub from: String,
    /// The URI in the output.
    pub to: String,
}

/// An input file copied beside a `.gltf` output ([`InputFiles::Copy`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CopiedFile {
    /// Buffer or image (the first one that uses the file).
    pub kind: ResourceKind,
    /// Its index in `buffers` or `images`.
    pub index: usize,
    /// The input's file.
    pub from: PathBuf,
    /// The copy.
    pub to: PathBuf,
    /// The URI the output uses for it.
    pub uri: String,
}

/// Where the new binary data (the fallback quads) went.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum NewData {
    /// There was none (no lights, or fallback quads off).
    #[default]
    Nothing,
    /// Appended to the end of buffer 0 (a `.glb` output's BIN chunk, or a `.glb` input's BIN
    /// chunk that a `.gltf` output stores as `<out>.streaklight.bin`), whose earlier bytes are
    /// unchanged.
    AppendedToBuffer {
        /// The buffer's index.
        buffer: usize,
        /// Byte offset of the new data in it.
        byte_offset: usize,
    },
    /// In a new buffer.
    NewBuffer {
        /// The new buffer's index (the last one).
        buffer: usize,
        /// Its file (`<out>.streaklight.bin`), or `None` for a `.glb`'s BIN chunk.
        file: Option<PathBuf>,
    },
}

/// What was done about the document's binary data and the files it refers to.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ResourceHandling {
    /// `.glb` output: the buffers and images whose bytes came from a URI (a file or `data:`)
    /// into the BIN chunk.
    pub embedded: Vec<(ResourceKind, usize)>,
    /// `.gltf` output: the input's files copied beside it.
    pub copied: Vec<CopiedFile>,
    /// `.gltf` output with [`InputFiles::Reference`]: URIs rewritten to reach the input's
    /// files from the output's folder (empty when it is the same folder).
    pub rewritten_uris: Vec<UriRewrite>,
    /// Where the new binary data went.
    pub new_data: NewData,
    /// For a `.glb` input written as `.gltf`: the file that now holds its BIN chunk (buffer 0).
    pub bin_chunk_moved_to: Option<PathBuf>,
    /// GLB chunks of unknown type dropped because a `.gltf` output cannot hold them (readers
    /// ignore such chunks), plus a BIN chunk no buffer referred to.
    pub dropped_glb_chunks: usize,
    /// Things the user should know (files referred to where they are, images at web
    /// addresses that stay there).
    pub warnings: Vec<String>,
    /// Every file written, the output scene last.
    pub files_written: Vec<PathBuf>,
}

/// What [`write_lit_scene`] added to the document.
#[derive(Debug, Clone, PartialEq)]
pub struct WriteSummary {
    /// Index of each light (same order as the input) in `extensions.EXT_lights_area.lights`.
    pub light_indices: Vec<usize>,
    /// Index of each light's node in `nodes`.
    pub node_indices: Vec<usize>,
    /// Each light node's translation: the light's centre moved [`WriteOptions::light_offset`]
    /// along its normal.
    pub node_translations: Vec<[f64; 3]>,
    /// Index of each light's fallback quad node (empty when fallback quads are off).
    pub fallback_node_indices: Vec<usize>,
    /// The scene the light nodes were added to.
    pub scene_index: usize,
    /// Binary data and external files.
    pub resources: ResourceHandling,
}

/// Writes `lights` into the glTF scene `input`, saving the result as `output` (`.gltf` or
/// `.glb`, by its extension). Nothing is written if anything is wrong: an unreadable or
/// corrupt input, an output that would overwrite the input or one of its files, a light that
/// is not a proper rectangle. Every file is written atomically.
pub fn write_lit_scene(
    input: &Path,
    output: &Path,
    lights: &[LightToWrite],
    options: &WriteOptions,
) -> Result<WriteSummary> {
    write_lit_scene_with(input, output, lights, options, None)
}

/// [`write_lit_scene`], with the output's copies of the input's files written ahead
/// ([`CopiesAhead::start`] with the same `input`, `output` and `options.input_files`), put
/// in place instead of written again.
pub fn write_lit_scene_with(
    input: &Path,
    output: &Path,
    lights: &[LightToWrite],
    options: &WriteOptions,
    ahead: Option<CopiesAhead>,
) -> Result<WriteSummary> {
    document::Format::from_output_path(output)?;
    if !(options.nits_scale.is_finite() && options.nits_scale > 0.0) {
        return Err(Error::Usage(format!(
            "the nits scale must be a positive number, not {}",
            options.nits_scale
        )));
    }
    if !(options.light_offset.is_finite() && options.light_offset >= 0.0) {
        return Err(Error::Usage(format!(
            "the light offset must be a number of metres >= 0, not {}",
            options.light_offset
        )));
    }
    let prepared = lights
        .iter()
        .enumerate()
        .map(|(i, l)| lights::prepare(l, i, options.nits_scale, options.light_offset))
        .collect::<Result<Vec<_>>>()?;
    let finished = ahead.and_then(|a| a.finish(input, output, options.input_files));
    let (mut staged, written) = match finished {
        Some(ahead) => (ahead.staged, ahead.written),
        None => (
            staged::stage(input, output, options.input_files)?,
            Vec::new(),
        ),
    };
    let mut summary = WriteSummary {
        light_indices: Vec::new(),
        node_indices: Vec::new(),
        node_translations: prepared.iter().map(|p| p.translation).collect(),
        fallback_node_indices: Vec::new(),
        scene_index: 0,
        resources: ResourceHandling::default(),
    };
    if !prepared.is_empty() {
        if options.fallback_quads {
            let at = staged.append_data(&fallback_quad::bytes(&prepared), input)?;
            let root = root_mut(&mut staged.json, input)?;
            summary.fallback_node_indices =
                fallback_quad::append(root, &prepared, at.0, at.1, input)?;
        }
        let root = root_mut(&mut staged.json, input)?;
        append_lights(root, &prepared, &mut summary, input)?;
    }
    summary.resources = staged.write(output, written)?;
    Ok(summary)
}

/// Appends the light objects, their nodes, and the nodes to the scene; lists the extension.
fn append_lights(
    root: &mut serde_json::Map<String, Value>,
    prepared: &[lights::PreparedLight],
    summary: &mut WriteSummary,
    input: &Path,
) -> Result<()> {
    let extensions = object_mut(root, "extensions", input)?;
    let ext = object_mut(extensions, EXTENSION, input)?;
    let list = array_mut(ext, "lights", input)?;
    for light in prepared {
        list.push(lights::light_json(light));
        summary.light_indices.push(list.len() - 1);
    }
    for (k, light) in prepared.iter().enumerate() {
        let child = summary.fallback_node_indices.get(k).copied();
        let node = lights::node_json(light, summary.light_indices[k], child);
        summary.node_indices.push(push(root, "nodes", node, input)?);
    }
    summary.scene_index = target_scene(root, input)?;
    let scene = array_mut(root, "scenes", input)?
        .get_mut(summary.scene_index)
        .and_then(Value::as_object_mut)
        .ok_or_else(|| Error::scene(input, "a scene is not an object"))?;
    let nodes = array_mut(scene, "nodes", input)?;
    nodes.extend(summary.node_indices.iter().map(|&n| Value::from(n)));
    use_extension(root, EXTENSION, input)
}

/// The default scene, else scene 0, else a new scene made the default.
pub(crate) fn target_scene(
    root: &mut serde_json::Map<String, Value>,
    input: &Path,
) -> Result<usize> {
    let count = len_of(root, "scenes");
    if let Some(scene) = root.get("scene") {
        return scene
            .as_u64()
            .and_then(|s| usize::try_from(s).ok())
            .filter(|&s| s < count)
            .ok_or_else(|| {
                Error::scene(input, format!("\"scene\": {scene} is not a scene index"))
            });
    }
    if count > 0 {
        return Ok(0);
    }
    let index = push(root, "scenes", json!({ "nodes": [] }), input)?;
    root.insert("scene".into(), Value::from(index));
    Ok(index)
}
