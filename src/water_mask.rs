//! Step 2 of method §5, second half: which pixels of the photo see the water.

use rayon::prelude::*;

use crate::scene_in::Scene;

/// For each pixel of a `width` x `height` photo (row-major, row 0 at the top), true when the
/// camera ray through the pixel centre first hits the water. The hits are the scene's
/// centre hits of the whole image ([`Scene::centre_hits`]), which the lamps' direct images
/// read again.
pub fn water_mask(scene: &Scene, width: u32, height: u32) -> Vec<bool> {
    if width == 0 || height == 0 {
        return Vec::new();
    }
    let hits = scene.centre_hits((0, 0, width - 1, height - 1), width, height, &|_| false);
    let mut mask = vec![false; width as usize * height as usize];
    mask.par_chunks_mut(width as usize)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, cell) in row.iter_mut().enumerate() {
                *cell = hits
                    .get(x as u32, y as u32)
                    .is_some_and(|(triangle, _)| scene.is_water[triangle as usize]);
            }
        });
    mask
}
