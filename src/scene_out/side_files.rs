//! A `.gltf` output's folder holds every file it refers to: the input's buffer and image files
//! are copied beside it, under names made from the output's own name, so that
//!
//! - the output still loads when its folder is copied elsewhere;
//! - a tool that rewrites the output in place (glTF-Transform writes buffers back under their
//!   URIs) writes into the copies, never into the input's files;
//! - two outputs in one folder never share a file: `lit.gltf`'s files are
//!   `lit.buffer0.bin`, `lit.image2.png`, `lit.streaklight.bin`. The last two dot-separated
//!   parts of such a name (a kind with its index, and an extension without dots) are never
//!   the same for two outputs of different names, nor for two resources of one output.
//!
//! The alternative, [`InputFiles::Reference`](super::InputFiles::Reference), keeps the input's
//! files where they are and rewrites the URIs to reach them (the `resources` module).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use serde_json::Value;

use super::resources::{encode_path, LocalResource};
use super::ResourceKind;
use crate::Result;

/// A file written beside the output: where, and its bytes.
pub(crate) type SideFile = (PathBuf, Vec<u8>);

/// The name of the copy of resource `kind` `index` (a file at `source`) beside output `stem`.
pub(crate) fn copy_name(stem: &str, kind: ResourceKind, index: usize, source: &Path) -> String {
    let kind = match kind {
        ResourceKind::Buffer => "buffer",
        ResourceKind::Image => "image",
    };
    let ext = source
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .filter(|e| {
            !e.is_empty()
                && e.len() <= 8
                && e.bytes().all(|b| b.is_ascii_alphanumeric())
                && e != "gltf"
                && e != "glb"
        })
        .unwrap_or_else(|| "bin".into());
    format!("{stem}.{kind}{index}.{ext}")
}

/// The name of the buffer file holding the data streaklight adds, beside output `stem`.
pub(crate) fn data_name(stem: &str) -> String {
    format!("{stem}.streaklight.bin")
}

/// Copies every local resource of `json` into `folder` (see the module docs) and points its
/// URI at the copy. A file two resources share is copied once. Returns the files to write and
/// what was copied where.
pub(crate) fn copy_beside(
    json: &mut Value,
    resources: &[LocalResource],
    folder: &Path,
    stem: &str,
) -> Result<(Vec<SideFile>, Vec<super::CopiedFile>)> {
    let mut files = Vec::new();
    let mut copied = Vec::new();
    let mut names: HashMap<&Path, String> = HashMap::new();
    for res in resources {
        let name = match names.get(res.path.as_path()) {
            Some(name) => name.clone(),
            None => {
                let name = copy_name(stem, res.kind, res.index, &res.path);
                let bytes = crate::input_file::read(&res.path)?;
                files.push((folder.join(&name), bytes));
                names.insert(&res.path, name.clone());
                name
            }
        };
        let uri = encode_path(&name);
        let key = match res.kind {
            ResourceKind::Buffer => "buffers",
            ResourceKind::Image => "images",
        };
        if let Some(item) = json.get_mut(key).and_then(|a| a.get_mut(res.index)) {
            item["uri"] = Value::from(uri.clone());
        }
        copied.push(super::CopiedFile {
            kind: res.kind,
            index: res.index,
            from: res.path.clone(),
            to: folder.join(&name),
            uri,
        });
    }
    Ok((files, copied))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn copy_names_cannot_collide() {
        let p = Path::new;
        assert_eq!(
            copy_name("lit", ResourceKind::Buffer, 0, p("in/water.bin")),
            "lit.buffer0.bin"
        );
        assert_eq!(
            copy_name("lit", ResourceKind::Image, 3, p("t/A.PNG")),
            "lit.image3.png"
        );
        // No extension, a dotted or odd one, or a glTF one: ".bin".
        for odd in ["noext", "x.tar.gz~", "x.gltf", "x.my ext"] {
            assert!(
                copy_name("o", ResourceKind::Buffer, 1, p(odd)).ends_with(".buffer1.bin"),
                "{odd}"
            );
        }
        assert_ne!(
            copy_name("lit.buffer0", ResourceKind::Buffer, 0, p("a.bin")),
            data_name("lit")
        );
    }
}
