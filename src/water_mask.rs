//! Step 2 of method §5, second half: which pixels of the photo see the water.

use rayon::prelude::*;

use crate::scene_in::{Scene, KEPT_PIXELS};

/// For each pixel of a `width` x `height` photo (row-major, row 0 at the top), true when the
/// camera ray through the pixel centre first hits the water. An image the scene's cache of
/// centre hits can hold whole is traced into it ([`Scene::centre_hits`]), and the lamps'
/// direct images read the hits again; a larger one is traced row by row (in packets, as the
/// cache is), without the 8 bytes a pixel the cache would take for a moment.
pub fn water_mask(scene: &Scene, width: u32, height: u32) -> Vec<bool> {
    if width == 0 || height == 0 {
        return Vec::new();
    }
    let kept = (width as usize * height as usize <= KEPT_PIXELS)
        .then(|| scene.centre_hits((0, 0, width - 1, height - 1), width, height, &|_| false));
    let is_water = |hit: Option<(u32, f32)>| {
        hit.is_some_and(|(triangle, _)| scene.is_water[triangle as usize])
    };
    let mut mask = vec![false; width as usize * height as usize];
    mask.par_chunks_mut(width as usize)
        .enumerate()
        .for_each(|(y, row)| {
            let y = y as u32;
            match &kept {
                Some(hits) => {
                    for (x, cell) in row.iter_mut().enumerate() {
                        *cell = is_water(hits.get(x as u32, y));
                    }
                }
                None => {
                    let mut cells = row.iter_mut();
                    scene.centre_row(y, (0, width - 1), width, height, &|_| false, &mut |hit| {
                        if let Some(cell) = cells.next() {
                            *cell = is_water(hit.flatten());
                        }
                    });
                }
            }
        });
    mask
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An image too large for the cache of centre hits is traced row by row to the same mask:
    /// pixel (5x + 2, 5y + 2) of 3000 x 3000 (9 M pixels) has the centre of pixel (x, y) of
    /// the 600 x 600 mask, which the cache served.
    #[test]
    fn a_photo_too_large_for_the_cache_gets_the_same_mask() {
        let crate::samples::Fixture {
            scene,
            photo,
            water,
            ..
        } = crate::samples::fixture("table1.png");
        assert_eq!((photo.width, photo.height), (600, 600));
        let large = water_mask(scene, 3000, 3000);
        const { assert!(3000 * 3000 > KEPT_PIXELS) };
        let mut differ = 0;
        for y in 0..600 {
            for x in 0..600 {
                if large[(5 * y + 2) * 3000 + 5 * x + 2] != water[y * 600 + x] {
                    differ += 1;
                }
            }
        }
        let seen = water.iter().filter(|&&w| w).count();
        assert!(seen > 100_000, "the camera sees water in {seen} pixels");
        // The two directions agree to rounding: only a pixel whose ray grazes the water's
        // edge may flip.
        assert!(differ <= 5, "{differ} pixels differ");
        // Every pixel of rows across the horizon and the water, traced in packets, as a
        // single ray through its centre classifies it.
        let origin = scene.camera.position;
        let (mut on_water, mut off_water) = (0, 0);
        for y in (0..3000u32).step_by(97) {
            let row = &large[y as usize * 3000..(y as usize + 1) * 3000];
            for (x, &got) in row.iter().enumerate() {
                let dir = scene
                    .camera
                    .direction(x as f32 + 0.5, y as f32 + 0.5, 3000, 3000);
                let want = scene
                    .tracer
                    .closest_hit(origin, dir, 0.0, f32::INFINITY)
                    .is_some_and(|h| scene.is_water[h.triangle as usize]);
                assert_eq!(got, want, "pixel ({x}, {y})");
            }
            on_water += row.iter().filter(|&&w| w).count();
            off_water += row.iter().filter(|&&w| !w).count();
        }
        assert!(
            on_water > 10_000 && off_water > 10_000,
            "{on_water} water and {off_water} other pixels compared"
        );
    }
}
