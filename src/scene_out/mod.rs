//! Step 10 of the pipeline (method §5, §7): write the fitted lights into the user's glTF,
//! losslessly.
//!
//! The document is edited as JSON: every existing key, value and index stays as it was, and
//! new objects are appended (`extensionsUsed`, the top-level `EXT_lights_area.lights`, nodes
//! added to the scene, and for the fallback quads buffer views, accessors, materials and
//! meshes). Existing binary data is never rewritten; new data is appended after it.
//!
//! Where the new binary data goes:
//!
//! | input | output | new data |
//! |---|---|---|
//! | `.glb` with a BIN chunk | `.glb` | appended to the BIN chunk (buffer 0 grows) |
//! | `.glb` with a BIN chunk | `.gltf` | the BIN chunk + new data become `<out>.streaklight.bin`, buffer 0's `uri` |
//! | buffer 0 is a `data:` URI | `.glb` | buffer 0's bytes move into the BIN chunk (its `uri` is dropped), new data appended |
//! | no buffers | `.glb` | a new BIN chunk, new buffer 0 |
//! | buffer 0 is an external file | `.glb` | a new buffer, external file `<out>.streaklight.bin` |
//! | no BIN-chunk buffer | `.gltf` | a new buffer, external file `<out>.streaklight.bin` |
//!
//! A `data:` URI is never used for new data: the glTF-Validator warns about `data:` URIs in a
//! GLB (`DATA_URI_GLB`), and in a `.gltf` a base64 copy is a third larger than the file. Only
//! buffer 0 can live in the BIN chunk (GLB spec), so the input's other `data:` buffers and
//! images stay as they are, and a `.glb` written from such a `.gltf` keeps those warnings.
//!
//! When the output goes to another folder than the input, relative buffer and image URIs are
//! rewritten to reach the original files (see the `resources` module); nothing is copied.

mod document;
mod edit;
mod fallback_quad;
mod lights;
mod resources;

use std::path::{Path, PathBuf};

use base64::Engine;
use glam::DVec3;
use serde_json::{json, Value};

use crate::output_file::{ensure_not_an_input, write_atomically};
use crate::{Error, Result};
use document::{padded_len, Document, Format};
use edit::{array_mut, len_of, object_mut, push, root_mut, use_extension};

pub use lights::EXTENSION;

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

/// How to write the lights.
#[derive(Debug, Clone, PartialEq)]
pub struct WriteOptions {
    /// Add an emissive quad under each light for viewers without area lights.
    pub fallback_quads: bool,
    /// Intensity in the file = largest radiance component times this (683 turns W/(sr m^2)
    /// into nits). Must be finite and > 0.
    pub nits_scale: f64,
}

impl Default for WriteOptions {
    fn default() -> Self {
        WriteOptions {
            fallback_quads: true,
            nits_scale: 1.0,
        }
    }
}

/// Which kind of object a rewritten URI belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ResourceKind {
    /// `buffers[index].uri`
    Buffer,
    /// `images[index].uri`
    Image,
}

/// A relative URI changed so it still reaches its file from the output's folder.
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

/// How a buffer that this writer created is stored.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum BufferStorage {
    /// The BIN chunk of the output `.glb`.
    GlbBinChunk,
    /// An external file written next to the output.
    ExternalFile(PathBuf),
}

/// Where the new binary data (the fallback quads) went.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum NewData {
    /// There was none (no lights, or fallback quads off).
    Nothing,
    /// Appended to the end of buffer 0 (the input GLB's BIN-chunk buffer, or a `data:` buffer 0
    /// moved into the output GLB's BIN chunk), whose earlier bytes are unchanged.
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
        /// How it is stored.
        storage: BufferStorage,
    },
}

