//! Reading a glTF file (`.gltf` JSON or `.glb` binary) into its JSON tree and its GLB chunks,
//! and writing them back out. Nothing here knows about lights: this is the container format.
//!
//! The JSON is kept as a `serde_json::Value` (with `preserve_order`, so keys keep their order,
//! and `float_roundtrip`, so every number parses to the exact f64 its text denotes and is
//! written back as the same value).

use std::path::Path;

use serde_json::Value;

use crate::{Error, Result};

/// `glTF` in little-endian: the first four bytes of every GLB file.
const GLB_MAGIC: u32 = 0x4654_6C67;
/// The GLB container version this writer reads and writes.
const GLB_VERSION: u32 = 2;
/// Chunk type of the JSON chunk (`JSON`).
const CHUNK_JSON: u32 = 0x4E4F_534A;
/// Chunk type of the binary chunk (`BIN\0`).
const CHUNK_BIN: u32 = 0x004E_4942;
/// Size of the GLB header and of a chunk header.
const GLB_HEADER_LEN: usize = 12;
const CHUNK_HEADER_LEN: usize = 8;

/// The two container formats of glTF 2.0.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// JSON text (`.gltf`), buffers and images in external files or `data:` URIs.
    Gltf,
    /// Binary container (`.glb`): a JSON chunk, an optional BIN chunk, maybe other chunks.
    Glb,
}

impl Format {
    /// The format an output path asks for, from its extension (case-insensitive).
    pub fn from_output_path(path: &Path) -> Result<Format> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        match ext.as_deref() {
            Some("gltf") => Ok(Format::Gltf),
            Some("glb") => Ok(Format::Glb),
            _ => Err(Error::output(
                path,
                "the output scene must end in .gltf (JSON) or .glb (binary glTF)",
            )),
        }
    }
}

/// A glTF document as read from disk.
#[derive(Debug, Clone)]
pub struct Document {
    /// The format the file was in (from its content, not its name).
    pub format: Format,
    /// The JSON tree; its root is an object holding an `asset` with a 2.x `version`.
    pub json: Value,
    /// The data of the GLB BIN chunk, padding included, if the file had one.
    pub bin_chunk: Option<Vec<u8>>,
    /// Chunks of the GLB other than JSON and BIN, in file order: readers must ignore them, we
    /// keep them so a `.glb` output loses nothing.
    pub other_chunks: Vec<(u32, Vec<u8>)>,
}

/// Reads and checks the glTF file at `path`. Every error names the file.
pub fn read(path: &Path) -> Result<Document> {
    let bytes = crate::input_file::read(path)?;
    let says_glb = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    let doc = if bytes.len() >= 4 && read_u32(&bytes, 0) == Some(GLB_MAGIC) {
        parse_glb(path, &bytes)?
    } else if says_glb {
        return Err(Error::scene(
            path,
            "not a GLB file: it does not start with the magic bytes \"glTF\"",
        ));
    } else {
        Document {
            format: Format::Gltf,
            json: parse_json(path, &bytes)?,
            bin_chunk: None,
            other_chunks: Vec::new(),
        }
    };
    check_is_gltf2(path, &doc.json)?;
    Ok(doc)
}

