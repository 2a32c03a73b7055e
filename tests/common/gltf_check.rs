//! Checks on glTF outputs, independent of the writer: "every original value and byte is still
//! there" and "the Khronos glTF-Validator finds nothing new".
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use base64::Engine;
use serde_json::Value;

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
            .filter(|c| c.0 == 0x004E_4942)
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

/// Every value of `a` is present and equal at the same path in `b` (objects may gain keys,
/// arrays may gain trailing elements); returns the JSON pointers where it is not.
pub fn missing_or_changed(a: &Value, b: &Value, at: &str, out: &mut Vec<String>) {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            for (k, v) in x {
                match y.get(k) {
                    Some(w) => missing_or_changed(v, w, &format!("{at}/{k}"), out),
                    None => out.push(format!("{at}/{k} (removed)")),
                }
            }
        }
        (Value::Array(x), Value::Array(y)) => {
            for (i, v) in x.iter().enumerate() {
                match y.get(i) {
                    Some(w) => missing_or_changed(v, w, &format!("{at}/{i}"), out),
                    None => out.push(format!("{at}/{i} (removed)")),
                }
            }
        }
        // serde_json's `==` also tells 1 from 1.0.
        _ if a == b => {}
        _ => out.push(at.to_string()),
    }
}

/// Asserts that `output` keeps every JSON value of `input` at the same path, and that every
/// input buffer's bytes are a prefix of the output's buffer of the same index. Both files are
/// expected to keep their buffers in the same form (a `.gltf` with `data:` buffers into a
/// `.gltf`), so the `uri`s compare equal too.
pub fn assert_keeps_everything(input: &Path, output: &Path) {
    let a = load(input);
    let b = load(output);
    let mut diffs = Vec::new();
    missing_or_changed(&a.json, &b.json, "", &mut diffs);
    // A `.gltf` -> `.gltf` write keeps even the data URIs; buffer 0 of a GLB grows.
    diffs.retain(|d| !(d == "/buffers/0/byteLength" && a.json["buffers"][0].get("uri").is_none()));
    // A relative URI may be rewritten to reach the same file from the output's folder.
    diffs.retain(|d| {
        let Some(rest) = d.strip_prefix('/').and_then(|r| r.strip_suffix("/uri")) else {
            return true;
        };
        let same_file = |v: &Value, doc: &Path| {
            let uri = v.pointer(&format!("/{rest}/uri"))?.as_str()?;
            if uri.starts_with("data:") {
                return None;
            }
            doc.parent()?
                .join(streaklight::scene_in::document::percent_decode(uri))
                .canonicalize()
                .ok()
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
    assert!(b.buffers.len() >= a.buffers.len());
    for (i, (x, y)) in a.buffers.iter().zip(&b.buffers).enumerate() {
        assert!(
            y.starts_with(x),
            "{}: buffer {i} of {} changed",
            output.display(),
            input.display()
        );
    }
    assert_eq!(
        a.json.get("extensionsRequired"),
        b.json.get("extensionsRequired"),
        "extensionsRequired must not change"
    );
}

/// The errors and warnings (code, JSON pointer) -> count the Khronos glTF-Validator reports.
pub fn validator_problems(file: &Path) -> BTreeMap<(String, String), usize> {
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/validator/validate.mjs");
    let out = Command::new("node").arg(script).arg(file).output().unwrap_or_else(|e| {
        panic!("cannot run `node` ({e}): install Node.js, then run `npm ci --prefix tests/validator`")
    });
    assert!(
        out.status.success(),
        "glTF-Validator on {} failed ({}): {} -- if the package is missing, run `npm ci --prefix tests/validator`",
        file.display(),
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    let mut problems = BTreeMap::new();
    for m in report["issues"]["messages"].as_array().unwrap() {
        if m["severity"].as_u64().unwrap() <= 1 {
            let key = (
                m["code"].as_str().unwrap().to_string(),
                m["pointer"].as_str().unwrap_or("").to_string(),
            );
            *problems.entry(key).or_insert(0) += 1;
        }
    }
    problems
}

/// Asserts the validator reports no error and no warning at all.
pub fn assert_validator_clean(file: &Path) {
    let problems = validator_problems(file);
    assert!(
        problems.is_empty(),
        "{}: glTF-Validator errors/warnings: {problems:?}",
        file.display()
    );
}

/// Asserts `output` has no validator error or warning that `input` did not have.
pub fn assert_no_new_problems(input: &Path, output: &Path) {
    let before = validator_problems(input);
    let after = validator_problems(output);
    let added: Vec<_> = after
        .iter()
        .filter(|(key, n)| before.get(*key).is_none_or(|m| *n > m))
        .collect();
    assert!(
        added.is_empty(),
        "{}: glTF-Validator errors/warnings {} did not have: {added:?}",
        output.display(),
        input.display()
    );
}
