//! The exact-surface water model: the scene's water mesh is the photo's water, as in the
//! paper's setting (method §4), and exactly as the renderer ([`crate::render`]) makes a
//! pixel: the camera ray's first hit on a water triangle, the mesh's interpolated shading
//! normal as the lobe's axis, its face normal as the side the reflected rays stay on, and the
//! renderer's offset off the surface.

use glam::{Vec2, Vec3};

use super::{LobeDraws, WaterModel};
use crate::optics::{LobeSample, ReflectionModel};
use crate::render::{camera_hit, camera_water_points, CameraHit, WaterPoint};
use crate::scene_in::Scene;

/// The water is the scene's water mesh (see the module doc).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExactSurface;

impl WaterModel for ExactSurface {
    fn water_point(
        &self,
        scene: &Scene,
        x: f32,
        y: f32,
        width: u32,
        height: u32,
    ) -> Option<WaterPoint> {
        // No area lights: the fit asks what a light on a plane would show, not what the
        // scene's own lights do.
        match camera_hit(scene, &[], x, y, width, height) {
            CameraHit::Water(water) => Some(water),
            CameraHit::Light(_) | CameraHit::Other => None,
        }
    }

    fn water_points(
        &self,
        scene: &Scene,
        positions: &[Vec2],
        width: u32,
        height: u32,
        points: &mut [Option<WaterPoint>],
    ) {
        camera_water_points(scene, positions, width, height, points);
    }

    #[inline]
    fn reflect(&self, point: &WaterPoint, model: &ReflectionModel, u: Vec2) -> Option<LobeSample> {
        point.reflect(model, u)
    }

    #[inline]
    fn reflect_direction(
        &self,
        point: &WaterPoint,
        model: &ReflectionModel,
        u: Vec2,
    ) -> Option<Vec3> {
        point.reflect_direction(model, u)
    }

    fn lobe_draws(&self, model: &ReflectionModel, pairs: &[Vec2]) -> LobeDraws {
        LobeDraws::microfacet(model, pairs)
    }

    #[inline]
    fn reflect_drawn(
        &self,
        point: &WaterPoint,
        model: &ReflectionModel,
        draws: &LobeDraws,
        i: usize,
    ) -> Option<LobeSample> {
        match draws.half(i, model.gloss) {
            Some(draw) => point.reflect_drawn(model, draw),
            None => point.reflect(model, draws.pair(i)),
        }
    }
}