fn read_u32(bytes: &[u8], at: usize) -> Option<u32> {
    let b = bytes.get(at..at.checked_add(4)?)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

fn parse_glb(path: &Path, bytes: &[u8]) -> Result<Document> {
    let corrupt = |msg: String| Error::scene(path, format!("corrupt GLB file: {msg}"));
    if bytes.len() < GLB_HEADER_LEN {
        return Err(corrupt(format!(
            "{} bytes, shorter than the 12-byte header",
            bytes.len()
        )));
    }
    let version = read_u32(bytes, 4).unwrap_or(0);
    if version != GLB_VERSION {
        return Err(Error::scene(
            path,
            format!("GLB container version {version}; only version 2 (glTF 2.0) is supported"),
        ));
    }
    let declared = read_u32(bytes, 8).unwrap_or(0) as usize;
    if declared != bytes.len() {
        return Err(corrupt(format!(
            "the header says {declared} bytes but the file has {} (truncated or padded?)",
            bytes.len()
        )));
    }
    let mut at = GLB_HEADER_LEN;
    let mut json = None;
    let mut bin_chunk = None;
    let mut other_chunks = Vec::new();
    let mut index = 0usize;
    while at < bytes.len() {
        let (Some(len), Some(kind)) = (read_u32(bytes, at), read_u32(bytes, at + 4)) else {
            return Err(corrupt(format!("chunk {index} has a truncated header")));
        };
        let start = at + CHUNK_HEADER_LEN;
        let end = start
            .checked_add(len as usize)
            .filter(|&e| e <= bytes.len())
            .ok_or_else(|| {
                corrupt(format!(
                    "chunk {index} claims {len} bytes, past the end of the file"
                ))
            })?;
        let data = &bytes[start..end];
        match (index, kind) {
            (0, CHUNK_JSON) => json = Some(parse_json(path, data)?),
            (0, _) => return Err(corrupt("the first chunk is not the JSON chunk".into())),
            (1, CHUNK_BIN) => bin_chunk = Some(data.to_vec()),
            (_, CHUNK_JSON) | (_, CHUNK_BIN) => {
                return Err(corrupt(format!(
                    "chunk {index} repeats a JSON or BIN chunk"
                )))
            }
            _ => other_chunks.push((kind, data.to_vec())),
        }
        at = end;
        index += 1;
    }
    let json = json.ok_or_else(|| corrupt("no JSON chunk".into()))?;
    Ok(Document {
        format: Format::Glb,
        json,
        bin_chunk,
        other_chunks,
    })
}

fn parse_json(path: &Path, bytes: &[u8]) -> Result<Value> {
    // A byte-order mark is not allowed by the spec but some tools write one; GLB JSON chunks
    // are padded with spaces (and, from some exporters, NULs). Neither is content.
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let end = bytes
        .iter()
        .rposition(|&b| b != 0 && b != b' ')
        .map_or(0, |p| p + 1);
    serde_json::from_slice(&bytes[..end]).map_err(|e| {
        Error::scene(
            path,
            format!("not a glTF file: its JSON does not parse: {e}"),
        )
    })
}

fn check_is_gltf2(path: &Path, json: &Value) -> Result<()> {
    let Some(root) = json.as_object() else {
        return Err(Error::scene(
            path,
            "not a glTF file: the JSON is not an object",
        ));
    };
    let version = root
        .get("asset")
        .and_then(|a| a.get("version"))
        .and_then(Value::as_str)
        .ok_or_else(|| {
            Error::scene(
                path,
                "not a glTF file: it has no \"asset\": {\"version\": ...}",
            )
        })?;
    if !version.starts_with("2.") {
        return Err(Error::scene(
            path,
            format!("glTF version {version}; only glTF 2.x is supported"),
        ));
    }
    Ok(())
}

/// The JSON text of a `.gltf` file: pretty-printed, ending with a newline.
pub fn gltf_bytes(json: &Value) -> Result<Vec<u8>> {
    let mut text = serde_json::to_vec_pretty(json)
        .map_err(|e| Error::Usage(format!("cannot serialise the glTF JSON: {e}")))?;
    text.push(b'\n');
    Ok(text)
}

/// A `.glb` file: the JSON chunk (compact, space-padded), the BIN chunk if any (zero-padded),
/// then the other chunks as they were.
pub fn glb_bytes(
    json: &Value,
    bin: Option<&[u8]>,
    other_chunks: &[(u32, Vec<u8>)],
) -> Result<Vec<u8>> {
    let json_text = serde_json::to_vec(json)
        .map_err(|e| Error::Usage(format!("cannot serialise the glTF JSON: {e}")))?;
    let mut chunks: Vec<(u32, &[u8], u8)> = vec![(CHUNK_JSON, &json_text, b' ')];
    if let Some(bin) = bin {
        chunks.push((CHUNK_BIN, bin, 0));
    }
    for (kind, data) in other_chunks {
        chunks.push((*kind, data, 0));
    }
    let total: usize = GLB_HEADER_LEN
        + chunks
            .iter()
            .map(|(_, d, _)| CHUNK_HEADER_LEN + padded_len(d.len()))
            .sum::<usize>();
    let total32 = u32::try_from(total).map_err(|_| {
        Error::Usage(format!(
            "the GLB would be {total} bytes, over the 4 GiB limit"
        ))
    })?;
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(&GLB_MAGIC.to_le_bytes());
    out.extend_from_slice(&GLB_VERSION.to_le_bytes());
    out.extend_from_slice(&total32.to_le_bytes());
    for (kind, data, pad) in chunks {
        let len = padded_len(data.len());
        // `total` fits in u32, so every chunk length does too.
        out.extend_from_slice(&(len as u32).to_le_bytes());
        out.extend_from_slice(&kind.to_le_bytes());
        out.extend_from_slice(data);
        out.resize(out.len() + (len - data.len()), pad);
    }
    Ok(out)
}

/// `len` rounded up to a multiple of 4, the alignment of GLB chunks and of our buffer views.
pub fn padded_len(len: usize) -> usize {
    len.div_ceil(4) * 4
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glb_round_trips_through_bytes() {
        let json = serde_json::json!({"asset": {"version": "2.0"}, "buffers": [{"byteLength": 5}]});
        let other = vec![(0x1234_5678, vec![9u8, 8, 7])];
        let bytes = glb_bytes(&json, Some(&[1, 2, 3, 4, 5]), &other).unwrap();
        assert_eq!(bytes.len() % 4, 0);
        let dir = std::env::temp_dir().join(format!("streaklight-doc-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("a.glb");
        std::fs::write(&path, &bytes).unwrap();
        let doc = read(&path).unwrap();
        assert_eq!(doc.format, Format::Glb);
        assert_eq!(doc.json, json);
        assert_eq!(
            doc.bin_chunk.as_deref(),
            Some(&[1u8, 2, 3, 4, 5, 0, 0, 0][..])
        );
        assert_eq!(doc.other_chunks, vec![(0x1234_5678, vec![9u8, 8, 7, 0])]);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
