//! Helpers shared by the integration tests, one module per concern. Each test binary uses a
//! subset of them (hence `dead_code` allowed).
#![allow(dead_code)]

/// Temporary folders and folder listings.
pub mod dirs;

/// The glTF/GLB builder ([`TestScene`], the paper setup in miniature) and `data:` URIs.
pub mod gltf_builder;

/// JSON documents compared value by value.
pub mod json;

/// Khronos glTF-Validator assertions.
pub mod validator;

/// The chain sample scene -> photo -> water mask -> streaks, and `convert` options for it.
pub mod pipeline;

/// Running the command line.
pub mod cli;

/// Running the Node scripts of `tests/engines/`.
pub mod node;

/// Running code on a given number of threads.
pub mod threads;

/// Small end-to-end `fit` cases (scene, truth light, rendered photo).
pub mod fit_case;

/// The fitting tests' threshold segmentation and paper fit of a sample photo.
pub mod fit_helpers;

/// Lossless checks on glTF outputs.
pub mod gltf_check;

/// The glTF writer's test inputs (lights, generated scenes, published samples).
pub mod scene_out_case;

/// What every output of the glTF writer must satisfy.
pub mod scene_out_checks;

/// Appends a fit setup (camera, water, wall, optional light) to glTF files we did not write.
pub mod augment;

// The helpers most tests call, at `common::`; a binary that calls none of them would warn.
#[allow(unused_imports)]
pub use cli::run_cli;
#[allow(unused_imports)]
pub use dirs::temp_dir;
#[allow(unused_imports)]
pub use gltf_builder::{flat_grid, paper_setup, TestScene};

/// A fitted light against the sample light it stands for.
pub mod truth;

/// A scene's water flattened to its mean level.
pub mod water;
