//! A `.glb` output holds everything it needs in its BIN chunk: every buffer of the input (its
//! BIN chunk, `data:` URIs, external files) becomes part of one buffer 0, and every image with
//! a URI becomes a buffer view of it. Copied alone to another folder, the `.glb` still loads,
//! and the glTF-Validator has no `DATA_URI_GLB` warning to give.
//!
//! Buffer 0 keeps its bytes at offset 0, so a `.glb` input's BIN chunk is a prefix of the
//! output's and its buffer views are untouched. Buffer `k > 0` is appended at a 4-byte
//! aligned offset (every accessor's alignment is relative to its buffer's start, and no
//! glTF component is wider than 4 bytes); its buffer views move by that offset, and so do
//! the compressed views of `EXT_meshopt_compression`. An `EXT_meshopt_compression` fallback
//! buffer (no URI, no bytes: readers decompress instead) stays a buffer of its own, after
//! buffer 0, and its views follow it. Every other index stays valid: only `buffers` shrinks.
use std::path::Path;

use base64::Engine;
use serde_json::{json, Map, Value};

use super::document::{padded_len, Document};
use super::resources::relative_file_path;
use super::ResourceKind;
use crate::{Error, Result};

/// The extension whose buffer views name a buffer of their own (compressed data).
const MESHOPT: &str = "EXT_meshopt_compression";

/// What embedding did.
pub(crate) struct Embedded {
    /// The BIN chunk (buffer 0), when the document has any buffer.
    pub bin: Option<Vec<u8>>,
    /// Buffers and images whose bytes came from a URI (file or `data:`) into the BIN chunk.
    pub embedded: Vec<(ResourceKind, usize)>,
    /// The input's BIN chunk was not buffer 0's storage and was dropped.
    pub unused_bin_chunk: bool,
    /// Images that stay where their URI points (a web address cannot be embedded).
    pub warnings: Vec<String>,
}

/// Moves every buffer and image of `json` (read from `doc`, at `input` in `input_dir`) into
/// one BIN-chunk buffer 0, as the module docs describe.
pub(crate) fn embed_all(
    json: &mut Value,
    doc: &Document,
    input: &Path,
    input_dir: &Path,
) -> Result<Embedded> {
    let bin_buffer0 = super::staged::bin_chunk_buffer(doc, input)?;
    let mut out = Embedded {
        bin: None,
        embedded: Vec::new(),
        unused_bin_chunk: doc.bin_chunk.is_some() && bin_buffer0.is_none(),
        warnings: Vec::new(),
    };
    let buffers: Vec<Value> = json
        .get("buffers")
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    let mut bin = Vec::new();
    // Where each input buffer goes: the output buffer and the offset of its bytes in it.
    let mut places = Vec::with_capacity(buffers.len());
    let mut merged_json = None;
    let mut fallbacks = Vec::new();
    for (i, buffer) in buffers.iter().enumerate() {
        if is_meshopt_fallback(buffer) && !(i == 0 && bin_buffer0.is_some()) {
            fallbacks.push(buffer.clone());
            places.push(Place::Fallback(fallbacks.len() - 1));
            continue;
        }
        let len = byte_length(buffer, i, input)?;
        let bytes = match (&bin_buffer0, i) {
            (Some(chunk), 0) => chunk.clone(),
            _ => {
                let uri = buffer.get("uri").and_then(Value::as_str).ok_or_else(|| {
                    Error::scene(
                        input,
                        format!("buffer {i} has no \"uri\" and is not the GLB's BIN chunk"),
                    )
                })?;
                out.embedded.push((ResourceKind::Buffer, i));
                uri_bytes(uri, input, input_dir, &format!("buffer {i}"))?.ok_or_else(|| {
                    Error::scene(
                        input,
                        format!(
                            "buffer {i} is at {uri}, which cannot be embedded into a .glb; \
                             write a .gltf output instead"
                        ),
                    )
                })?
            }
        };
        let bytes = bytes.get(..len).ok_or_else(|| {
            Error::scene(
                input,
                format!(
                    "buffer {i} is too short: it declares {len} bytes but holds {}",
                    bytes.len()
                ),
            )
        })?;
        let base = padded_len(bin.len());
        bin.resize(base, 0);
        bin.extend_from_slice(bytes);
        places.push(Place::Merged(base));
        merged_json.get_or_insert_with(|| buffer.clone());
    }
    let root = json
        .as_object_mut()
        .ok_or_else(|| Error::scene(input, "not a glTF file: the JSON is not an object"))?;
    if merged_json.is_none() && !fallbacks.is_empty() {
        return Err(Error::scene(
            input,
            "its only buffers are EXT_meshopt_compression fallbacks: there is no compressed \
             data to read",
        ));
    }
    // The fallbacks follow buffer 0.
    move_buffer_views(root, &places, 1, input)?;
    embed_images(root, &mut bin, &mut out, input, input_dir)?;
    // Images embedded into a document without buffers made an empty buffer 0.
    let merged_json = merged_json.or_else(|| {
        root.get("buffers")
            .and_then(|b| b.get(0))
            .filter(|_| buffers.is_empty())
            .cloned()
    });
    let Some(mut merged) = merged_json else {
        return Ok(out);
    };
    if let Some(b0) = merged.as_object_mut() {
        // shift_remove keeps the order of the other keys.
        b0.shift_remove("uri");
        // Untouched unless it changed: the input may spell the same number differently.
        if b0.get("byteLength").and_then(Value::as_u64) != Some(bin.len() as u64) {
            b0.insert("byteLength".into(), Value::from(bin.len()));
        }
    }
    let mut list = vec![merged];
    list.extend(fallbacks);
    root.insert("buffers".into(), Value::Array(list));
    out.bin = Some(bin);
    Ok(out)
}

