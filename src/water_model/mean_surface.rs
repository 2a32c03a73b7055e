//! The mean water surface and the slope statistics of the scene's water, as the photo's
//! camera sees it (method §10): where the statistical water model puts the water, and the
//! start of its slope estimate.
//!
//! Water at rest is level, so the mean surface is a plane: the area-weighted plane of the
//! water triangles the image frames (their summed area vectors give its normal, their
//! centroid a point of it). A flat quad gives itself; a wave mesh gives its mean level, its
//! waves averaged out at the scale of the whole view. Not the plane of what the camera's rays
//! hit, which a grazing camera biases (see `area_weighted_plane`). The slopes are those of
//! the shading normals the camera sees (one camera ray through the centre of each cell of a
//! grid over the image, the rays whose first hit is the water), relative to that plane, along
//! two axes of it: the
//! camera's viewing direction projected onto the plane ("along") and the horizontal
//! direction across it. Counting by image cells weighs the water as the photo does (near
//! water, which fills most of the image, counts most).

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use crate::render::{camera_hit, CameraHit};
use crate::scene_in::Scene;

/// A plane of the scene frame with a tangent frame on it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeanSurface {
    /// A point of the plane.
    pub point: Vec3,
    /// Its unit normal, on the camera's side.
    pub normal: Vec3,
    /// The unit tangent "along": the camera's viewing direction projected onto the plane.
    pub along: Vec3,
    /// How far the scene's water rises above the plane at most (0 for a flat quad): the
    /// statistical model's reflected rays leave from this high, so that they clear the
    /// scene's own crests, which the model replaces by its masking term.
    pub crest: f32,
}

impl MeanSurface {
    /// The unit tangent "across": `normal x along`.
    pub fn across(&self) -> Vec3 {
        self.normal.cross(self.along)
    }

    /// A plane through `point` with unit `normal` (turned to the camera at the scene
    /// frame's origin), its "along" axis taken from the camera's `forward` (or, when the
    /// camera looks straight down on it, from its `up`).
    pub fn new(point: Vec3, normal: Vec3, forward: Vec3, up: Vec3) -> Self {
        let mut normal = normal.normalize_or_zero();
        if normal.dot(-point) < 0.0 {
            normal = -normal;
        }
        let project = |d: Vec3| (d - normal * normal.dot(d)).normalize_or_zero();
        let mut along = project(forward);
        if along.length_squared() < 0.5 || forward.dot(normal).abs() > 0.999 {
            along = project(up);
        }
        MeanSurface {
            point,
            normal,
            along,
            crest: 0.0,
        }
    }

    /// Where the ray `origin + t dir` (t > 0) meets the plane, and its `t`.
    pub fn hit(&self, origin: Vec3, dir: Vec3) -> Option<(Vec3, f32)> {
        let denom = dir.dot(self.normal);
        if denom.abs() < 1e-12 {
            return None;
        }
        let t = (self.point - origin).dot(self.normal) / denom;
        (t > 0.0 && t.is_finite()).then(|| (origin + dir * t, t))
    }

    /// The slopes of a surface of unit normal `n` relative to this plane, along and across
    /// (rise over run: a normal tilted towards +along has a negative slope along).
    pub fn slopes(&self, n: Vec3) -> [f32; 2] {
        let c = n.dot(self.normal);
        if c <= 1e-6 {
            return [0.0, 0.0];
        }
        [-n.dot(self.along) / c, -n.dot(self.across()) / c]
    }
}

/// What the camera sees of the scene's water: its mean surface and the variances of its
/// slopes relative to it, along and across ([`MeanSurface`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WaterStatistics {
    /// The mean surface.
    pub surface: MeanSurface,
    /// Variances of the slopes along and across the mean surface (dimensionless).
    pub slope_variance: [f32; 2],
    /// Camera rays that met the water (of a grid of `GRID` x `GRID`).
    pub rays: usize,
}

/// Cells per side of the image grid the statistics are taken over.
pub const GRID: u32 = 256;