/// What was done about the document's binary data and the files it refers to.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ResourceHandling {
    /// Relative buffer/image URIs rewritten because the output is in another folder than the
    /// input (empty when it is in the same folder). Files are never copied.
    pub rewritten_uris: Vec<UriRewrite>,
    /// Where the new binary data went.
    pub new_data: NewData,
    /// For a `.glb` input written as `.gltf`: the file that now holds its BIN chunk (buffer 0).
    pub bin_chunk_moved_to: Option<PathBuf>,
    /// For a `.glb` output whose input's buffer 0 was a `data:` URI: its bytes (unchanged)
    /// now are the BIN chunk, and its `uri` was removed.
    pub data_uri_buffer0_moved_to_bin_chunk: bool,
    /// GLB chunks of unknown type dropped because a `.gltf` output cannot hold them (readers
    /// ignore such chunks), plus a BIN chunk no buffer referred to.
    pub dropped_glb_chunks: usize,
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
    let out_format = Format::from_output_path(output)?;
    if !(options.nits_scale.is_finite() && options.nits_scale > 0.0) {
        return Err(Error::Usage(format!(
            "the nits scale must be a positive number, not {}",
            options.nits_scale
        )));
    }
    let prepared = lights
        .iter()
        .enumerate()
        .map(|(i, l)| lights::prepare(l, i, options.nits_scale))
        .collect::<Result<Vec<_>>>()?;
    let doc = document::read(input)?;
    let input_dir = folder_of(input)
        .canonicalize()
        .map_err(|e| Error::io(input, e))?;
    let output_dir = folder_of(output).canonicalize().map_err(|_| {
        Error::output(
            output,
            format!("the folder {} does not exist", folder_of(output).display()),
        )
    })?;
    let bin_path = output.with_extension("streaklight.bin");
    let bin_name = bin_path
        .file_name()
        .and_then(|n| n.to_str())
        .map(resources::encode_path)
        .ok_or_else(|| Error::output(output, "the output file name is not valid UTF-8"))?;

    let mut json = doc.json.clone();
    let bin_buffer0 = bin_chunk_buffer(&doc, input)?;
    let unused_bin_chunk = doc.bin_chunk.is_some() && bin_buffer0.is_none();
    let mut data_uri_moved = false;
    let buffer0 = match bin_buffer0 {
        None if out_format == Format::Glb => {
            let moved = take_data_uri_buffer0(&mut json, input)?;
            data_uri_moved = moved.is_some();
            moved
        }
        other => other,
    };
    let local = resources::local_resources(&json, &input_dir);
    let rewritten_uris = if input_dir == output_dir {
        Vec::new()
    } else {
        resources::rewrite_uris(&mut json, &local, &output_dir, output)?
    };

    let root = root_mut(&mut json, input)?;
    let quad_bytes = if options.fallback_quads && !prepared.is_empty() {
        fallback_quad::bytes(&prepared)
    } else {
        Vec::new()
    };
    let placed = place_new_data(
        root, buffer0, quad_bytes, out_format, &bin_name, &bin_path, input,
    )?;

    // Check every output against every input before writing anything.
    let mut inputs: Vec<&Path> = vec![input];
    inputs.extend(local.iter().map(|r| r.path.as_path()));
    if placed.external.is_some() {
        ensure_not_an_input(&bin_path, &inputs)?;
    }
    ensure_not_an_input(output, &inputs)?;

    let mut summary = WriteSummary {
        light_indices: Vec::new(),
        node_indices: Vec::new(),
        fallback_node_indices: Vec::new(),
        scene_index: 0,
        resources: ResourceHandling {
            rewritten_uris,
            new_data: placed.new_data.clone(),
            bin_chunk_moved_to: placed.bin_chunk_moved_to.clone(),
            data_uri_buffer0_moved_to_bin_chunk: data_uri_moved,
            dropped_glb_chunks: usize::from(unused_bin_chunk),
            files_written: Vec::new(),
        },
    };
    if !prepared.is_empty() {
        if let Some((buffer, offset)) = placed.quads_at {
            summary.fallback_node_indices =
                fallback_quad::append(root, &prepared, buffer, offset, input)?;
        }
        append_lights(root, &prepared, &mut summary, input)?;
    }

    let mut other_chunks = doc.other_chunks.clone();
    let out_bytes = match out_format {
        Format::Glb => document::glb_bytes(&json, placed.glb_bin.as_deref(), &other_chunks)?,
        Format::Gltf => {
            summary.resources.dropped_glb_chunks += other_chunks.len();
            other_chunks.clear();
            document::gltf_bytes(&json)?
        }
    };
    summary.resources.files_written = write_files(output, &out_bytes, &bin_path, placed.external)?;
    Ok(summary)
}