/// Where an input buffer's bytes go in a `.glb` output.
#[derive(Clone, Copy)]
enum Place {
    /// Into buffer 0, at this offset.
    Merged(usize),
    /// A meshopt fallback buffer: the `k`th after the merged buffer 0.
    Fallback(usize),
}

/// An `EXT_meshopt_compression` fallback buffer: no URI, and no bytes that any reader loads.
pub(crate) fn is_meshopt_fallback(buffer: &Value) -> bool {
    buffer.get("uri").is_none()
        && buffer
            .pointer("/extensions/EXT_meshopt_compression/fallback")
            .and_then(Value::as_bool)
            == Some(true)
}

/// `byteLength` of buffer `i`.
fn byte_length(buffer: &Value, i: usize, input: &Path) -> Result<usize> {
    buffer
        .get("byteLength")
        .and_then(Value::as_u64)
        .and_then(|l| usize::try_from(l).ok())
        .ok_or_else(|| Error::scene(input, format!("buffer {i} has no valid \"byteLength\"")))
}

/// The bytes a buffer or image URI holds: decoded from a `data:` URI, or read from the file it
/// names (relative to `input_dir`); `None` for a URI with another scheme (a web address).
pub(crate) fn uri_bytes(
    uri: &str,
    input: &Path,
    input_dir: &Path,
    what: &str,
) -> Result<Option<Vec<u8>>> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (header, payload) = rest.split_once(',').unwrap_or(("", ""));
        if !header.ends_with(";base64") {
            return Err(Error::scene(
                input,
                format!("{what}'s data: URI is not base64-encoded"),
            ));
        }
        let bytes = base64::engine::general_purpose::STANDARD
            .decode(payload)
            .map_err(|e| {
                Error::scene(
                    input,
                    format!("{what}'s data: URI is not valid base64: {e}"),
                )
            })?;
        return Ok(Some(bytes));
    }
    let Some(relative) = relative_file_path(uri) else {
        return Ok(None);
    };
    let path = input_dir.join(relative);
    crate::input_file::read(&path)
        .map(Some)
        .map_err(|e| Error::scene(input, format!("{what}'s file {e}")))
}

/// Points every buffer view at the output buffer holding its input buffer's bytes
/// (`places`), fallback buffers numbered from `fallback_base`.
fn move_buffer_views(
    root: &mut Map<String, Value>,
    places: &[Place],
    fallback_base: usize,
    input: &Path,
) -> Result<()> {
    let Some(views) = root.get_mut("bufferViews").and_then(Value::as_array_mut) else {
        return Ok(());
    };
    for (v, view) in views.iter_mut().enumerate() {
        let Some(view) = view.as_object_mut() else {
            continue;
        };
        move_view(view, places, fallback_base, input, v)?;
        if let Some(meshopt) = view
            .get_mut("extensions")
            .and_then(|e| e.get_mut(MESHOPT))
            .and_then(Value::as_object_mut)
        {
            move_view(meshopt, places, fallback_base, input, v)?;
        }
    }
    Ok(())
}

