//! Rendering the water under a scene's area lights: the forward model the fit inverts, used
//! to make sample photos and to check a fit by re-rendering it.
//!
//! Per pixel, jittered camera rays integrate over the pixel's footprint (method §2). A camera
//! ray that hits a light sees its radiance; one that hits the water samples the reflection
//! lobe a few times and each reflected ray sees the light it reaches unoccluded, if any;
//! everything else is black (night), or with an [`Environment`] the dim sky and the walls
//! it lights. Each pixel draws its random numbers from its own stream, so the image does not
//! depend on how many threads render it.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use crate::environment::Environment;
use crate::optics::{ReflectionModel, Shadowing};
use crate::progress::Reporter;
use crate::random::Rng;
use crate::scene_in::{AreaLight, Scene};
use crate::settings::Setting;
use crate::tracing::Hit;
use crate::water_model::WaterModel;
use crate::{Error, Result};

mod packets;

pub use packets::{camera_water_points, reflected_hits_of};

/// How to render.
#[derive(Clone, Debug)]
pub struct RenderOptions<'a> {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel: lobe samples on the water, split over jittered camera rays
    /// (see [`camera_rays_per_pixel`]).
    pub samples_per_pixel: u32,
    /// Multiplies radiance before it is stored (the photo's exposure).
    pub exposure: f32,
    /// Seed of every random number.
    pub seed: u64,
    /// Shadowing term of the reflection model.
    pub shadowing: Shadowing,
    /// Told the rows done as they finish (silent by default).
    pub progress: Reporter<'a>,
    /// How the water reflects: `None` for the scene's own water mesh (the photo's waves);
    /// a statistical model renders its expected image instead (the mean over the waves it
    /// describes), as the fit under that model sees the photo.
    pub water: Option<&'a dyn WaterModel>,
    /// What rays that reach no light see: `None` for a black night.
    pub environment: Option<Environment>,
}

impl Default for RenderOptions<'_> {
    fn default() -> Self {
        RenderOptions {
            width: 600,
            height: 600,
            samples_per_pixel: 64,
            exposure: 1.0,
            seed: 1,
            shadowing: Shadowing::None,
            progress: Reporter::default(),
            water: None,
            environment: None,
        }
    }
}