/// The folder a path is in ("." for a bare file name).
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// The bytes of buffer 0 when it is stored in the input GLB's BIN chunk (its `byteLength`
/// first bytes; the rest of the chunk is padding). Checks the buffers' storage while at it.
fn bin_chunk_buffer(doc: &Document, input: &Path) -> Result<Option<Vec<u8>>> {
    let buffers = doc.json.get("buffers").and_then(Value::as_array);
    let Some(first) = buffers.and_then(|b| b.first()) else {
        return Ok(None);
    };
    if doc.format == Format::Gltf {
        if let Some(i) = buffers
            .into_iter()
            .flatten()
            .position(|b| b.get("uri").is_none())
        {
            return Err(Error::scene(
                input,
                format!("buffer {i} has no \"uri\"; in a .gltf file every buffer needs one"),
            ));
        }
        return Ok(None);
    }
    if first.get("uri").is_some() {
        return Ok(None);
    }
    let chunk = doc.bin_chunk.as_deref().ok_or_else(|| {
        Error::scene(
            input,
            "corrupt GLB file: buffer 0 has no \"uri\" but the file has no BIN chunk",
        )
    })?;
    let len = first
        .get("byteLength")
        .and_then(Value::as_u64)
        .and_then(|l| usize::try_from(l).ok())
        .ok_or_else(|| Error::scene(input, "buffer 0 has no valid \"byteLength\""))?;
    let bytes = chunk.get(..len).ok_or_else(|| {
        Error::scene(
            input,
            format!(
                "corrupt GLB file: buffer 0 is {len} bytes but the BIN chunk holds {}",
                chunk.len()
            ),
        )
    })?;
    Ok(Some(bytes.to_vec()))
}

/// For a `.glb` output: when buffer 0 is a base64 `data:` URI, removes the URI and returns
/// the buffer's bytes, which become the BIN chunk. Same index, same bytes, and no
/// `DATA_URI_GLB` warning for it.
fn take_data_uri_buffer0(json: &mut Value, input: &Path) -> Result<Option<Vec<u8>>> {
    let Some(buffer) = json
        .pointer_mut("/buffers/0")
        .and_then(Value::as_object_mut)
    else {
        return Ok(None);
    };
    let Some(uri) = buffer.get("uri").and_then(Value::as_str) else {
        return Ok(None);
    };
    let Some(payload) = uri
        .strip_prefix("data:")
        .and_then(|rest| rest.split_once(','))
        .filter(|(header, _)| header.ends_with(";base64"))
        .map(|(_, data)| data)
    else {
        return Ok(None);
    };
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(payload)
        .map_err(|e| {
            Error::scene(
                input,
                format!("buffer 0's data: URI is not valid base64: {e}"),
            )
        })?;
    let len = buffer
        .get("byteLength")
        .and_then(Value::as_u64)
        .and_then(|l| usize::try_from(l).ok())
        .filter(|&l| l <= bytes.len())
        .ok_or_else(|| {
            Error::scene(
                input,
                format!(
                    "buffer 0's \"byteLength\" is missing or over its {} bytes of data",
                    bytes.len()
                ),
            )
        })?;
    // shift_remove keeps the order of the other keys (remove would swap the last one in).
    buffer.shift_remove("uri");
    Ok(Some(bytes[..len].to_vec()))
}

/// The outcome of [`place_new_data`].
struct Placement {
    /// Buffer index and byte offset of the quad data, if there is any.
    quads_at: Option<(usize, usize)>,
    new_data: NewData,
    /// The BIN chunk of a `.glb` output.
    glb_bin: Option<Vec<u8>>,
    /// The bytes of `<out>.streaklight.bin`, for a `.gltf` output that needs it.
    external: Option<Vec<u8>>,
    bin_chunk_moved_to: Option<PathBuf>,
}

