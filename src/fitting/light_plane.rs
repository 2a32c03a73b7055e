//! method §5 step 7 (paper §4.2 step 3): the plane a light hangs on, found by casting the lobe's
//! rays at the streak's brightest pixel and taking the face most of them hit first.

use glam::{Vec2, Vec3};

use crate::optics::ReflectionModel;
use crate::plane::Plane;
use crate::random::Rng;
use crate::render::{trace, SceneHit, WaterPoint};
use crate::scene_in::Scene;
use crate::water_model::WaterModel;

/// The plane of one face of the scene (coplanar triangles of one glTF primitive), with the
/// frame a light's rectangle is expressed in.
#[derive(Clone, Debug, PartialEq)]
pub struct LightPlane {
    /// Node of the face's triangles.
    pub node: usize,
    /// Mesh of the face's triangles.
    pub mesh: usize,
    /// Primitive (within the mesh) of the face's triangles.
    pub primitive: usize,
    /// Origin of the rectangle coordinates: the mean landing point of the rays that found the
    /// plane (scene frame, camera-centred).
    pub point: Vec3,
    /// Unit normal, on the side the reflected rays come from (facing the water).
    pub normal: Vec3,
    /// Unit horizontal axis: perpendicular to world up and to `normal`, so that `u`, `v`,
    /// `normal` is right-handed (on a wall facing the camera, `u` points to the camera's
    /// right). For a horizontal plane, the camera's right projected onto it.
    pub u: Vec3,
    /// `normal x u`: upwards on a wall.
    pub v: Vec3,
    /// Fraction of the brightest pixel's lobe rays whose first hit was this face.
    pub hit_fraction: f32,
}

impl LightPlane {
    /// A plane through `point` with normal `normal` (made unit), its frame built from world
    /// up (+Y) and, for horizontal planes, `fallback_right`. `None` for a zero normal.
    pub fn with_frame(
        source: (usize, usize, usize),
        point: Vec3,
        normal: Vec3,
        fallback_right: Vec3,
        hit_fraction: f32,
    ) -> Option<Self> {
        let normal = normal.try_normalize()?;
        let u = Vec3::Y
            .cross(normal)
            .try_normalize()
            .filter(|_| Vec3::Y.cross(normal).length() > 1e-3)
            .or_else(|| (fallback_right - normal * normal.dot(fallback_right)).try_normalize())
            .or_else(|| normal.any_orthonormal_vector().try_normalize())?;
        let v = normal.cross(u);
        Some(LightPlane {
            node: source.0,
            mesh: source.1,
            primitive: source.2,
            point,
            normal,
            u,
            v,
            hit_fraction,
        })
    }

    /// Plane coordinates (u, v) of a point of the scene frame.
    pub fn coords(&self, p: Vec3) -> Vec2 {
        let d = p - self.point;
        Vec2::new(d.dot(self.u), d.dot(self.v))
    }

    /// The plane as a [`Plane`]: its point and front normal.
    pub fn plane(&self) -> Plane {
        Plane {
            point: self.point,
            normal: self.normal,
        }
    }

    /// How far along `dir` from `origin` the ray meets this plane's front side (the side the
    /// reflected rays come from), in units of `dir`'s length, when it does ahead of `origin`.
    #[inline]
    pub fn distance(&self, origin: Vec3, dir: Vec3) -> Option<f32> {
        self.plane()
            .front_distance(origin, dir)
            .filter(|&t| t > 0.0)
    }

    /// Where the ray from `origin` along `dir` meets this plane's front side, when it does
    /// ahead of `origin`: the distance ([`distance`](Self::distance)) and the plane
    /// coordinates (u, v) of the point.
    #[inline]
    pub fn hit(&self, origin: Vec3, dir: Vec3) -> Option<(f32, Vec2)> {
        let t = self.distance(origin, dir)?;
        Some((t, self.coords(origin + dir * t)))
    }

    /// The scene-frame point at plane coordinates (u, v).
    pub fn point_at(&self, u: f32, v: f32) -> Vec3 {
        self.point + self.u * u + self.v * v
    }

