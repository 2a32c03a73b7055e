//! The files a glTF document refers to (buffer and image URIs), and, for
//! [`InputFiles::Reference`](super::InputFiles::Reference), rewriting their relative URIs when
//! the output is written to another folder than the input.
//!
//! A rewritten URI is the relative path from the output's folder to the original file.
//! `data:` URIs and URIs with a scheme or an absolute path are left as they are. Only the core
//! `buffers[].uri` and `images[].uri` are URIs of files in glTF 2.0.

use std::path::{Component, Path, PathBuf};

use serde_json::Value;

use super::{ResourceKind, UriRewrite};
use crate::{Error, Result};

/// A buffer or image that lives in a local file next to (or under, or above) the input.
#[derive(Debug, Clone)]
pub(crate) struct LocalResource {
    pub kind: ResourceKind,
    pub index: usize,
    pub uri: String,
    /// The file, resolved against the input's folder (lexically normalised).
    pub path: PathBuf,
}

/// Every buffer and image of `json` stored in a local file, resolved against `base_dir`.
pub(crate) fn local_resources(json: &Value, base_dir: &Path) -> Vec<LocalResource> {
    let mut out = Vec::new();
    for (kind, key) in [
        (ResourceKind::Buffer, "buffers"),
        (ResourceKind::Image, "images"),
    ] {
        let Some(items) = json.get(key).and_then(Value::as_array) else {
            continue;
        };
        for (index, item) in items.iter().enumerate() {
            let Some(uri) = item.get("uri").and_then(Value::as_str) else {
                continue;
            };
            if let Some(relative) = relative_file_path(uri) {
                out.push(LocalResource {
                    kind,
                    index,
                    uri: uri.to_string(),
                    path: normalise(&base_dir.join(relative)),
                });
            }
        }
    }
    out
}

/// Rewrites the URI of every local resource so that it resolves from `output_dir` to the same
/// file as it did from the input's folder. Both folders must be absolute and canonical.
pub(crate) fn rewrite_uris(
    json: &mut Value,
    resources: &[LocalResource],
    output_dir: &Path,
    output: &Path,
) -> Result<Vec<UriRewrite>> {
    let mut rewrites = Vec::with_capacity(resources.len());
    for res in resources {
        let relative = relative_path(output_dir, &res.path).ok_or_else(|| {
            Error::output(
                output,
                format!(
                    "{} cannot be reached by a relative path from the output's folder {}; \
                     write the output next to the input",
                    res.path.display(),
                    output_dir.display()
                ),
            )
        })?;
        // Keep a query or fragment the original URI had (rare, but it is part of the URI).
        let suffix = res.uri.find(['?', '#']).map_or("", |at| &res.uri[at..]);
        let new_uri = format!("{}{suffix}", encode_path(&relative));
        let key = match res.kind {
            ResourceKind::Buffer => "buffers",
            ResourceKind::Image => "images",
        };
        if let Some(item) = json.get_mut(key).and_then(|a| a.get_mut(res.index)) {
            item["uri"] = Value::from(new_uri.clone());
        }
        rewrites.push(UriRewrite {
            kind: res.kind,
            index: res.index,
            from: res.uri.clone(),
            to: new_uri,
        });
    }
    Ok(rewrites)
}

/// The file path a URI reference denotes, if it is a relative reference to a local file:
/// not a `data:` URI, no scheme, not an absolute or network path. Percent-escapes decoded.
/// Query and fragment are not part of the file.
pub(crate) fn relative_file_path(uri: &str) -> Option<PathBuf> {
    if uri.is_empty() || uri.starts_with('/') || uri.starts_with('\\') || has_scheme(uri) {
        return None;
    }
    let path = &uri[..uri.find(['?', '#']).unwrap_or(uri.len())];
    // Some exporters write raw spaces or a stray '%': take such a URI literally.
    Some(PathBuf::from(
        percent_decode(path).unwrap_or_else(|| path.to_string()),
    ))
}

/// RFC 3986: scheme = ALPHA *( ALPHA / DIGIT / "+" / "-" / "." ), followed by ':'.
fn has_scheme(uri: &str) -> bool {
    let Some(colon) = uri.find(':') else {
        return false;
    };
    let scheme = &uri[..colon];
    let mut chars = scheme.chars();
    chars.next().is_some_and(|c| c.is_ascii_alphabetic())
        && chars.all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'))
}

fn percent_decode(s: &str) -> Option<String> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// Percent-encodes a relative path (with '/' separators) for use as a URI reference. Only
/// unreserved characters, '/' and a few safe sub-delimiters stay as they are; ':' is encoded
/// so that a first segment cannot read as a scheme.
pub(crate) fn encode_path(path: &str) -> String {
    let mut out = String::with_capacity(path.len());
    for b in path.bytes() {
        if b.is_ascii_alphanumeric() || b"-._~/!$&'()*+,;=@".contains(&b) {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

/// Removes `.` and resolves `..` lexically (the folder it starts from is canonical already).
pub(crate) fn normalise(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    out.push("..");
                }
            }
            other => out.push(other.as_os_str()),
        }
    }
    out
}

/// The relative path from folder `from` to `to`, with '/' separators, or `None` when the two
/// share no root (another drive) or a component is not UTF-8.
pub(crate) fn relative_path(from: &Path, to: &Path) -> Option<String> {
    let from: Vec<Component> = from.components().collect();
    let to: Vec<Component> = to.components().collect();
    if from.first() != to.first() {
        return None;
    }
    let common = from.iter().zip(&to).take_while(|(a, b)| a == b).count();
    let mut parts: Vec<&str> = vec![".."; from.len() - common];
    for c in &to[common..] {
        parts.push(c.as_os_str().to_str()?);
    }
    Some(parts.join("/"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_between_folders() {
        assert_eq!(
            relative_path(Path::new("/a/b/out"), Path::new("/a/b/in/x.bin")).as_deref(),
            Some("../in/x.bin")
        );
        assert_eq!(
            relative_path(Path::new("/a"), Path::new("/a/t/y.png")).as_deref(),
            Some("t/y.png")
        );
    }

    #[test]
    fn uris_decode_and_encode() {
        assert_eq!(
            relative_file_path("data:application/octet-stream;base64,AA"),
            None
        );
        assert_eq!(relative_file_path("https://example.com/a.bin"), None);
        assert_eq!(relative_file_path("/abs.bin"), None);
        assert_eq!(
            relative_file_path("tex/my%20image.png"),
            Some(PathBuf::from("tex/my image.png"))
        );
        assert_eq!(
            relative_file_path("100%.bin"),
            Some(PathBuf::from("100%.bin"))
        );
        assert_eq!(encode_path("../a b/c:d.png"), "../a%20b/c%3Ad.png");
        assert_eq!(normalise(Path::new("/a/./b/../c")), PathBuf::from("/a/c"));
    }
}
