//! The reflection model of METHOD.md §4. TEMPORARY minimal version so the renderer can be
//! written; replaced by the full module (being written on the `optics` branch).

use glam::{Vec2, Vec3};

/// Shadowing term G.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shadowing {
    /// G = 1.
    None,
    /// Smith.
    Smith,
}

/// Blinn-Phong microfacet reflection with dielectric Fresnel.
#[derive(Clone, Copy, Debug)]
pub struct ReflectionModel {
    /// Gloss e.
    pub gloss: f32,
    /// IOR.
    pub ior: f32,
    /// Shadowing.
    pub shadowing: Shadowing,
}

/// A sampled direction and its weight f cos / pdf.
#[derive(Clone, Copy, Debug)]
pub struct LobeSample {
    /// Direction towards the light.
    pub wi: Vec3,
    /// Weight.
    pub weight: f32,
}

fn fresnel(cos_i: f32, ior: f32) -> f32 {
    let c = cos_i.clamp(0.0, 1.0) as f64;
    let n = ior as f64;
    let g2 = n * n - 1.0 + c * c;
    if g2 < 0.0 {
        return 1.0;
    }
    let g = g2.sqrt();
    let a = (g - c) / (g + c);
    let b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    (0.5 * a * a * (1.0 + b * b)) as f32
}

impl ReflectionModel {
    /// A model without shadowing.
    pub fn new(gloss: f32, ior: f32) -> Self {
        ReflectionModel {
            gloss,
            ior,
            shadowing: Shadowing::None,
        }
    }

    /// Samples the lobe.
    #[inline]
    pub fn sample(&self, n: Vec3, wo: Vec3, u: Vec2) -> Option<LobeSample> {
        let cos_h = (u.x as f64).powf(1.0 / (self.gloss as f64 + 2.0)) as f32;
        let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
        let phi = std::f32::consts::TAU * u.y;
        let (t, b) = n.any_orthonormal_pair();
        let h = (t * (sin_h * phi.cos()) + b * (sin_h * phi.sin()) + n * cos_h).normalize();
        let wo_h = wo.dot(h);
        if wo_h <= 0.0 {
            return None;
        }
        let wi = h * (2.0 * wo_h) - wo;
        let n_wi = n.dot(wi);
        let n_wo = n.dot(wo);
        if n_wi <= 0.0 || n_wo <= 0.0 {
            return None;
        }
        Some(LobeSample {
            wi,
            weight: fresnel(wo_h, self.ior) * wo_h / (n_wo * cos_h),
        })
    }
}
