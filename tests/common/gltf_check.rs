//! Reading glTF outputs back independently of the writer, and the check "every original value
//! and byte is still there"; the published sample files those checks run on.

use std::path::{Path, PathBuf};

use base64::Engine;
use serde_json::Value;

use super::gltf_builder::GLB_BIN;
use super::json::json_diff;

/// The published glTF samples (`tests/data/gltf-real`, see its README).
pub const REAL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/gltf-real");

/// The `.gltf` files of [`REAL`], sorted.
pub fn real_files() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(REAL)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "gltf"))
        .collect();
    files.sort();
    files
}

/// A document's JSON, the bytes of each of its buffers (data URIs, files, the BIN chunk), and
/// for a .glb its chunks (type, bytes) as stored.
pub struct Doc {
    pub json: Value,
    pub buffers: Vec<Vec<u8>>,
    pub glb_chunks: Vec<(u32, Vec<u8>)>,
}

/// The file a relative URI points at, from the document at `doc`.
pub fn resolve(doc: &Path, uri: &str) -> Option<PathBuf> {
    if uri.starts_with("data:") {
        return None;
    }
    Some(
        doc.parent()
            .unwrap()
            .join(streaklight::scene_in::document::percent_decode(uri)),
    )
}

/// Reads a .gltf/.glb and every buffer it refers to (data URIs, files, the BIN chunk).
pub fn load(path: &Path) -> Doc {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let (json, bin, glb_chunks) = if bytes.starts_with(b"glTF") {
        let total = u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize;
        assert_eq!(total, bytes.len(), "GLB length field");
        let mut at = 12;
        let mut chunks = Vec::new();
        while at < bytes.len() {
            let len = u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
            let kind = u32::from_le_bytes(bytes[at + 4..at + 8].try_into().unwrap());
            assert_eq!(len % 4, 0, "chunk length must be a multiple of 4");
            chunks.push((kind, bytes[at + 8..at + 8 + len].to_vec()));
            at += 8 + len;
        }
        let json: Value = serde_json::from_slice(&chunks[0].1).unwrap();
        let bin = chunks
            .get(1)
            .filter(|c| c.0 == GLB_BIN)
            .map(|c| c.1.clone());
        (json, bin, chunks)
    } else {
        (serde_json::from_slice(&bytes).unwrap(), None, Vec::new())
    };
    let mut buffers = Vec::new();
    for b in json["buffers"].as_array().into_iter().flatten() {
        let len = b["byteLength"].as_u64().unwrap() as usize;
        let data = match b["uri"].as_str() {
            None => bin.clone().expect("buffer without uri needs a BIN chunk"),
            Some(uri) if uri.starts_with("data:") => base64::engine::general_purpose::STANDARD
                .decode(&uri[uri.find(',').unwrap() + 1..])
                .unwrap(),
            Some(uri) => std::fs::read(resolve(path, uri).unwrap())
                .unwrap_or_else(|e| panic!("{}: buffer {uri}: {e}", path.display())),
        };
        assert!(data.len() >= len, "buffer shorter than its byteLength");
        buffers.push(data[..len].to_vec());
    }
    Doc {
        json,
        buffers,
        glb_chunks,
    }
}

/// Asserts that every buffer of `a` (read from `input`) is a prefix of the buffer of the same
/// index of `b` (read from `output`).
pub fn assert_buffers_kept(input: &Path, a: &Doc, output: &Path, b: &Doc) {
    assert!(b.buffers.len() >= a.buffers.len());
    for (i, (x, y)) in a.buffers.iter().zip(&b.buffers).enumerate() {
        assert!(
            y.starts_with(x),
            "{}: buffer {i} of {} changed",
            output.display(),
            input.display()
        );
    }
}

/// Asserts that `output` keeps every JSON value of `input` at the same path (objects may gain
/// keys, arrays may gain trailing elements), and that every input buffer's bytes are a prefix
/// of the output's buffer of the same index. Both files are expected to keep their buffers in
/// the same form (a `.gltf` with `data:` buffers into a `.gltf`), so the `uri`s compare equal
/// too.
pub fn assert_keeps_everything(input: &Path, output: &Path) {
    let a = load(input);
    let b = load(output);
    let mut diffs = json_diff(&a.json, &b.json).changed;
    // A `.gltf` -> `.gltf` write keeps even the data URIs; buffer 0 of a GLB grows.
    diffs.retain(|d| !(d == "/buffers/0/byteLength" && a.json["buffers"][0].get("uri").is_none()));
    // A relative URI may be rewritten to reach the same file from the output's folder.
    diffs.retain(|d| {
        let Some(rest) = d.strip_prefix('/').and_then(|r| r.strip_suffix("/uri")) else {
            return true;
        };
        let same_file = |v: &Value, doc: &Path| {
            let uri = v.pointer(&format!("/{rest}/uri"))?.as_str()?;
            resolve(doc, uri)?.canonicalize().ok()
        };
        let (x, y) = (same_file(&a.json, input), same_file(&b.json, output));
        !(x.is_some() && x == y)
    });
    assert!(
        diffs.is_empty(),
        "{} lost or changed values of {}: {diffs:?}",
        output.display(),
        input.display()
    );
    assert_buffers_kept(input, &a, output, &b);
    assert_eq!(
        a.json.get("extensionsRequired"),
        b.json.get("extensionsRequired"),
        "extensionsRequired must not change"
    );
}