    /// True when `triangle` is part of this face: same primitive, parallel, and within a
    /// rounding tolerance of the plane.
    pub fn contains_triangle(&self, scene: &Scene, triangle: u32) -> bool {
        let s = scene.sources[triangle as usize];
        if (s.node as usize, s.mesh as usize, s.primitive as usize)
            != (self.node, self.mesh, self.primitive)
        {
            return false;
        }
        coplanar(
            scene.triangles[triangle as usize],
            scene.face_normal(triangle),
            self.point,
            self.normal,
        )
    }

    /// True when two planes are the same face (for merging fragments).
    pub fn same_face(&self, other: &LightPlane) -> bool {
        (self.node, self.mesh, self.primitive) == (other.node, other.mesh, other.primitive)
            && self.same_plane(other)
    }

    /// True when two planes are one plane, whatever faces they came from: parallel, and
    /// each point within `plane_tolerance` of the other plane.
    pub fn same_plane(&self, other: &LightPlane) -> bool {
        self.normal.dot(other.normal) > 1.0 - COPLANAR_COS
            && (other.point - self.point).dot(self.normal).abs()
                <= plane_tolerance(self.point, other.point)
    }

    /// The distance from the camera to the plane's origin (the scene frame is centred on the
    /// camera): the length every tolerance of the fit on this plane is a share of, so that a
    /// scene scaled as a whole is fitted as it is unscaled.
    pub fn camera_distance(&self) -> f32 {
        self.point.length()
    }
}

/// 1 - cos of the largest angle between coplanar triangles' normals (about 1.4 degrees: a
/// tessellated flat wall exported in f32 stays far inside it, a bent one does not).
const COPLANAR_COS: f32 = 3e-4;

/// Distance within which points `a` and `b` (scene frame, centred on the camera) lie on one
/// plane: a share of their distance from the camera, far above f32 rounding there (a 1e-4
/// share is about 1700 units in the last place) and far below any real step between two
/// walls.
fn plane_tolerance(a: Vec3, b: Vec3) -> f32 {
    1e-4 * a.abs().max_element().max(b.abs().max_element())
}

fn coplanar(tri: [Vec3; 3], tri_normal: Vec3, point: Vec3, normal: Vec3) -> bool {
    tri_normal.dot(normal).abs() > 1.0 - COPLANAR_COS
        && tri
            .iter()
            .all(|&c| (c - point).dot(normal).abs() <= plane_tolerance(c, point))
}

/// A face found by the lobe's rays, while counting.
struct FaceHits {
    source: (usize, usize, usize),
    triangle_normal: Vec3,
    anchor: Vec3,
    count: u32,
    point_sum: glam::DVec3,
}

/// Stream tag of the plane search's random numbers (see [`crate::random::Rng::new`]).
const PLANE_STREAM: u64 = 1 << 48;

/// The result of casting the brightest pixel's lobe.
pub enum PlaneSearch {
    /// The face hit most often.
    Found(LightPlane),
    /// No ray hit anything but the water (or nothing at all).
    Nothing {
        /// Rays that left the water.
        rays: u32,
        /// Of those, rays whose first hit was the water itself.
        water_hits: u32,
    },
}

