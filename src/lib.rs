//! streaklight: fit rectangle area lights to the reflections ("streaks") of lights on night
//! water, and write them into a glTF scene.
//!
//! The pipeline of METHOD.md §5, one module per step:
//!
//! | step | module |
//! |---|---|
//! | 1. load the scene, bake transforms, build the BVH | [`scene_in`], [`tracing`] |
//! | 2. decode the photo, mark clipped and water pixels | [`photo_in`], [`water_mask`] |
//! | 3-6. superpixels, seeds, streaks, streak edges | [`streaks`] |
//! | reflection model (§4) | [`optics`] |
//! | 7-9. light plane, radiance, edges | [`fitting`] |
//! | 10. write the lights back | [`scene_out`] |
//! | the whole converter, end to end | [`convert`], [`report`] |
//! | rendering a lit scene (to make and check photos) | [`render`], [`photo_out`] |
//! | sample scenes of the paper's setup | [`samples`] |

pub mod convert;
pub mod error;
pub mod fitting;
pub mod optics;
pub mod output_file;
pub mod photo_in;
pub mod photo_out;
pub mod random;
pub mod render;
pub mod report;
pub mod samples;
pub mod scene_in;
pub mod scene_out;
pub mod streaks;
pub mod tracing;
pub mod water_mask;
pub mod water_model;

pub use error::{Error, Result};
