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
    /// The file it was read from.
    pub path: PathBuf,
    pub json: Value,
    /// Empty for an `EXT_meshopt_compression` fallback buffer, which has no bytes.
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

/// The bytes a `data:` URI holds, or the file a relative URI names (from the document at
/// `doc`).
fn uri_bytes(doc: &Path, uri: &str) -> Vec<u8> {
    if uri.starts_with("data:") {
        return base64::engine::general_purpose::STANDARD
            .decode(&uri[uri.find(',').unwrap() + 1..])
            .unwrap();
    }
    std::fs::read(resolve(doc, uri).unwrap())
        .unwrap_or_else(|e| panic!("{}: {uri}: {e}", doc.display()))
}

/// A buffer without bytes of its own: `EXT_meshopt_compression`'s fallback, which readers
/// that decompress never load (glTF-Transform's `optimize` writes one, without a URI).
pub fn is_meshopt_fallback(buffer: &Value) -> bool {
    buffer.get("uri").is_none()
        && buffer.pointer("/extensions/EXT_meshopt_compression/fallback")
            == Some(&Value::Bool(true))
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
    for (i, b) in json["buffers"].as_array().into_iter().flatten().enumerate() {
        let len = b["byteLength"].as_u64().unwrap() as usize;
        let data = match b["uri"].as_str() {
            None if i > 0 || bin.is_none() => {
                assert!(
                    is_meshopt_fallback(b),
                    "{}: buffer {i} has no uri",
                    path.display()
                );
                buffers.push(Vec::new());
                continue;
            }
            None => bin.clone().unwrap(),
            Some(uri) => uri_bytes(path, uri),
        };
        assert!(
            data.len() >= len,
            "{}: buffer {i} holds {} bytes, shorter than its byteLength {len}",
            path.display(),
            data.len()
        );
        buffers.push(data[..len].to_vec());
    }
    Doc {
        path: path.to_path_buf(),
        json,
        buffers,
        glb_chunks,
    }
}

impl Doc {
    /// The bytes of buffer view `v`.
    pub fn view_bytes(&self, v: usize) -> &[u8] {
        let view = &self.json["bufferViews"][v];
        let buffer = &self.buffers[view["buffer"].as_u64().unwrap() as usize];
        let start = view["byteOffset"].as_u64().unwrap_or(0) as usize;
        &buffer[start..start + view["byteLength"].as_u64().unwrap() as usize]
    }

    /// The bytes of image `i`, wherever they are stored (a buffer view, a `data:` URI, a file).
    pub fn image_bytes(&self, i: usize) -> Vec<u8> {
        let image = &self.json["images"][i];
        match image["uri"].as_str() {
            Some(uri) => uri_bytes(&self.path, uri),
            None => self
                .view_bytes(image["bufferView"].as_u64().unwrap() as usize)
                .to_vec(),
        }
    }

    /// A `.glb` file.
    pub fn is_glb(&self) -> bool {
        !self.glb_chunks.is_empty()
    }
}

/// Whether a difference [`json_diff`] found between an input and its output (a pointer in
/// `changed` or `added`) is only where the data is stored: buffers' URIs and lengths (a `.glb`
/// output merges every buffer into its BIN chunk, a `.gltf` output refers to copies beside
/// it), the buffer and offset of a buffer view, and an image's URI replaced by a buffer view
/// (with its media type). [`assert_same_data`] then checks that every value reads the same.
pub fn is_storage_change(pointer: &str) -> bool {
    let parts: Vec<&str> = pointer.trim_start_matches('/').split('/').collect();
    match parts.as_slice() {
        ["buffers", _, "uri" | "uri (removed)" | "byteLength"] => true,
        // Buffer k > 0 merged into buffer 0 of a .glb (this output, or one it was made from).
        ["buffers", k] => k.strip_suffix(" (removed)").is_some_and(|k| k != "0"),
        ["bufferViews", _, "buffer" | "byteOffset"] => true,
        ["images", _, "uri" | "uri (removed)" | "bufferView" | "mimeType"] => true,
        _ => false,
    }
}