/// Moves one `{buffer, byteOffset}` object.
fn move_view(
    view: &mut Map<String, Value>,
    places: &[Place],
    fallback_base: usize,
    input: &Path,
    v: usize,
) -> Result<()> {
    let Some(buffer) = view.get("buffer").and_then(Value::as_u64) else {
        return Ok(());
    };
    let place = usize::try_from(buffer)
        .ok()
        .and_then(|b| places.get(b))
        .copied()
        .ok_or_else(|| {
            Error::scene(
                input,
                format!("buffer view {v} names buffer {buffer}, which does not exist"),
            )
        })?;
    let (to, base) = match place {
        Place::Merged(base) => (0, base),
        Place::Fallback(k) => (fallback_base + k, 0),
    };
    if to as u64 != buffer {
        view.insert("buffer".into(), Value::from(to));
    }
    if base > 0 {
        let offset = view.get("byteOffset").and_then(Value::as_u64).unwrap_or(0);
        view.insert("byteOffset".into(), Value::from(offset + base as u64));
    }
    Ok(())
}

/// Replaces each image's URI by a buffer view of the BIN chunk holding its bytes.
fn embed_images(
    root: &mut Map<String, Value>,
    bin: &mut Vec<u8>,
    out: &mut Embedded,
    input: &Path,
    input_dir: &Path,
) -> Result<()> {
    let images: Vec<(usize, String, Option<String>)> = root
        .get("images")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .enumerate()
        .filter_map(|(i, img)| {
            let uri = img.get("uri")?.as_str()?.to_string();
            let mime = img
                .get("mimeType")
                .and_then(Value::as_str)
                .map(String::from);
            Some((i, uri, mime))
        })
        .collect();
    for (i, uri, mime) in images {
        let what = format!("image {i}");
        let Some(bytes) = uri_bytes(&uri, input, input_dir, &what)? else {
            out.warnings.push(format!(
                "{}: image {i} stays at {uri}: a web address cannot be embedded into a .glb",
                input.display()
            ));
            continue;
        };
        let mime = match mime.or_else(|| sniff_mime(&bytes).map(String::from)) {
            Some(m) => m,
            None => {
                return Err(Error::scene(
                    input,
                    format!(
                        "{what} ({uri}) is not a PNG, JPEG, WebP or KTX2 image and has no \
                         \"mimeType\"; a .glb needs one"
                    ),
                ))
            }
        };
        let base = padded_len(bin.len());
        bin.resize(base, 0);
        bin.extend_from_slice(&bytes);
        if root
            .get("buffers")
            .and_then(Value::as_array)
            .is_none_or(Vec::is_empty)
        {
            root.insert("buffers".into(), json!([{ "byteLength": 0 }]));
        }
        let view = super::edit::push(
            root,
            "bufferViews",
            json!({ "buffer": 0, "byteOffset": base, "byteLength": bytes.len() }),
            input,
        )?;
        if let Some(img) = root
            .get_mut("images")
            .and_then(|a| a.get_mut(i))
            .and_then(Value::as_object_mut)
        {
            img.shift_remove("uri");
            img.insert("bufferView".into(), Value::from(view));
            img.insert("mimeType".into(), Value::from(mime));
        }
        out.embedded.push((ResourceKind::Image, i));
    }
    Ok(())
}

/// The media type of an image from its first bytes.
fn sniff_mime(bytes: &[u8]) -> Option<&'static str> {
    if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        Some("image/png")
    } else if bytes.starts_with(&[0xFF, 0xD8, 0xFF]) {
        Some("image/jpeg")
    } else if bytes.len() >= 12 && &bytes[..4] == b"RIFF" && &bytes[8..12] == b"WEBP" {
        Some("image/webp")
    } else if bytes.starts_with(b"\xABKTX 20\xBB") {
        Some("image/ktx2")
    } else {
        None
    }
}