/// Casts `samples` lobe rays of pixel `pixel` (jittered over its footprint, exactly as the
/// renderer samples it, the water as `water_model` has it) and returns the face most of them
/// hit first. Every triangle, the water included, takes part in the depth test.
#[allow(clippy::too_many_arguments)]
pub fn find_plane(
    water_model: &dyn WaterModel,
    scene: &Scene,
    model: &ReflectionModel,
    pixel: u32,
    width: u32,
    height: u32,
    samples: u32,
    seed: u64,
) -> PlaneSearch {
    let mut rng = Rng::new(seed, PLANE_STREAM | pixel as u64);
    let (x, y) = (pixel % width, pixel / width);
    let mut faces: Vec<FaceHits> = Vec::new();
    let (mut rays, mut water_hits) = (0u32, 0u32);
    for _ in 0..samples {
        let Some((water, sample)) =
            reflected_sample(water_model, scene, model, x, y, width, height, &mut rng)
        else {
            continue;
        };
        let (start, wi) = (water.start, sample.wi);
        rays += 1;
        let SceneHit::Surface(hit) = trace(scene, &[], start, wi, water.tmin(wi)) else {
            continue;
        };
        if scene.is_water[hit.triangle as usize] {
            water_hits += 1;
            continue;
        }
        let s = scene.sources[hit.triangle as usize];
        let source = (s.node as usize, s.mesh as usize, s.primitive as usize);
        let tri = scene.triangles[hit.triangle as usize];
        let n = scene.face_normal(hit.triangle);
        let p = start + wi * hit.t;
        let existing = faces
            .iter_mut()
            .find(|f| f.source == source && coplanar(tri, n, f.anchor, f.triangle_normal));
        match existing {
            Some(f) => {
                f.count += 1;
                f.point_sum += p.as_dvec3();
            }
            None => faces.push(FaceHits {
                source,
                triangle_normal: n,
                anchor: tri[0],
                count: 1,
                point_sum: p.as_dvec3(),
            }),
        }
    }
    // Ties go to the face found first, which is deterministic.
    let best = faces
        .iter()
        .enumerate()
        .max_by_key(|(i, f)| (f.count, std::cmp::Reverse(*i)))
        .map(|(_, f)| f);
    let Some(best) = best else {
        return PlaneSearch::Nothing { rays, water_hits };
    };
    let mean = (best.point_sum / best.count as f64).as_vec3();
    let mut normal = best.triangle_normal;
    // Facing the water: towards where the rays came from.
    if normal.dot(scene.camera.position - mean) < 0.0 {
        normal = -normal;
    }
    // Project the mean onto the face's plane so coordinates are exactly in-plane.
    let point = mean - normal * (mean - best.anchor).dot(normal);
    match LightPlane::with_frame(
        best.source,
        point,
        normal,
        scene.camera.right,
        best.count as f32 / samples.max(1) as f32,
    ) {
        Some(plane) => PlaneSearch::Found(plane),
        None => PlaneSearch::Nothing { rays, water_hits },
    }
}

/// One camera sample of pixel (x, y) reflected off the water, with the renderer's model
/// ([`crate::render`] under [`crate::water_model::ExactSurface`]: a jittered camera ray, the
/// same shading and face normals, the same offset; the renderer additionally stratifies its
/// camera rays and shares each among several lobe samples, which changes the noise but not
/// the expectation): the reflected ray's origin together with the lobe sample, or `None` when
/// the sample reflects nothing (the jittered ray misses the water, or the lobe sample is below
/// the surface). The water point says where the reflected ray starts and what it ignores
/// ([`WaterPoint::tmin`]). Draws four numbers from `rng` whatever happens: the jitter, then
/// the lobe's.
#[allow(clippy::too_many_arguments)]
pub fn reflected_sample(
    water_model: &dyn WaterModel,
    scene: &Scene,
    model: &ReflectionModel,
    x: u32,
    y: u32,
    width: u32,
    height: u32,
    rng: &mut Rng,
) -> Option<(WaterPoint, crate::optics::LobeSample)> {
    let (jx, jy) = jittered(x, y, rng);
    let u = Vec2::new(rng.next_f32(), rng.next_f32());
    let water = water_model.water_point(scene, jx, jy, width, height)?;
    let sample = water_model.reflect(&water, model, u)?;
    Some((water, sample))
}

/// A uniform point of pixel (`x`, `y`), in pixel units: the first two numbers a
/// [`reflected_sample`] draws.
pub(crate) fn jittered(x: u32, y: u32, rng: &mut Rng) -> (f32, f32) {
    let jx = x as f32 + rng.next_f32();
    let jy = y as f32 + rng.next_f32();
    (jx, jy)
}
