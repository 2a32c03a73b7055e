//! JSON files and schemas, and comparing two JSON documents value by value, as JSON pointers.

use std::path::Path;

use serde_json::Value;

/// Where `b` differs from `a`, each place a JSON pointer.
#[derive(Debug, Default)]
pub struct JsonDiff {
    /// Keys and trailing array elements only in `b`.
    pub added: Vec<String>,
    /// Values of `a` that differ in `b`, and those missing from it (`POINTER (removed)`).
    pub changed: Vec<String>,
    /// Objects whose keys common to both come in another order in `b`.
    pub reordered: Vec<String>,
}

/// Walks `a` and `b` together. serde_json's `==` on numbers also tells 1 from 1.0, so a number
/// that changed kind counts as changed.
pub fn json_diff(a: &Value, b: &Value) -> JsonDiff {
    let mut d = JsonDiff::default();
    walk(a, b, "", &mut d);
    d
}

fn walk(a: &Value, b: &Value, at: &str, d: &mut JsonDiff) {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            for (k, v) in x {
                let p = format!("{at}/{k}");
                match y.get(k) {
                    Some(w) => walk(v, w, &p, d),
                    None => d.changed.push(format!("{p} (removed)")),
                }
            }
            let keys: Vec<&String> = x.keys().filter(|k| y.contains_key(*k)).collect();
            let kept: Vec<&String> = y.keys().filter(|k| x.contains_key(*k)).collect();
            if keys != kept {
                d.reordered.push(at.to_string());
            }
            d.added.extend(
                y.keys()
                    .filter(|k| !x.contains_key(*k))
                    .map(|k| format!("{at}/{k}")),
            );
        }
        (Value::Array(x), Value::Array(y)) => {
            for (i, v) in x.iter().enumerate() {
                match y.get(i) {
                    Some(w) => walk(v, w, &format!("{at}/{i}"), d),
                    None => d.changed.push(format!("{at}/{i} (removed)")),
                }
            }
            d.added
                .extend((x.len()..y.len()).map(|i| format!("{at}/{i}")));
        }
        _ if a == b => {}
        _ => d.changed.push(at.to_string()),
    }
}

/// Reads and parses the JSON file `path`.
pub fn read_json(path: &Path) -> Value {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_slice(&bytes).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The JSON Schema `schema/FILE` of the repository.
pub fn schema(file: &str) -> Value {
    read_json(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("schema")
            .join(file),
    )
}

/// A validator for the JSON Schema `schema/FILE`.
pub fn schema_validator(file: &str) -> jsonschema::Validator {
    jsonschema::validator_for(&schema(file)).unwrap()
}
