//! Step 2 of method §5, second half: which pixels of the photo see the water.

use rayon::prelude::*;

use crate::scene_in::Scene;

/// For each pixel of a `width` x `height` photo (row-major, row 0 at the top), true when the
/// camera ray through the pixel centre first hits the water.
pub fn water_mask(scene: &Scene, width: u32, height: u32) -> Vec<bool> {
    let mut mask = vec![false; width as usize * height as usize];
    mask.par_chunks_mut(width as usize)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, cell) in row.iter_mut().enumerate() {
                let dir = scene
                    .camera
                    .direction(x as f32 + 0.5, y as f32 + 0.5, width, height);
                *cell = scene
                    .tracer
                    .closest_hit(scene.camera.position, dir, 0.0, f32::INFINITY)
                    .is_some_and(|h| scene.is_water[h.triangle as usize]);
            }
        });
    mask
}