/// The statistics of the water the camera sees, over a `GRID` x `GRID` grid of camera rays
/// of a `width` x `height` image (see the module doc); `None` when no ray meets the water.
pub fn water_statistics(scene: &Scene, width: u32, height: u32) -> Option<WaterStatistics> {
    let (points, normals) = seen_water(scene, width, height, GRID);
    if points.is_empty() {
        return None;
    }
    let count = points.len() as f64;
    // The seen normals' mean: up for the water (a flat quad's exact normal), which orients
    // the triangles' area vectors below.
    let seen = (normals.iter().sum::<DVec3>() / count).normalize_or_zero();
    if seen == DVec3::ZERO {
        return None;
    }
    let (normal, centroid) = area_weighted_plane(scene, width, height, seen)
        // No triangle centred in view (a few large quads): the seen points.
        .unwrap_or((seen, points.iter().sum::<DVec3>() / count));
    // The plane through the centroid is the one of mean height along `normal`.
    let mut surface = MeanSurface::new(
        centroid.as_vec3(),
        normal.as_vec3(),
        scene.camera.forward,
        scene.camera.up,
    );
    surface.crest = scene
        .triangles
        .par_iter()
        .zip(&scene.is_water)
        .filter(|(_, &w)| w)
        .flat_map_iter(|(t, _)| t.iter())
        .map(|&p| (p - surface.point).dot(surface.normal))
        .reduce(|| 0.0f32, f32::max);
    Some(WaterStatistics {
        surface,
        slope_variance: slope_variances(&surface, &normals),
        rays: points.len(),
    })
}

/// Whether the water the camera sees clearly holds waves: the slope variance of the shading
/// normals over a `GRID / 2` grid of camera rays, about the mean of those normals, above
/// [`CLEARLY_OVER`] times `threshold` along or across. A quarter of
/// [`water_statistics`]'s rays and none of its sums over the triangles (30 ms of a 0.8 s
/// fit of Table 1, where the test before the exact fit needs only to know that the mesh is
/// not flat); `false` leaves the question to [`water_statistics`].
pub fn clearly_wavy(scene: &Scene, width: u32, height: u32, threshold: [f32; 2]) -> bool {
    let (points, normals) = seen_water(scene, width, height, GRID / 2);
    let seen = normals.iter().sum::<DVec3>().normalize_or_zero();
    if seen == DVec3::ZERO {
        return false;
    }
    let surface = MeanSurface::new(
        (points.iter().sum::<DVec3>() / points.len() as f64).as_vec3(),
        seen.as_vec3(),
        scene.camera.forward,
        scene.camera.up,
    );
    let variance = slope_variances(&surface, &normals);
    (0..2).any(|a| variance[a] > CLEARLY_OVER * threshold[a])
}

/// How far over a threshold [`clearly_wavy`]'s variances must lie: its grid holds a quarter
/// of the rays and its plane is the seen normals' mean, not the area-weighted one, so its
/// variances differ from [`water_statistics`]'s by the sampling of the waves and the
/// plane's tilt, a few percent on the samples' meshes, far under a factor of 3.
const CLEARLY_OVER: f32 = 3.0;

/// The first hits on the water of a `grid` x `grid` grid of camera rays through the cells'
/// centres of a `width` x `height` image: the points and the shading normals (turned to the
/// face's side), in the grid's order (the sums over them run in it).
fn seen_water(scene: &Scene, width: u32, height: u32, grid: u32) -> (Vec<DVec3>, Vec<DVec3>) {
    (0..grid * grid)
        .into_par_iter()
        .filter_map(|k| {
            let (i, j) = (k % grid, k / grid);
            let x = (i as f32 + 0.5) / grid as f32 * width as f32;
            let y = (j as f32 + 0.5) / grid as f32 * height as f32;
            let CameraHit::Water(w) = camera_hit(scene, &[], x, y, width, height) else {
                return None;
            };
            let n = if w.normal.dot(w.face) < 0.0 {
                -w.normal
            } else {
                w.normal
            };
            Some((w.start.as_dvec3(), n.as_dvec3()))
        })
        .unzip()
}

/// The variances of the slopes of `normals` relative to `surface`, along and across, about
/// their means.
fn slope_variances(surface: &MeanSurface, normals: &[DVec3]) -> [f32; 2] {
    let count = normals.len() as f64;
    let slopes: Vec<[f64; 2]> = normals
        .iter()
        .map(|n| surface.slopes(n.as_vec3()).map(|s| s as f64))
        .collect();
    let mean = [0, 1].map(|a| slopes.iter().map(|s| s[a]).sum::<f64>() / count);
    [0, 1].map(|a| (slopes.iter().map(|s| (s[a] - mean[a]).powi(2)).sum::<f64>() / count) as f32)
}

