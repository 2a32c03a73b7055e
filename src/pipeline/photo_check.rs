//! Whether a photo can have been taken by the scene's camera (method §2): large enough for
//! the superpixels, and of the camera's aspect ratio.

use std::path::Path;

use crate::photo_in::Photo;
use crate::scene_in::Scene;
use crate::{Error, Result};

/// The smallest photo the method can work with: superpixels of ~20 pixels need room.
pub const MIN_PHOTO_SIDE: u32 = 64;
/// How far the photo's aspect ratio may differ from the camera's (method §2).
pub const ASPECT_TOLERANCE: f32 = 0.005;

/// Checks that the photo can have been taken by the scene's camera; `path` names the photo
/// in messages.
pub fn check_photo(scene: &Scene, photo: &Photo, path: &Path) -> Result<()> {
    if photo.width < MIN_PHOTO_SIDE || photo.height < MIN_PHOTO_SIDE {
        return Err(Error::photo(
            path,
            format!(
                "the photo is {} x {} pixels; streaklight needs at least {MIN_PHOTO_SIDE} x {MIN_PHOTO_SIDE}",
                photo.width, photo.height
            ),
        ));
    }
    if let Some(camera_aspect) = scene.camera.aspect_ratio {
        let photo_aspect = photo.width as f32 / photo.height as f32;
        if ((photo_aspect - camera_aspect) / camera_aspect).abs() > ASPECT_TOLERANCE {
            return Err(Error::photo(
                path,
                format!(
                    "the photo's aspect ratio {photo_aspect:.4} ({} x {}) differs from the camera \"{}\"'s {camera_aspect:.4}: was it taken with another camera, or cropped?",
                    photo.width, photo.height, scene.camera.name
                ),
            ));
        }
    }
    Ok(())
}
