//! streaklight: fit rectangle area lights to the reflections ("streaks") of lights on night
//! water, and write them into a glTF scene.
//!
//! The pipeline of `docs/method.md` §5, one module per step:
//!
//! | step | module |
//! |---|---|
//! | 1. load the scene, bake transforms, build the BVH | [`scene_in`], [`tracing`] |
//! | 2. decode the photo, mark clipped and water pixels | [`photo_in`] ([`photo_rounding`]), [`water_mask`] |
//! | a night's smooth background, taken off the photo | [`background`] |
//! | 3-6. superpixels, seeds, streaks, streak edges | [`streaks`] |
//! | reflection model (§4) | [`optics`] |
//! | how a pixel's reflection reaches a light's plane | [`water_model`] |
//! | 7-9. light plane, radiance, edges; the joint fit; the gloss | [`fitting`] |
//! | the whole fit in memory, with its policies | [`pipeline`], [`settings`], [`progress`] |
//! | 10. write the lights back | [`scene_out`] |
//! | files in, files out; the report | [`convert`], [`batch`], [`report`] |
//! | pictures of every stage, and their page | [`debug_pictures`] |
//! | rendering a lit scene (to make and check photos) | [`render`], [`environment`], [`photo_out`] |
//! | sample scenes of the paper's setup | [`samples`] |
//!
//! # Fitting in memory
//!
//! [`pipeline::fit`] takes a loaded scene and a decoded photo and returns the lights; it is
//! what `streaklight fit` runs between reading and writing files. Here the bundled Table 1
//! sample (one 3 x 3 m light of radiance 20 with its corner at (-4, 2, 0)) is fitted with the
//! default settings:
//!
//! ```
//! use streaklight::pipeline::{self, FitSettings};
//! use streaklight::progress::Reporter;
//! use streaklight::{photo_in, samples, scene_in};
//!
//! # fn main() -> streaklight::Result<()> {
//! let dir = std::env::temp_dir().join(format!("streaklight-doc-{}", std::process::id()));
//! samples::write_scenes(&dir)?; // the scene of the paper's setup and its water mesh
//! let scene = scene_in::load(&dir.join("scene.gltf"), &Default::default())?;
//! let png = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/samples/table1.png"))
//!     .map_err(|e| streaklight::Error::io("samples/table1.png", e))?;
//! let photo = photo_in::decode(&png, samples::PHOTO_EXPOSURE, "table1.png".as_ref())?;
//!
//! let lit = pipeline::fit(&scene, &photo, &FitSettings::default(), Reporter::default())?;
//!
//! assert_eq!(lit.lights.len(), 1);
//! let light = &lit.lights[0];
//! let corner = light.corner_left_bottom_world(scene.origin);
//! assert!((corner.x + 4.0).abs() < 0.03 && (corner.y - 2.0).abs() < 0.03);
//! assert!((light.width() - 3.0).abs() < 0.03 && (light.height() - 3.0).abs() < 0.03);
//! assert!((light.radiance[0] - 20.0).abs() < 0.2);
//! # let _ = std::fs::remove_dir_all(&dir);
//! # Ok(())
//! # }
//! ```

pub mod background;
pub mod batch;
pub mod convert;
pub mod debug_pictures;
pub mod environment;
pub mod error;
pub mod fitting;
pub mod input_file;
pub mod limits;
pub mod names;
pub mod optics;
pub mod output_file;
pub mod photo_exif;
pub mod photo_in;
pub mod photo_out;
pub mod photo_rounding;
pub mod pipeline;
pub mod pixel_index;
pub mod pixel_scale;
pub mod plane;
pub mod progress;
pub mod random;
pub mod render;
pub mod report;
pub mod samples;
pub mod scene_in;
pub mod scene_out;
pub mod settings;
pub mod streaks;
pub mod tracing;
pub mod water_mask;
pub mod water_model;

pub use error::{Error, Result};
