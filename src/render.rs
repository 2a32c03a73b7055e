//! Rendering the water under a scene's area lights: the forward model the fit inverts, used
//! to make sample photos and to check a fit by re-rendering it.
//!
//! Per pixel, jittered camera rays integrate over the pixel's footprint (METHOD §2). A camera
//! ray that hits a light sees its radiance; one that hits the water samples the reflection
//! lobe once and sees what the reflected ray's closest hit is; everything else is black
//! (night). Each pixel draws its random numbers from its own stream, so the image does not
//! depend on how many threads render it.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use crate::optics::{ReflectionModel, Shadowing};
use crate::random::Rng;
use crate::scene_in::Scene;
use crate::{Error, Result};

/// How to render.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Camera rays per pixel.
    pub samples_per_pixel: u32,
    /// Multiplies radiance before it is stored (the photo's exposure).
    pub exposure: f32,
    /// Seed of every random number.
    pub seed: u64,
    /// Shadowing term of the reflection model.
    pub shadowing: Shadowing,
    /// Show a progress bar on stderr (only drawn when stderr is a terminal).
    pub progress: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 600,
            height: 600,
            samples_per_pixel: 64,
            exposure: 1.0,
            seed: 1,
            shadowing: Shadowing::None,
            progress: false,
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

/// Traces a ray against the scene's triangles and area lights.
pub fn trace(scene: &Scene, origin: Vec3, dir: Vec3, tmin: f32) -> SceneHit {
    let mut nearest_light: Option<(usize, f32)> = None;
    for (i, light) in scene.area_lights.iter().enumerate() {
        let limit = nearest_light.map_or(f32::INFINITY, |(_, t)| t);
        if let Some(t) = light.intersect(origin, dir, tmin, limit) {
            nearest_light = Some((i, t));
        }
    }
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

/// Renders the scene's water and lights as the camera sees them.
pub fn render(scene: &Scene, options: &RenderOptions) -> Result<Rendered> {
    let (w, h) = (options.width, options.height);
    if w == 0 || h == 0 || w > 32768 || h > 32768 {
        return Err(Error::Usage(format!(
            "the image size {w} x {h} is out of range (1 to 32768 on each side)"
        )));
    }
    if options.samples_per_pixel == 0 {
        return Err(Error::Usage("--spp must be at least 1".into()));
    }
    if !(options.exposure.is_finite() && options.exposure > 0.0) {
        return Err(Error::Usage(format!(
            "--exposure must be a positive number, not {}",
            options.exposure
        )));
    }
    let model = ReflectionModel {
        gloss: scene.water.gloss,
        ior: scene.water.ior,
        shadowing: options.shadowing,
    };
    let start = Instant::now();
    let reflected = AtomicU64::new(0);
    let bar = progress_bar(options.progress, h as u64);
    let mut pixels = vec![[0f32; 3]; w as usize * h as usize];
    pixels
        .par_chunks_mut(w as usize)
        .enumerate()
        .for_each(|(y, row)| {
            let mut row_reflected = 0u64;
            for (x, out) in row.iter_mut().enumerate() {
                let index = y as u64 * w as u64 + x as u64;
                let mut rng = Rng::new(options.seed, index);
                let mut sum = [0f64; 3];
                for _ in 0..options.samples_per_pixel {
                    let (value, reflected_ray) =
                        pixel_sample(scene, &model, x as u32, y as u32, w, h, &mut rng);
                    row_reflected += reflected_ray as u64;
                    for c in 0..3 {
                        sum[c] += value[c] as f64;
                    }
                }
                let scale = options.exposure as f64 / options.samples_per_pixel as f64;
                *out = sum.map(|s| (s * scale) as f32);
            }
            reflected.fetch_add(row_reflected, Ordering::Relaxed);
            bar.inc(1);
        });
    bar.finish_and_clear();
    Ok(Rendered {
        width: w,
        height: h,
        pixels,
        camera_rays: w as u64 * h as u64 * options.samples_per_pixel as u64,
        reflected_rays: reflected.into_inner(),
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// One camera sample of pixel (x, y): the radiance it carries and whether a reflected ray
/// was traced.
fn pixel_sample(
    scene: &Scene,
    model: &ReflectionModel,
    x: u32,
    y: u32,
    w: u32,
    h: u32,
    rng: &mut Rng,
) -> ([f32; 3], bool) {
    let jx = x as f32 + rng.next_f32();
    let jy = y as f32 + rng.next_f32();
    let u = Vec2::new(rng.next_f32(), rng.next_f32());
    let origin = scene.camera.position;
    let dir = scene.camera.direction(jx, jy, w, h);
    let hit = match trace(scene, origin, dir, 0.0) {
        SceneHit::Light(i) => return (scene.area_lights[i].radiance, false),
        SceneHit::Miss => return ([0.0; 3], false),
        SceneHit::Surface(hit) => hit,
    };
    if !scene.is_water[hit.triangle as usize] {
        return ([0.0; 3], false);
    }
    let p = origin + dir * hit.t;
    let wo = -dir;
    let n = scene.shading_normal(hit.triangle, hit.barycentric);
    let Some(sample) = model.sample(n, wo, u) else {
        return ([0.0; 3], false);
    };
    let mut face = scene.face_normal(hit.triangle);
    if face.dot(wo) < 0.0 {
        face = -face;
    }
    // A reflected ray that would enter the water geometrically sees nothing.
    if face.dot(sample.wi) <= 0.0 {
        return ([0.0; 3], false);
    }
    let start = p + face * surface_offset(p);
    match trace(scene, start, sample.wi, 0.0) {
        SceneHit::Light(i) => {
            let l = scene.area_lights[i].radiance;
            (l.map(|c| c * sample.weight), true)
        }
        _ => ([0.0; 3], true),
    }
}

fn progress_bar(enabled: bool, rows: u64) -> indicatif::ProgressBar {
    use std::io::IsTerminal;
    if !enabled || !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(rows);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "rendering {bar:40} {pos}/{len} rows, {elapsed} elapsed, ~{eta} left",
    ) {
        bar.set_style(style);
    }
    bar
}