/// A rendered image and what it cost.
#[derive(Clone, Debug)]
pub struct Rendered {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear RGB per pixel, radiance times exposure, row 0 at the top.
    pub pixels: Vec<[f32; 3]>,
    /// Camera rays traced.
    pub camera_rays: u64,
    /// Reflected rays traced from the water.
    pub reflected_rays: u64,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// What a ray sees first.
pub enum SceneHit {
    /// The emitting face of area light `index`.
    Light(usize),
    /// A triangle of the scene.
    Surface(crate::tracing::Hit),
    /// Nothing.
    Miss,
}

/// How much nearer geometry must be than a light to hide it. Lights usually sit on a wall,
/// coplanar with it; without a margin the wall would hide them by rounding.
const LIGHT_TIE_MARGIN: f32 = 1e-4;

/// The nearest light whose emitting face the ray hits, and the distance to it.
fn nearest_light(lights: &[AreaLight], origin: Vec3, dir: Vec3, tmin: f32) -> Option<(usize, f32)> {
    let mut nearest: Option<(usize, f32)> = None;
    for (i, light) in lights.iter().enumerate() {
        let limit = nearest.map_or(f32::INFINITY, |(_, t)| t);
        if let Some(t) = light.intersect(origin, dir, tmin, limit) {
            nearest = Some((i, t));
        }
    }
    nearest
}

/// The light a ray sees, if any: the nearest light it hits, unless geometry is nearer. Only
/// an occlusion query is needed, and none at all for a ray that misses every light, which
/// is most reflected rays.
pub fn visible_light(
    scene: &Scene,
    lights: &[AreaLight],
    origin: Vec3,
    dir: Vec3,
    tmin: f32,
) -> Option<usize> {
    let (i, t) = nearest_light(lights, origin, dir, tmin)?;
    (!scene
        .tracer
        .occluded(origin, dir, tmin, t * (1.0 - LIGHT_TIE_MARGIN)))
    .then_some(i)
}

/// Traces a ray against the scene's triangles and the area lights `lights`.
pub fn trace(scene: &Scene, lights: &[AreaLight], origin: Vec3, dir: Vec3, tmin: f32) -> SceneHit {
    let nearest_light = nearest_light(lights, origin, dir, tmin);
    let tmax = nearest_light.map_or(f32::INFINITY, |(_, t)| t * (1.0 - LIGHT_TIE_MARGIN));
    match scene.tracer.closest_hit(origin, dir, tmin, tmax) {
        Some(hit) => SceneHit::Surface(hit),
        None => match nearest_light {
            Some((i, _)) => SceneHit::Light(i),
            None => SceneHit::Miss,
        },
    }
}

/// Offset that lifts a reflected ray's origin off the surface, relative to the hit's
/// distance from the scene origin (f32 rounding grows with it).
pub fn surface_offset(p: Vec3) -> f32 {
    1e-5 * (1.0 + p.abs().max_element())
}

/// Where a camera ray meets the water, with what its reflected rays need.
#[derive(Clone, Copy, Debug, Default)]
pub struct WaterPoint {
    /// Origin of the reflected rays: the hit lifted off the surface on the camera's side.
    pub start: Vec3,
    /// Unit direction back towards the camera.
    pub wo: Vec3,
    /// Shading normal (the lobe's axis).
    pub normal: Vec3,
    /// Geometric normal, turned to the camera's side.
    pub face: Vec3,
    /// Height above `start`, along `face`, below which a reflected ray ignores what it hits
    /// (0 for the exact model): a statistical model's rays leave its mean plane, under the
    /// crests of the scene's own waves, which must not shadow them a second time.
    pub clear: f32,
}

/// The least cosine to the water's face [`WaterPoint::tmin`] divides by: a flatter ray starts
/// counting hits no farther than a thousand crest heights out.
const MIN_CLEAR_COSINE: f32 = 1e-3;

impl WaterPoint {
    /// The distance along a reflected ray in direction `wi` before which it ignores what it
    /// hits ([`clear`](Self::clear)): the ray is the one from `start`, only its occlusion
    /// starts above the crests.
    #[inline]
    pub fn tmin(&self, wi: Vec3) -> f32 {
        if self.clear > 0.0 {
            self.clear / wi.dot(self.face).max(MIN_CLEAR_COSINE)
        } else {
            0.0
        }
    }

    /// The first triangle a reflected ray in direction `wi` meets past [`tmin`](Self::tmin)
    /// and before `tmax`. Past the crests (`clear` > 0) no water triangle lies ahead, so the
    /// ray is traced against the others alone ([`Scene::closest_hit_above_water`]), unless it
    /// is so grazing that `tmin` is capped below the crests' height.
    #[inline]
    pub fn reflected_hit(&self, scene: &Scene, wi: Vec3, tmax: f32) -> Option<Hit> {
        let cos = wi.dot(self.face);
        if self.clear > 0.0 && cos >= MIN_CLEAR_COSINE {
            scene.closest_hit_above_water(self.start, wi, self.tmin(wi), tmax)
        } else {
            scene
                .tracer
                .closest_hit(self.start, wi, self.tmin(wi), tmax)
        }
    }

    /// [`reflected_hit`](Self::reflected_hit) of each direction of `wi` within its `tmax`,
    /// into `hits` (as long as both). The exact model's rays, which leave one point, are
    /// traced together ([`crate::tracing::Tracer::closest_hits`]).
    pub fn reflected_hits(
        &self,
        scene: &Scene,
        wi: &[Vec3],
        tmax: &[f32],
        hits: &mut [Option<Hit>],
    ) {
        if self.clear > 0.0 {
            for ((&wi, &tmax), hit) in wi.iter().zip(tmax).zip(hits) {
                *hit = self.reflected_hit(scene, wi, tmax);
            }
        } else {
            scene.tracer.closest_hits(self.start, wi, 0.0, tmax, hits);
        }
    }

    /// One reflected lobe sample for the uniform pair `u`; `None` when the model rejects it
    /// or the ray would enter the water geometrically (it then sees nothing, but still
    /// counts in the pixel's mean).
    pub fn reflect(&self, model: &ReflectionModel, u: Vec2) -> Option<crate::optics::LobeSample> {
        let sample = model.sample(self.normal, self.wo, u)?;
        (self.face.dot(sample.wi) > 0.0).then_some(sample)
    }

