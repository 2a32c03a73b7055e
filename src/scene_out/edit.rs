//! Small helpers to append to a glTF JSON tree without touching what is already there.
//!
//! Every helper either creates a missing array/object or appends to the existing one; a
//! member that exists with the wrong JSON type is a malformed input, reported against the
//! input file rather than silently replaced.

use std::path::Path;

use serde_json::{Map, Value};

use crate::{Error, Result};

/// The root object of the document (checked to be an object when it was read).
pub(crate) fn root_mut<'a>(
    json: &'a mut Value,
    input: &Path,
) -> Result<&'a mut Map<String, Value>> {
    json.as_object_mut()
        .ok_or_else(|| Error::scene(input, "not a glTF file: the JSON is not an object"))
}

/// `object[key]` as an array, created empty if absent.
pub(crate) fn array_mut<'a>(
    object: &'a mut Map<String, Value>,
    key: &str,
    input: &Path,
) -> Result<&'a mut Vec<Value>> {
    object
        .entry(key.to_string())
        .or_insert_with(|| Value::Array(Vec::new()))
        .as_array_mut()
        .ok_or_else(|| Error::scene(input, format!("\"{key}\" is not an array")))
}

/// `object[key]` as an object, created empty if absent.
pub(crate) fn object_mut<'a>(
    object: &'a mut Map<String, Value>,
    key: &str,
    input: &Path,
) -> Result<&'a mut Map<String, Value>> {
    object
        .entry(key.to_string())
        .or_insert_with(|| Value::Object(Map::new()))
        .as_object_mut()
        .ok_or_else(|| Error::scene(input, format!("\"{key}\" is not an object")))
}

/// Appends `value` to the top-level array `key` and returns its index.
pub(crate) fn push(
    root: &mut Map<String, Value>,
    key: &str,
    value: Value,
    input: &Path,
) -> Result<usize> {
    let array = array_mut(root, key, input)?;
    array.push(value);
    Ok(array.len() - 1)
}

/// Adds `name` to `extensionsUsed` unless it is listed already. `extensionsRequired` is never
/// touched: viewers refuse files that require an extension they lack (method §7).
pub(crate) fn use_extension(root: &mut Map<String, Value>, name: &str, input: &Path) -> Result<()> {
    let used = array_mut(root, "extensionsUsed", input)?;
    if !used.iter().any(|v| v.as_str() == Some(name)) {
        used.push(Value::from(name));
    }
    Ok(())
}

/// The number of elements of the top-level array `key` (0 if absent).
pub(crate) fn len_of(root: &Map<String, Value>, key: &str) -> usize {
    root.get(key).and_then(Value::as_array).map_or(0, Vec::len)
}