/// The plane of the water triangles whose centroids the camera's image frames, area-weighted:
/// the normal of their summed area vectors (each turned to `up`'s side) and their centroid.
/// Not the plane of what the camera's rays hit: a grazing camera sees the wave faces turned
/// towards it and the crests, so the seen points' mean normal leans towards the camera (by
/// 0.8 degrees over the harbour sample's waves, which turns every reflection by twice that)
/// and their mean height sits above the water's. `None` when no triangle is centred in view.
fn area_weighted_plane(
    scene: &Scene,
    width: u32,
    height: u32,
    up: DVec3,
) -> Option<(DVec3, DVec3)> {
    let (w, h) = (width as f32, height as f32);
    // The triangles centred in view, found in parallel; summed below in their order.
    let framed: Vec<u32> = (0..scene.triangles.len() as u32)
        .into_par_iter()
        .filter(|&i| {
            let t = &scene.triangles[i as usize];
            scene.is_water[i as usize]
                && scene
                    .camera
                    .project((t[0] + t[1] + t[2]) / 3.0, width, height)
                    .is_some_and(|(x, y)| (0.0..w).contains(&x) && (0.0..h).contains(&y))
        })
        .collect();
    let mut area_vector = DVec3::ZERO;
    let mut moment = DVec3::ZERO;
    let mut area = 0.0f64;
    for &i in &framed {
        let [a, b, d] = scene.triangles[i as usize].map(|p| p.as_dvec3());
        let mut v = 0.5 * (b - a).cross(d - a);
        // Every triangle's area vector up, whatever its winding (not towards the camera: a
        // wave face turned away from a grazing camera would be flipped).
        if v.dot(up) < 0.0 {
            v = -v;
        }
        let da = v.length();
        area_vector += v;
        moment += da * (a + b + d) / 3.0;
        area += da;
    }
    let normal = area_vector.normalize_or_zero();
    (area > 0.0 && normal != DVec3::ZERO).then(|| (normal, moment / area))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slopes_are_rise_over_run_in_the_plane_frame() {
        let s = MeanSurface::new(
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::Y,
            Vec3::new(0.0, -0.2, -1.0).normalize(),
            Vec3::Y,
        );
        assert!((s.along - Vec3::NEG_Z).length() < 1e-6);
        assert!(
            (s.across() - Vec3::new(-1.0, 0.0, 0.0)).length() < 1e-6,
            "{:?}",
            s.across()
        );
        // The surface y = 0.1 * (-z) rises away from the camera: its normal is
        // (0, 1, 0.1) normalised, and its slope along -z is +0.1.
        let n = Vec3::new(0.0, 1.0, 0.1).normalize();
        let [a, c] = s.slopes(n);
        assert!((a - 0.1).abs() < 1e-6 && c.abs() < 1e-6, "{a} {c}");
        // A normal below the camera's side is turned up by `new`.
        let down = MeanSurface::new(Vec3::new(0.0, -1.0, 0.0), Vec3::NEG_Y, Vec3::NEG_Z, Vec3::Y);
        assert_eq!(down.normal, Vec3::Y);
    }

    #[test]
    fn a_camera_looking_straight_down_takes_along_from_its_up() {
        let s = MeanSurface::new(Vec3::new(0.0, -2.0, 0.0), Vec3::Y, Vec3::NEG_Y, Vec3::NEG_Z);
        assert!((s.along - Vec3::NEG_Z).length() < 1e-6);
    }

    #[test]
    fn hits_in_front_only() {
        let s = MeanSurface::new(Vec3::new(0.0, -1.0, 0.0), Vec3::Y, Vec3::NEG_Z, Vec3::Y);
        let (p, t) = s.hit(Vec3::ZERO, Vec3::new(0.0, -1.0, -1.0)).unwrap();
        assert!((p - Vec3::new(0.0, -1.0, -1.0)).length() < 1e-6 && (t - 1.0).abs() < 1e-6);
        assert!(s.hit(Vec3::ZERO, Vec3::new(0.0, 1.0, -1.0)).is_none());
        assert!(s.hit(Vec3::ZERO, Vec3::NEG_Z).is_none());
    }
}
