//! Assertions on what the Khronos glTF-Validator reports, run through node
//! (`tests/validator/validate.mjs`; needs `npm ci --prefix tests/validator`).

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

use serde_json::Value;

/// The errors and warnings (code, JSON pointer) -> count the Khronos glTF-Validator reports.
pub fn validator_problems(file: &Path) -> BTreeMap<(String, String), usize> {
    validator_messages(file, 1)
}

/// The errors alone, as [`validator_problems`].
pub fn validator_errors(file: &Path) -> BTreeMap<(String, String), usize> {
    validator_messages(file, 0)
}

/// The messages of severity `max_severity` or more severe (0 error, 1 warning, 2 information).
fn validator_messages(file: &Path, max_severity: u64) -> BTreeMap<(String, String), usize> {
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/validator/validate.mjs");
    let out = Command::new("node").arg(script).arg(file).output().unwrap_or_else(|e| {
        panic!("cannot run `node` ({e}): run `scripts/test`, which installs Node.js and runs `npm ci --prefix tests/validator`")
    });
    assert!(
        out.status.success(),
        "glTF-Validator on {} failed ({}): {} -- if the package is missing, run `scripts/test` (it runs `npm ci --prefix tests/validator`)",
        file.display(),
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    let mut problems = BTreeMap::new();
    for m in report["issues"]["messages"].as_array().unwrap() {
        if m["severity"].as_u64().unwrap() <= max_severity {
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
    assert_no_new_problems_except(input, output, |_, _| false);
}

/// [`assert_no_new_problems`], accepting a problem (code, pointer) that `input` does not have
/// at all where `excused` says so.
pub fn assert_no_new_problems_except(
    input: &Path,
    output: &Path,
    excused: impl Fn(&str, &str) -> bool,
) {
    let before = validator_problems(input);
    let after = validator_problems(output);
    let added: Vec<_> = after
        .iter()
        .filter(|(key, n)| before.get(*key).is_none_or(|m| *n > m))
        .filter(|(key, _)| before.contains_key(*key) || !excused(&key.0, &key.1))
        .collect();
    assert!(
        added.is_empty(),
        "{}: glTF-Validator errors/warnings {} did not have: {added:?}",
        output.display(),
        input.display()
    );
}
