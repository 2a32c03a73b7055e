//! Water for the water-model tests: a scene's mesh flattened to its mean level.

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