    /// [`reflect`](Self::reflect) from the half vector `draw` that `model` drew
    /// ([`ReflectionModel::draw`]): the same sample to the last bit.
    pub fn reflect_drawn(
        &self,
        model: &ReflectionModel,
        draw: &crate::optics::HalfDraw,
    ) -> Option<crate::optics::LobeSample> {
        let sample = model.sample_drawn(
            self.normal,
            crate::optics::orthonormal_basis(self.normal),
            self.wo,
            draw,
        )?;
        (self.face.dot(sample.wi) > 0.0).then_some(sample)
    }

    /// The direction of [`reflect`](Self::reflect)'s sample for `u`, without its weight.
    pub fn reflect_direction(&self, model: &ReflectionModel, u: Vec2) -> Option<Vec3> {
        let wi = model.direction(self.normal, self.wo, u)?;
        (self.face.dot(wi) > 0.0).then_some(wi)
    }
}

/// What a camera ray sees first.
#[derive(Clone, Copy, Debug)]
pub enum CameraHit {
    /// Area light `index`, directly.
    Light(usize),
    /// The water.
    Water(WaterPoint),
    /// Anything else, or nothing: black at night.
    Other,
}

/// Traces the camera ray through image position (`x`, `y`) (pixel units, fractional) of a
/// `width` x `height` image. The renderer and the fitter's footprints share it, so that the
/// fit models exactly the pixel the renderer makes.
pub fn camera_hit(
    scene: &Scene,
    lights: &[AreaLight],
    x: f32,
    y: f32,
    width: u32,
    height: u32,
) -> CameraHit {
    let origin = scene.camera.position;
    let dir = scene.camera.direction(x, y, width, height);
    let hit = match trace(scene, lights, origin, dir, 0.0) {
        SceneHit::Light(i) => return CameraHit::Light(i),
        SceneHit::Miss => return CameraHit::Other,
        SceneHit::Surface(hit) => hit,
    };
    match water_point_of(scene, dir, &hit) {
        Some(water) => CameraHit::Water(water),
        None => CameraHit::Other,
    }
}

/// The water point of the camera ray in direction `dir` whose first hit is `hit`, or `None`
/// when that is not the water.
fn water_point_of(scene: &Scene, dir: Vec3, hit: &Hit) -> Option<WaterPoint> {
    if !scene.is_water[hit.triangle as usize] {
        return None;
    }
    let p = scene.camera.position + dir * hit.t;
    let wo = -dir;
    let mut face = scene.face_normal(hit.triangle);
    if face.dot(wo) < 0.0 {
        face = -face;
    }
    Some(WaterPoint {
        start: p + face * surface_offset(p),
        wo,
        normal: scene.shading_normal(hit.triangle, hit.barycentric),
        face,
        clear: 0.0,
    })
}

/// Renders the scene's water and lights as the camera sees them.
pub fn render(scene: &Scene, options: &RenderOptions) -> Result<Rendered> {
    render_with_lights(scene, &scene.area_lights, options)
}

/// Renders the scene's water under `lights` instead of the scene's own (to check a fit).
pub fn render_with_lights(
    scene: &Scene,
    lights: &[AreaLight],
    options: &RenderOptions,
) -> Result<Rendered> {
    let (w, h) = (options.width, options.height);
    let model = checked_model(scene, options)?;
    let start = Instant::now();
    let reflected = AtomicU64::new(0);
    let rows_done = AtomicU64::new(0);
    options.progress.advance(0, h as u64);
    let mut pixels = vec![[0f32; 3]; w as usize * h as usize];
    pixels
        .par_chunks_mut(w as usize)
        .enumerate()
        .for_each(|(y, row)| {
            let mut row_reflected = 0u64;
            for (x, out) in row.iter_mut().enumerate() {
                let (value, traced) =
                    pixel_value(scene, lights, &model, options, x as u32, y as u32);
                *out = value;
                row_reflected += traced;
            }
            reflected.fetch_add(row_reflected, Ordering::Relaxed);
            let done = rows_done.fetch_add(1, Ordering::Relaxed) + 1;
            options.progress.advance(done, h as u64);
        });
    Ok(Rendered {
        width: w,
        height: h,
        pixels,
        camera_rays: w as u64 * h as u64 * camera_rays_per_pixel(options.samples_per_pixel) as u64,
        reflected_rays: reflected.into_inner(),
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// The pixels `pixels` (indices `y * width + x`) of [`render_with_lights`]'s image, each
/// the same value to the last bit, rendered alone under the water's reflection model
/// `model` (its gloss, index of refraction and shadowing, where the image's are the scene's
/// material's and `options.shadowing`): what a test of a few pixels needs.
pub fn render_pixels(
    scene: &Scene,
    lights: &[AreaLight],
    model: &ReflectionModel,
    options: &RenderOptions,
    pixels: &[u32],
) -> Result<Vec<[f32; 3]>> {
    checked_model(scene, options)?;
    let w = options.width;
    Ok(pixels
        .par_iter()
        .map(|&p| pixel_value(scene, lights, model, options, p % w, p / w).0)
        .collect())
}

/// The reflection model of `scene`'s water under `options`, once `options` are checked.
fn checked_model(scene: &Scene, options: &RenderOptions) -> Result<ReflectionModel> {
    let (w, h) = (options.width, options.height);
    if w == 0 || h == 0 || w > 32768 || h > 32768 {
        return Err(Error::Usage(format!(
            "the image size {w} x {h} is out of range (1 to 32768 on each side)"
        )));
    }
    if options.samples_per_pixel == 0 {
        return Err(Error::setting(Setting::RenderSamples, "must be at least 1"));
    }
    if !(options.exposure.is_finite() && options.exposure > 0.0) {
        return Err(Error::setting(
            Setting::Exposure,
            format!("must be a positive number, not {}", options.exposure),
        ));
    }
    Ok(ReflectionModel {
        gloss: scene.water.gloss,
        ior: scene.water.ior,
        shadowing: options.shadowing,
    })
}

/// Pixel (x, y)'s value (radiance times exposure) and the reflected rays it traced, from its
/// own random stream.
fn pixel_value(
    scene: &Scene,
    lights: &[AreaLight],
    model: &ReflectionModel,
    options: &RenderOptions,
    x: u32,
    y: u32,
) -> ([f32; 3], u64) {
    let (w, h) = (options.width, options.height);
    let environment = options.environment.filter(|e| !e.is_black());
    let camera_rays = camera_rays_per_pixel(options.samples_per_pixel);
    let lobe_samples = options.samples_per_pixel / camera_rays;
    let strata = (camera_rays as f32).sqrt() as u32;
    let mut rng = Rng::new(options.seed, y as u64 * w as u64 + x as u64);
    let (sum, traced) = match environment.as_ref() {
        // Under a black night the pixel's camera rays go in packets.
        None => packets::black_night_pixel(
            scene,
            lights,
            model,
            options.water,
            (x, y),
            (camera_rays, lobe_samples),
            (w, h),
            &mut rng,
        ),
        Some(environment) => {
            let (mut sum, mut traced) = ([0f64; 3], 0u64);
            for k in 0..camera_rays {
                let (value, n) = pixel_sample(
                    scene,
                    lights,
                    model,
                    options.water,
                    Some(environment),
                    PixelSample {
                        x,
                        y,
                        stratum: k,
                        strata,
                        lobe_samples,
                    },
                    w,
                    h,
                    &mut rng,
                );
                traced += n as u64;
                for c in 0..3 {
                    sum[c] += value[c] as f64;
                }
            }
            (sum, traced)
        }
    };
    let scale = options.exposure as f64 / camera_rays as f64;
    (sum.map(|s| (s * scale) as f32), traced)
}

/// Lobe samples traced from each camera ray's water hit. Tracing the camera ray is as costly
/// as tracing a reflected one, and the pixel's value varies far more over the reflection lobe
/// than over the pixel's footprint, so each camera ray is shared by a few lobe samples.
pub const LOBE_SAMPLES_PER_CAMERA_RAY: u32 = 4;

/// Camera rays per pixel for `samples_per_pixel` samples: the samples are split into camera
/// rays of [`LOBE_SAMPLES_PER_CAMERA_RAY`] lobe samples each (one lobe sample each when there
/// are too few samples to split).
pub fn camera_rays_per_pixel(samples_per_pixel: u32) -> u32 {
    if samples_per_pixel >= LOBE_SAMPLES_PER_CAMERA_RAY * 4 {
        samples_per_pixel / LOBE_SAMPLES_PER_CAMERA_RAY
    } else {
        samples_per_pixel
    }
}

/// Which camera ray of a pixel to trace.
struct PixelSample {
    x: u32,
    y: u32,
    /// Index of the camera ray within the pixel.
    stratum: u32,
    /// The pixel is split into strata x strata cells for the first strata^2 camera rays, so
    /// that the footprint is covered evenly (the rest are uniformly jittered).
    strata: u32,
    /// Lobe samples to average at the water hit.
    lobe_samples: u32,
}

/// One camera ray of a pixel: the mean radiance its lobe samples carry, and how many
/// reflected rays were traced.
#[allow(clippy::too_many_arguments)]
fn pixel_sample(
    scene: &Scene,
    lights: &[AreaLight],
    model: &ReflectionModel,
    water_model: Option<&dyn WaterModel>,
    environment: Option<&Environment>,
    s: PixelSample,
    w: u32,
    h: u32,
    rng: &mut Rng,
) -> ([f32; 3], u32) {
    let (x, y) = s.jittered(rng);
    let hit = camera_hit(scene, lights, x, y, w, h);
    shade(
        scene,
        lights,
        model,
        water_model,
        environment,
        (x, y, hit),
        s.lobe_samples,
        (w, h),
        rng,
    )
}

impl PixelSample {
    /// Where in the image its camera ray goes: the first two numbers it draws.
    fn jittered(&self, rng: &mut Rng) -> (f32, f32) {
        let (mut fx, mut fy) = (rng.next_f32(), rng.next_f32());
        if self.stratum < self.strata * self.strata {
            let n = self.strata as f32;
            fx = ((self.stratum % self.strata) as f32 + fx) / n;
            fy = ((self.stratum / self.strata) as f32 + fy) / n;
        }
        (self.x as f32 + fx, self.y as f32 + fy)
    }
}

/// The value of a camera ray through image position (`x`, `y`) that sees `hit` first, and
/// how many reflected rays it traced: the rest of [`pixel_sample`] after the camera ray.
#[allow(clippy::too_many_arguments)]
fn shade(
    scene: &Scene,
    lights: &[AreaLight],
    model: &ReflectionModel,
    water_model: Option<&dyn WaterModel>,
    environment: Option<&Environment>,
    (x, y, hit): (f32, f32, CameraHit),
    lobe_samples: u32,
    (w, h): (u32, u32),
    rng: &mut Rng,
) -> ([f32; 3], u32) {
    let water = match hit {
        CameraHit::Light(i) => return (lights[i].radiance, 0),
        CameraHit::Other => {
            let seen = environment.map_or([0.0; 3], |env| {
                let dir = scene.camera.direction(x, y, w, h);
                env.seen(scene, lights, scene.camera.position, dir, 0.0, rng)
            });
            return (seen, 0);
        }
        CameraHit::Water(water) => water,
    };
    // Under another water model the camera ray meets that model's surface (a statistical
    // model's mean plane) where the scene's mesh says it sees water.
    let water = match water_model {
        None => water,
        Some(m) => match m.water_point(scene, x, y, w, h) {
            Some(p) => p,
            None => return ([0.0; 3], 0),
        },
    };
    let mut sum = [0f32; 3];
    let mut traced = 0;
    for _ in 0..lobe_samples {
        let u = Vec2::new(rng.next_f32(), rng.next_f32());
        let sample = match water_model {
            None => water.reflect(model, u),
            Some(m) => m.reflect(&water, model, u),
        };
        let Some(sample) = sample else {
            continue;
        };
        traced += 1;
        let tmin = water.tmin(sample.wi);
        let seen = match visible_light(scene, lights, water.start, sample.wi, tmin) {
            Some(i) => lights[i].radiance,
            None => match environment {
                Some(env) => env.seen(scene, lights, water.start, sample.wi, tmin, rng),
                None => continue,
            },
        };
        for c in 0..3 {
            sum[c] += seen[c] * sample.weight;
        }
    }
    let inv = 1.0 / lobe_samples as f32;
    (sum.map(|c| c * inv), traced)
}
