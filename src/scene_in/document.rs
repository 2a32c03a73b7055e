//! Reading the bytes of a glTF scene: `.gltf` JSON or `.glb` container, and its buffers.
//!
//! The `gltf` crate's own loader refuses a valid scene whose `extensionsRequired` names an
//! extension it does not know, and fails on `KHR_animation_pointer` (method §7). This tool
//! reads only geometry, cameras and materials, so before handing the JSON to `gltf` for
//! validation it removes the two things that can make it refuse for reasons that do not
//! concern us: `extensionsRequired` and `animations`. The GLB container is parsed here
//! rather than by `gltf::Glb`, which subtracts lengths from untrusted headers unchecked.

use std::path::{Path, PathBuf};

use base64::Engine;
use serde_json::Value;

use crate::{Error, Result};

/// A glTF document as read from disk: its JSON (complete and unmodified, for the parts of
/// the tool that need extensions and extras), the validated `gltf` document (with the two
/// ignored parts removed), and the bytes of every buffer.
pub struct SourceDocument {
    /// The scene file.
    pub path: PathBuf,
    /// The JSON as written in the file.
    pub json: Value,
    /// The validated document used to read geometry.
    pub document: gltf::Document,
    /// Bytes of each buffer, at least `byteLength` long.
    pub buffers: Vec<Vec<u8>>,
}

const GLB_MAGIC: &[u8; 4] = b"glTF";
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;

/// The JSON chunk and optional BIN chunk of a GLB file.
pub struct GlbChunks<'a> {
    /// The JSON chunk's bytes.
    pub json: &'a [u8],
    /// The first BIN chunk's bytes, if any.
    pub bin: Option<&'a [u8]>,
}

fn read_u32(bytes: &[u8], at: usize) -> Option<u32> {
    let b = bytes.get(at..at.checked_add(4)?)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// Splits a GLB container into its chunks, checking every length against the data.
pub fn split_glb(bytes: &[u8]) -> std::result::Result<GlbChunks<'_>, String> {
    if bytes.len() < 12 || &bytes[0..4] != GLB_MAGIC {
        return Err("not a GLB file (no 'glTF' header)".into());
    }
    let version = read_u32(bytes, 4).unwrap_or(0);
    if version != 2 {
        return Err(format!("GLB version {version} is not supported (only 2)"));
    }
    let declared = read_u32(bytes, 8).unwrap_or(0) as usize;
    if declared > bytes.len() {
        return Err(format!(
            "truncated GLB: the header declares {declared} bytes but the file holds {}",
            bytes.len()
        ));
    }
    let body = &bytes[..declared];
    let mut at = 12usize;
    let mut json = None;
    let mut bin = None;
    while at < body.len() {
        let (Some(len), Some(kind)) = (read_u32(body, at), read_u32(body, at + 4)) else {
            return Err(format!("truncated GLB chunk header at byte {at}"));
        };
        let start = at + 8;
        let end = start
            .checked_add(len as usize)
            .filter(|&e| e <= body.len())
            .ok_or_else(|| {
                format!("truncated GLB: a chunk at byte {at} declares {len} bytes past the end")
            })?;
        match kind {
            CHUNK_JSON if json.is_none() => json = Some(&body[start..end]),
            CHUNK_BIN if bin.is_none() && json.is_some() => bin = Some(&body[start..end]),
            _ => {}
        }
        // Chunks are 4-byte aligned; tolerate a missing final padding.
        at = end.div_ceil(4) * 4;
    }
    let json = json.ok_or("the GLB has no JSON chunk")?;
    Ok(GlbChunks { json, bin })
}

/// Decodes a `data:` URI's payload (base64 only, as glTF requires for binary data).
pub fn decode_data_uri(uri: &str) -> Option<Vec<u8>> {
    let rest = uri.strip_prefix("data:")?;
    let (header, payload) = rest.split_once(',')?;
    if !header.ends_with(";base64") {
        return None;
    }
    base64::engine::general_purpose::STANDARD
        .decode(payload.trim())
        .ok()
}

