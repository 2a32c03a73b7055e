//! Monte Carlo estimates built on the lobe sampler: the paper's reflection coefficient and the
//! directional albedo.

use glam::{Vec2, Vec3};

use super::lobe::ReflectionModel;
use crate::random::Rng;

/// Estimator of the reflection coefficient `c(p) = integral f(wo, wi) V(wi) (n.wi) dwi`
/// (method §4, paper eq. 11) over the truncation cone: the mean of `weight * visibility(wi)`
/// over `samples` lobe samples drawn with `rng`.
///
/// `visibility` is called once for each sample that leaves above the surface, with its `wi`,
/// and returns how much of the light is seen that way (1 lit, 0 not). Samples with no
/// direction (see [`ReflectionModel::sample`]) count as zero. Returns 0 for `samples == 0`.
pub fn reflection_coefficient(
    model: &ReflectionModel,
    n: Vec3,
    wo: Vec3,
    samples: u32,
    rng: &mut Rng,
    mut visibility: impl FnMut(Vec3) -> f32,
) -> f32 {
    if samples == 0 {
        return 0.0;
    }
    // f64 sum: 1e6 f32 additions would lose ~1e-4 relative.
    let mut sum = 0.0f64;
    for _ in 0..samples {
        let u = Vec2::new(rng.next_f32(), rng.next_f32());
        if let Some(s) = model.sample(n, wo, u) {
            sum += (s.weight * visibility(s.wi)) as f64;
        }
    }
    (sum / samples as f64) as f32
}

impl ReflectionModel {
    /// Estimate of the directional albedo `integral f(wo, wi) (n.wi) dwi` over the cone, every
    /// `wi` counted as lit: the fraction of light arriving from all directions that the surface
    /// sends towards `wo`. It is [`reflection_coefficient`] with a visibility of 1.
    pub fn albedo(&self, n: Vec3, wo: Vec3, samples: u32, rng: &mut Rng) -> f32 {
        reflection_coefficient(self, n, wo, samples, rng, |_| 1.0)
    }
}