/// Asserts that every buffer view and every image of `a` holds the same bytes in `b`, however
/// each stores them; and that no buffer of a `.glb` `b` refers to a file or a `data:` URI.
pub fn assert_same_data(a: &Doc, b: &Doc) {
    let count = |d: &Doc, key: &str| d.json[key].as_array().map_or(0, Vec::len);
    for v in 0..count(a, "bufferViews") {
        if a.buffers[a.json["bufferViews"][v]["buffer"].as_u64().unwrap() as usize].is_empty() {
            continue; // a view of a meshopt fallback buffer holds no bytes
        }
        assert!(
            a.view_bytes(v) == b.view_bytes(v),
            "{}: buffer view {v} of {} reads differently",
            b.path.display(),
            a.path.display()
        );
    }
    for i in 0..count(a, "images") {
        assert!(
            a.image_bytes(i) == b.image_bytes(i),
            "{}: image {i} of {} differs",
            b.path.display(),
            a.path.display()
        );
    }
    if b.is_glb() {
        for (i, buffer) in b.json["buffers"]
            .as_array()
            .into_iter()
            .flatten()
            .enumerate()
        {
            assert!(
                buffer.get("uri").is_none(),
                "{}: buffer {i} is not in the BIN chunk",
                b.path.display()
            );
        }
    }
}

/// Asserts that every buffer of `a` is a prefix of the buffer of the same index of `b`, where
/// `b` keeps `a`'s buffers apart (a `.gltf` written from it; a `.glb` written from a document
/// with one buffer, which becomes its BIN chunk). A `.glb` merges several into one (and a
/// `.gltf` written from that `.glb` keeps them merged), which [`assert_same_data`] checks
/// view by view.
pub fn assert_buffers_kept(a: &Doc, b: &Doc) {
    if b.buffers.len() < a.buffers.len() {
        return;
    }
    for (i, (x, y)) in a.buffers.iter().zip(&b.buffers).enumerate() {
        assert!(
            y.starts_with(x),
            "{}: buffer {i} of {} changed",
            b.path.display(),
            a.path.display()
        );
    }
}

/// Asserts that `output` keeps every JSON value of `input` at the same path (objects may gain
/// keys, arrays may gain trailing elements) apart from where the data is stored
/// ([`is_storage_change`]), that every buffer view and image reads the same bytes, and that
/// every input buffer's bytes are a prefix of the output's buffer of the same index (where
/// [`assert_buffers_kept`] applies).
pub fn assert_keeps_everything(input: &Path, output: &Path) {
    let a = load(input);
    let b = load(output);
    let mut diffs = json_diff(&a.json, &b.json).changed;
    diffs.retain(|d| !is_storage_change(d));
    assert!(
        diffs.is_empty(),
        "{} lost or changed values of {}: {diffs:?}",
        output.display(),
        input.display()
    );
    assert_same_data(&a, &b);
    assert_buffers_kept(&a, &b);
    assert_eq!(
        a.json.get("extensionsRequired"),
        b.json.get("extensionsRequired"),
        "extensionsRequired must not change"
    );
}

/// Every `EXT_lights_area` light on a node of the document at `path`: (light name, light
/// object, node translation, node rotation; empty when the node has none), sorted by name.
pub fn lights_by_name(path: &Path) -> Vec<(String, Value, Vec<f64>, Vec<f64>)> {
    let json = load(path).json;
    let floats = |v: &Value| -> Vec<f64> {
        v.as_array()
            .into_iter()
            .flatten()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let mut out: Vec<_> = json["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|n| {
            let i = n["extensions"]["EXT_lights_area"]["light"].as_u64()? as usize;
            let light = json["extensions"]["EXT_lights_area"]["lights"][i].clone();
            let name = light["name"].as_str().unwrap().to_string();
            Some((
                name,
                light,
                floats(&n["translation"]),
                floats(&n["rotation"]),
            ))
        })
        .collect();
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}