/// Undoes percent-encoding in a relative URI so it can be used as a file path.
pub fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            let hex = |b: u8| (b as char).to_digit(16);
            if let (Some(h), Some(l)) = (hex(bytes[i + 1]), hex(bytes[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Reads the scene file at `path`.
pub fn read(path: &Path) -> Result<SourceDocument> {
    let bytes = crate::input_file::read(path)?;
    from_bytes(&bytes, path, Some(path.parent().unwrap_or(Path::new("."))))
}

/// Reads a scene from its bytes. `path` names the scene in messages; external buffers are
/// resolved relative to `base`, and with `base` = `None` (bytes that come from no folder, as
/// when fuzzing) a buffer that refers to a file is an error.
pub fn from_bytes(bytes: &[u8], path: &Path, base: Option<&Path>) -> Result<SourceDocument> {
    let (json_bytes, bin) = if bytes.starts_with(GLB_MAGIC) {
        let chunks = split_glb(bytes).map_err(|m| Error::scene(path, m))?;
        (chunks.json, chunks.bin)
    } else {
        (bytes, None)
    };
    let json: Value = serde_json::from_slice(json_bytes).map_err(|e| {
        Error::scene(
            path,
            format!("not a glTF file: its JSON does not parse ({e})"),
        )
    })?;
    if !json.is_object() || json.get("asset").is_none() {
        return Err(Error::scene(
            path,
            "not a glTF file: the JSON has no \"asset\" object",
        ));
    }
    let mut for_reading = json.clone();
    if let Some(root) = for_reading.as_object_mut() {
        root.remove("extensionsRequired");
        root.remove("animations");
    }
    check_position_accessors(&for_reading).map_err(|m| Error::scene(path, m))?;
    let root: gltf::json::Root = serde_json::from_value(for_reading)
        .map_err(|e| Error::scene(path, format!("not a valid glTF 2.0 document: {e}")))?;
    let document = gltf::Document::from_json(root).map_err(|e| {
        Error::scene(
            path,
            format!(
                "the glTF document is not valid: {}",
                describe_validation(&e)
            ),
        )
    })?;
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let index = buffer.index();
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => bin.map(<[u8]>::to_vec).ok_or_else(|| {
                Error::scene(
                    path,
                    format!("buffer {index} refers to the GLB binary chunk, but there is none"),
                )
            })?,
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => decode_data_uri(uri)
                .ok_or_else(|| {
                    Error::scene(
                        path,
                        format!("buffer {index}: its data: URI is not valid base64"),
                    )
                })?,
            gltf::buffer::Source::Uri(uri) => {
                let base = base.ok_or_else(|| {
                    Error::scene(
                        path,
                        format!("buffer {index} refers to the file \"{uri}\", but the scene was not read from a folder"),
                    )
                })?;
                read_buffer_file(&base.join(percent_decode(uri)))
                    .map_err(|m| Error::scene(path, format!("buffer {index} {m}")))?
            }
        };
        if data.len() < buffer.length() {
            return Err(Error::scene(
                path,
                format!(
                    "buffer {index} is too short: it declares {} bytes but holds {}",
                    buffer.length(),
                    data.len()
                ),
            ));
        }
        buffers.push(data);
    }
    Ok(SourceDocument {
        path: path.to_path_buf(),
        json,
        document,
        buffers,
    })
}

/// Checks that every primitive's POSITION names an existing accessor: `gltf-json` 1.4.1's
/// validation indexes the accessors with it unchecked and panics (found by fuzzing).
fn check_position_accessors(json: &Value) -> std::result::Result<(), String> {
    let accessors = json
        .get("accessors")
        .and_then(Value::as_array)
        .map_or(0, Vec::len);
    let meshes = json.get("meshes").and_then(Value::as_array);
    for (m, mesh) in meshes.into_iter().flatten().enumerate() {
        let primitives = mesh.get("primitives").and_then(Value::as_array);
        for (p, primitive) in primitives.into_iter().flatten().enumerate() {
            let Some(index) = primitive.pointer("/attributes/POSITION") else {
                continue;
            };
            if index.as_u64().is_none_or(|i| i >= accessors as u64) {
                return Err(format!(
                    "not a valid glTF 2.0 document: mesh {m} primitive {p}: POSITION refers to accessor {index}, but there are {accessors} accessors"
                ));
            }
        }
    }
    Ok(())
}

/// Reads an external buffer, bounded ([`crate::input_file::read`]: a URI naming a device such
/// as `/dev/zero` would otherwise be read without end).
fn read_buffer_file(file: &Path) -> std::result::Result<Vec<u8>, String> {
    crate::input_file::read(file).map_err(|e| format!("({e})"))
}

fn describe_validation(e: &gltf::Error) -> String {
    match e {
        gltf::Error::Validation(list) => list
            .iter()
            .take(5)
            .map(|(p, err)| format!("{}: {err}", p.as_str()))
            .collect::<Vec<_>>()
            .join("; "),
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glb_lengths_are_checked() {
        assert!(split_glb(b"glTF").is_err());
        let mut glb = Vec::new();
        glb.extend_from_slice(b"glTF");
        glb.extend_from_slice(&2u32.to_le_bytes());
        glb.extend_from_slice(&28u32.to_le_bytes());
        glb.extend_from_slice(&8u32.to_le_bytes());
        glb.extend_from_slice(&CHUNK_JSON.to_le_bytes());
        glb.extend_from_slice(b"{}      ");
        let chunks = split_glb(&glb).unwrap();
        assert_eq!(chunks.json, b"{}      ");
        assert!(chunks.bin.is_none());
        // A chunk that claims more than the file holds.
        let mut bad = glb.clone();
        bad[12..16].copy_from_slice(&1000u32.to_le_bytes());
        assert!(split_glb(&bad).is_err());
        // A header that claims more than the file holds.
        let mut bad = glb;
        bad[8..12].copy_from_slice(&1000u32.to_le_bytes());
        assert!(split_glb(&bad).is_err());
    }

    #[test]
    fn data_uris_and_percent_encoding() {
        assert_eq!(
            decode_data_uri("data:application/octet-stream;base64,AAEC"),
            Some(vec![0, 1, 2])
        );
        assert_eq!(decode_data_uri("data:text/plain,abc"), None);
        assert_eq!(percent_decode("my%20water.bin"), "my water.bin");
        assert_eq!(percent_decode("100%"), "100%");
    }
}
