//! A night that is not black: a dim sky and diffuse walls, for rendering photos whose
//! background the fit must tell from the lights (method §5, the background term).
//!
//! A ray that reaches no light sees the sky when it leaves the scene, and a wall (any surface
//! that is not water) shaded once: its albedo times the light arriving there from the sky and
//! from the area lights, each estimated with one sample. The water seen from a wall's bounce
//! counts as black: it reflects a few percent of what lands on it, a second-order term the
//! photo's noise hides.

use glam::{Vec2, Vec3};

use crate::random::Rng;
use crate::render::{trace, visible_light, SceneHit};
use crate::scene_in::{AreaLight, Scene};

/// The sky's radiance and the walls' albedo.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Environment {
    /// Linear radiance of the sky, the same in every direction, per channel.
    pub sky: [f32; 3],
    /// Diffuse albedo of every surface that is not water, 0 to 1.
    pub albedo: f32,
}

impl Environment {
    /// Whether the environment is black: no sky and black walls.
    pub fn is_black(&self) -> bool {
        self.sky.iter().all(|&s| s == 0.0) && self.albedo == 0.0
    }

    /// The radiance a ray from `origin` along unit `dir` sees when it reaches no light: the
    /// sky where it leaves the scene, a wall's diffuse glow where it meets one, black on the
    /// water.
    pub fn seen(
        &self,
        scene: &Scene,
        lights: &[AreaLight],
        origin: Vec3,
        dir: Vec3,
        tmin: f32,
        rng: &mut Rng,
    ) -> [f32; 3] {
        match trace(scene, &[], origin, dir, tmin) {
            SceneHit::Miss | SceneHit::Light(_) => self.sky,
            SceneHit::Surface(hit) => {
                if self.albedo == 0.0 || scene.is_water[hit.triangle as usize] {
                    return [0.0; 3];
                }
                let p = origin + dir * hit.t;
                let mut normal = scene.face_normal(hit.triangle);
                if normal.dot(dir) > 0.0 {
                    normal = -normal;
                }
                self.wall(scene, lights, p, normal, rng)
            }
        }
    }

    /// Radiance leaving a diffuse wall at `p` with unit normal `normal` (on the side the ray
    /// came from): albedo / pi times the irradiance from the sky (one cosine-weighted ray)
    /// and from every area light (one point sampled on each).
    fn wall(
        &self,
        scene: &Scene,
        lights: &[AreaLight],
        p: Vec3,
        normal: Vec3,
        rng: &mut Rng,
    ) -> [f32; 3] {
        let start = p + normal * crate::render::surface_offset(p);
        let mut out = [0f32; 3];
        // Sky: a cosine-weighted direction carries albedo x sky when it escapes (the pdf's
        // cos/pi cancels the BRDF's albedo/pi and the cosine).
        let u = Vec2::new(rng.next_f32(), rng.next_f32());
        let wi = cosine_direction(normal, u);
        if matches!(trace(scene, lights, start, wi, 0.0), SceneHit::Miss) {
            for (o, s) in out.iter_mut().zip(self.sky) {
                *o += self.albedo * s;
            }
        }
        // Lights: a uniform point on each; irradiance L cos cos' A / d^2.
        for (i, light) in lights.iter().enumerate() {
            let (a, b) = (rng.next_f32() * 2.0 - 1.0, rng.next_f32() * 2.0 - 1.0);
            let q = light.center + light.half_width * a + light.half_height * b;
            let to = q - start;
            let d2 = to.length_squared();
            if d2 <= 0.0 {
                continue;
            }
            let w = to / d2.sqrt();
            let (cos_wall, cos_light) = (normal.dot(w), -light.normal.dot(w));
            if cos_wall <= 0.0 || cos_light <= 0.0 {
                continue;
            }
            if visible_light(scene, lights, start, w, 0.0) != Some(i) {
                continue;
            }
            let area = 4.0 * light.half_width.length() * light.half_height.length();
            let g = self.albedo / std::f32::consts::PI * cos_wall * cos_light * area / d2;
            for (o, l) in out.iter_mut().zip(light.radiance) {
                *o += g * l;
            }
        }
        out
    }
}

/// A cosine-weighted direction about unit `n` for the uniform pair `u`.
fn cosine_direction(n: Vec3, u: Vec2) -> Vec3 {
    let r = u.x.sqrt();
    let phi = std::f32::consts::TAU * u.y;
    let (t, b) = n.any_orthonormal_pair();
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u.x).max(0.0).sqrt()).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cosine-weighted directions' mean cosine is 2/3 (the integral of cos^2 over the
    /// hemisphere against cos/pi), and none points below the surface.
    #[test]
    fn cosine_directions_have_the_cosine_law() {
        let n = Vec3::new(0.3, 0.9, -0.2).normalize();
        let mut rng = Rng::new(7, 0);
        let count = 200_000;
        let mut sum = 0.0f64;
        for _ in 0..count {
            let w = cosine_direction(n, Vec2::new(rng.next_f32(), rng.next_f32()));
            assert!(w.dot(n) >= -1e-6);
            sum += w.dot(n) as f64;
        }
        let mean = sum / count as f64;
        assert!((mean - 2.0 / 3.0).abs() < 3e-3, "mean cosine {mean}");
    }
}