/// Decides where the new binary data goes (see the table in the module docs) and edits the
/// `buffers` array accordingly. Existing buffers keep their index and their bytes.
fn place_new_data(
    root: &mut serde_json::Map<String, Value>,
    buffer0: Option<Vec<u8>>,
    new: Vec<u8>,
    format: Format,
    bin_name: &str,
    bin_path: &Path,
    input: &Path,
) -> Result<Placement> {
    if let Some(mut bytes) = buffer0 {
        let mut quads_at = None;
        let mut new_data = NewData::Nothing;
        if !new.is_empty() {
            // Our accessors need 4-byte alignment; the padding is new bytes, after the old.
            let offset = padded_len(bytes.len());
            bytes.resize(offset, 0);
            bytes.extend_from_slice(&new);
            quads_at = Some((0, offset));
            new_data = NewData::AppendedToBuffer {
                buffer: 0,
                byte_offset: offset,
            };
        }
        let grown = quads_at.is_some();
        let buffers = array_mut(root, "buffers", input)?;
        if let Some(b) = buffers.first_mut().and_then(Value::as_object_mut) {
            // Untouched unless it grew: the input may spell the same number differently.
            if grown {
                b.insert("byteLength".into(), Value::from(bytes.len()));
            }
            if format == Format::Gltf {
                b.insert("uri".into(), Value::from(bin_name));
            }
        }
        return Ok(match format {
            Format::Glb => Placement {
                quads_at,
                new_data,
                glb_bin: Some(bytes),
                external: None,
                bin_chunk_moved_to: None,
            },
            Format::Gltf => Placement {
                quads_at,
                new_data,
                glb_bin: None,
                external: Some(bytes),
                bin_chunk_moved_to: Some(bin_path.to_path_buf()),
            },
        });
    }
    let mut placement = Placement {
        quads_at: None,
        new_data: NewData::Nothing,
        glb_bin: None,
        external: None,
        bin_chunk_moved_to: None,
    };
    if new.is_empty() {
        return Ok(placement);
    }
    let index = len_of(root, "buffers");
    let (buffer, storage) = match format {
        // A buffer without a URI must be buffers[0] (GLB spec), so only an empty list may
        // get a BIN chunk; otherwise indices would have to move. An external buffer 0 stays
        // external, and so does our data.
        Format::Glb if index == 0 => (
            json!({ "byteLength": new.len(), "name": "streaklight" }),
            BufferStorage::GlbBinChunk,
        ),
        Format::Glb | Format::Gltf => (
            json!({ "byteLength": new.len(), "uri": bin_name, "name": "streaklight" }),
            BufferStorage::ExternalFile(bin_path.to_path_buf()),
        ),
    };
    push(root, "buffers", buffer, input)?;
    placement.quads_at = Some((index, 0));
    match storage {
        BufferStorage::GlbBinChunk => placement.glb_bin = Some(new),
        BufferStorage::ExternalFile(_) => placement.external = Some(new),
    }
    placement.new_data = NewData::NewBuffer {
        buffer: index,
        storage,
    };
    Ok(placement)
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
fn target_scene(root: &mut serde_json::Map<String, Value>, input: &Path) -> Result<usize> {
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

/// Writes the external `.bin` (if any), then the scene. If the scene cannot be written, the
/// `.bin` is removed again (or its previous content put back), so no stray file is left.
fn write_files(
    output: &Path,
    out_bytes: &[u8],
    bin_path: &Path,
    external: Option<Vec<u8>>,
) -> Result<Vec<PathBuf>> {
    let Some(bin) = external else {
        write_atomically(output, out_bytes)?;
        return Ok(vec![output.to_path_buf()]);
    };
    let previous = std::fs::read(bin_path).ok();
    write_atomically(bin_path, &bin)?;
    if let Err(e) = write_atomically(output, out_bytes) {
        let _ = match previous {
            Some(old) => write_atomically(bin_path, &old),
            None => std::fs::remove_file(bin_path).map_err(|e| Error::io(bin_path, e)),
        };
        return Err(e);
    }
    Ok(vec![bin_path.to_path_buf(), output.to_path_buf()])
}
