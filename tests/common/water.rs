//! Water for the water-model tests: a scene's mesh flattened to its mean level, and which
//! pixels see the water.

use streaklight::scene_in::Scene;
use streaklight::tracing::{Tracer, Triangle};

/// `scene` with its water flattened onto its mean level (world y = 0), normals straight up.
pub fn flattened(mut scene: Scene) -> Scene {
    let level = -scene.origin.y as f32;
    for ((t, n), &w) in scene
        .triangles
        .iter_mut()
        .zip(scene.normals.iter_mut())
        .zip(&scene.is_water)
    {
        if w {
            for v in t.iter_mut() {
                v.y = level;
            }
            *n = [glam::Vec3::Y; 3];
        }
    }
    let triangles: Vec<Triangle> = scene
        .triangles
        .iter()
        .map(|&vertices| Triangle { vertices })
        .collect();
    scene.tracer = Tracer::new(&triangles);
    scene
}

/// Per pixel of a `w` x `h` image, whether the camera ray through its centre meets the
/// water first.
pub fn water_pixels(scene: &Scene, w: u32, h: u32) -> Vec<bool> {
    use streaklight::render::{camera_hit, CameraHit};
    (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32 + 0.5, (i / w) as f32 + 0.5);
            matches!(camera_hit(scene, &[], x, y, w, h), CameraHit::Water(_))
        })
        .collect()
}
