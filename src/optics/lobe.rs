//! The reflection lobe: the model's parameters, importance sampling of `wi`, and evaluation of
//! the BRDF and of the sampling density.

use glam::{DVec3, Vec2, Vec3};

use super::frame::orthonormal_basis;
use super::fresnel::fresnel_dielectric;
use super::microfacet::{blinn_phong_d, cone_cos_theta, CONE_LOST_MASS};
use super::shadowing::Shadowing;

/// The reflection model of the water surface (method §4): Blinn-Phong microfacets of gloss
/// `e`, a dielectric of index `ior` seen from air, and a choice of geometry term.
///
/// Fields are public for convenience; `gloss` must be finite and >= 0 and `ior` > 0 (the
/// command line checks its inputs before building a model).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReflectionModel {
    /// The Blinn-Phong exponent `e` of the paper (光泽常数).
    pub gloss: f32,
    /// Index of refraction of the water (1.33 unless the scene says otherwise).
    pub ior: f32,
    /// Which geometry term `G` to use.
    pub shadowing: Shadowing,
}

/// One importance sample of the lobe.
#[derive(Clone, Copy, Debug)]
pub struct LobeSample {
    /// Unit direction towards the light, above the surface (`n.wi > 0`).
    pub wi: Vec3,
    /// `f(wo, wi) (n.wi) / pdf(wi)`: Fresnel, geometry term and the cone factor
    /// `1 - CONE_LOST_MASS` included, so the mean of `weight * L(wi)` estimates the reflected
    /// radiance.
    pub weight: f32,
    /// The solid-angle density it was drawn with ([`ReflectionModel::pdf`] of `wi`, from the
    /// sample's own numbers: cheaper, and exact to f32 rounding).
    pub pdf: f32,
}

const KEEP: f32 = (1.0 - CONE_LOST_MASS) as f32;

impl ReflectionModel {
    /// A model with the paper's geometry term ([`Shadowing::None`]).
    pub fn new(gloss: f32, ior: f32) -> Self {
        ReflectionModel {
            gloss,
            ior,
            shadowing: Shadowing::None,
        }
    }

    /// The same model with another geometry term.
    pub fn with_shadowing(self, shadowing: Shadowing) -> Self {
        ReflectionModel { shadowing, ..self }
    }

    /// `cos theta_0`: every sampled half vector satisfies `n.h >= cos theta_0`, and the cone
    /// holds all but `CONE_LOST_MASS` of the lobe (see the [module docs](super)).
    pub fn cone_cos_theta(&self) -> f32 {
        cone_cos_theta(self.gloss as f64) as f32
    }

    /// Draws `wi` for the view direction `wo` at a point of normal `n` from two uniform numbers
    /// `u` in [0, 1)^2.
    ///
    /// The half vector has `cos theta_h = xi^(1/(e+2))` with `xi = CONE_LOST_MASS +
    /// (1 - CONE_LOST_MASS) u.x` (so it stays in the cone) and azimuth `2 pi u.y`; `wi` is `wo`
    /// mirrored about it. Returns `None` when there is nothing to reflect: `wo` below the
    /// surface (`n.wo <= 0`, possible with interpolated normals), `wo.h <= 0`, or `wi` below
    /// the surface (`n.wi <= 0`). Those samples count as zero in every estimate.
    #[inline]
    pub fn sample(&self, n: Vec3, wo: Vec3, u: Vec2) -> Option<LobeSample> {
        self.sample_drawn(n, orthonormal_basis(n), wo, &self.draw(u))
    }

    /// [`sample`](Self::sample) from the half vector `draw` (of [`draw`](Self::draw)) about
    /// `n`, whose tangents `frame` are [`orthonormal_basis`]`(n)`: the same sample to the last
    /// bit. Where many water points read the same uniform pairs (the control variate's grid),
    /// the draws and each point's frame are made once.
    #[inline]
    pub fn sample_drawn(
        &self,
        n: Vec3,
        frame: (Vec3, Vec3),
        wo: Vec3,
        draw: &HalfDraw,
    ) -> Option<LobeSample> {
        let m = self.mirror(n, frame, wo, draw)?;
        let fresnel = fresnel_dielectric(m.cos_oh, self.ior);
        let g = self
            .shadowing
            .g(self.gloss, m.cos_o, m.cos_i, m.cos_h, m.cos_oh, fresnel);
        // f (n.wi) / pdf(wi) with pdf(wi) = D (n.h) / (4 (wo.h) KEEP): D cancels.
        let weight = KEEP * fresnel * g * m.cos_oh / (m.cos_o * m.cos_h);
        // D (n.h) = (e + 2) / (2 pi) (n.h)^(e+1) = (e + 2) xi / (2 pi (n.h)).
        let pdf =
            (self.gloss + 2.0) * m.xi / (std::f32::consts::TAU * m.cos_h * 4.0 * m.cos_oh * KEEP);
        Some(LobeSample {
            wi: m.wi,
            weight,
            pdf,
        })
    }

    /// The direction [`sample`](Self::sample) returns for the same arguments, without its
    /// weight: for neighbouring directions, where only the geometry is wanted.
    #[inline]
    pub fn direction(&self, n: Vec3, wo: Vec3, u: Vec2) -> Option<Vec3> {
        self.mirror(n, orthonormal_basis(n), wo, &self.draw(u))
            .map(|m| m.wi)
    }

    /// The half vector drawn from `u`, in the frame of the normal (see
    /// [`sample`](Self::sample)): what depends on `u` and the gloss alone.
    #[inline]
    pub fn draw(&self, u: Vec2) -> HalfDraw {
        let xi = CONE_LOST_MASS as f32 + KEEP * u.x;
        let log_cos_h = xi.ln() / (self.gloss + 2.0);
        let cos_h = log_cos_h.exp();
        // 1 - cos^2 computed as -expm1(2 ln cos): for e in the thousands cos_h is within 1e-4
        // of one and the direct difference would keep only a few significant digits.
        let sin_h = (-(2.0 * log_cos_h).exp_m1()).max(0.0).sqrt();
        let (sin_phi, cos_phi) = (std::f32::consts::TAU * u.y).sin_cos();
        HalfDraw {
            xi,
            cos_h,
            sin_h_cos_phi: sin_h * cos_phi,
            sin_h_sin_phi: sin_h * sin_phi,
        }
    }

    /// `wo` mirrored about the half vector `draw` about `n` (tangents `(t, b)`; see
    /// [`sample`](Self::sample)).
    #[inline]
    fn mirror(&self, n: Vec3, (t, b): (Vec3, Vec3), wo: Vec3, draw: &HalfDraw) -> Option<Mirrored> {
        let cos_o = n.dot(wo);
        if cos_o <= 0.0 {
            return None;
        }
        let HalfDraw {
            xi,
            cos_h,
            sin_h_cos_phi,
            sin_h_sin_phi,
        } = *draw;
        let h = t * sin_h_cos_phi + b * sin_h_sin_phi + n * cos_h;
        let cos_oh = wo.dot(h);
        if cos_oh <= 0.0 {
            return None;
        }
        let wi = h * (2.0 * cos_oh) - wo;
        let cos_i = n.dot(wi);
        if cos_i <= 0.0 {
            return None;
        }
        Some(Mirrored {
            wi,
            xi,
            cos_o,
            cos_h,
            cos_oh,
            cos_i,
        })
    }

    /// `f(wo, wi) (n.wi)`: the BRDF times the cosine at the light, 0 when either direction is
    /// below the surface or the half vector is outside the cone. Computed in f64 so the power
    /// in `D` keeps its precision at high gloss.
    pub fn eval_cos(&self, n: Vec3, wo: Vec3, wi: Vec3) -> f32 {
        match self.half_vector(n, wo, wi) {
            Some(hv) => {
                let d = blinn_phong_d(hv.cos_h, self.gloss as f64);
                let fresnel = fresnel_dielectric(hv.cos_oh as f32, self.ior);
                let g = self.shadowing.g(
                    self.gloss,
                    hv.cos_o as f32,
                    hv.cos_i as f32,
                    hv.cos_h as f32,
                    hv.cos_oh as f32,
                    fresnel,
                );
                (d * fresnel as f64 * g as f64 / (4.0 * hv.cos_o)) as f32
            }
            None => 0.0,
        }
    }

    /// The solid-angle density with which [`sample`](Self::sample) returns `wi` (for multiple
    /// importance sampling): `D(h) (n.h) / (4 (wo.h) (1 - CONE_LOST_MASS))` inside the cone, 0
    /// where `sample` never returns `wi`. Samples lost below the surface make it integrate to
    /// slightly less than 1.
    pub fn pdf(&self, n: Vec3, wo: Vec3, wi: Vec3) -> f32 {
        match self.half_vector(n, wo, wi) {
            Some(hv) => {
                let d = blinn_phong_d(hv.cos_h, self.gloss as f64);
                (d * hv.cos_h / (4.0 * hv.cos_oh * (1.0 - CONE_LOST_MASS))) as f32
            }
            None => 0.0,
        }
    }

    /// The cosines of a pair of directions that the lobe reaches, or `None`.
    fn half_vector(&self, n: Vec3, wo: Vec3, wi: Vec3) -> Option<HalfVector> {
        // Renormalised in f64: an f32 unit vector is off by up to ~1e-7 in length, and
        // wo.h - wi.h = (|wo|^2 - |wi|^2) / |wo + wi|, which for a facet seen at grazing
        // (wo.h ~ 1e-3) turns that into percent-level asymmetry and error.
        let (n, wo, wi) = (
            n.as_dvec3().normalize(),
            wo.as_dvec3().normalize(),
            wi.as_dvec3().normalize(),
        );
        let cos_o = n.dot(wo);
        let cos_i = n.dot(wi);
        if cos_o <= 0.0 || cos_i <= 0.0 {
            return None;
        }
        // Both directions are above the surface, so wo + wi is not zero and wo.h > 0.
        let h: DVec3 = (wo + wi).normalize();
        let cos_h = n.dot(h);
        if cos_h < cone_cos_theta(self.gloss as f64) {
            return None;
        }
        Some(HalfVector {
            cos_o,
            cos_i,
            cos_h,
            cos_oh: wo.dot(h),
        })
    }
}

/// A half vector drawn for [`ReflectionModel::sample`], in the frame of the normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HalfDraw {
    /// `(n.h)^(e+2)`, as drawn.
    xi: f32,
    cos_h: f32,
    /// The tangent components: `sin theta_h cos phi`, `sin theta_h sin phi`.
    sin_h_cos_phi: f32,
    sin_h_sin_phi: f32,
}

/// A drawn direction and the cosines its weight needs.
struct Mirrored {
    wi: Vec3,
    /// `(n.h)^(e+2)`, as drawn.
    xi: f32,
    cos_o: f32,
    cos_h: f32,
    cos_oh: f32,
    cos_i: f32,
}

struct HalfVector {
    cos_o: f64,
    cos_i: f64,
    cos_h: f64,
    cos_oh: f64,
}

/// Remaps two uniform numbers for [`ReflectionModel::sample`] so that a square stratum of
/// `[0, 1)^2` becomes a compact cell of the lobe around its axis, not a ring sector.
///
/// `sample` reads `u.x` as `1 - r^2` and `u.y` as the azimuth over `2 pi`, with `r` the
/// distance from the lobe's axis in a disk where the half vector's tangent offset is nearly
/// proportional to the position (`theta_h ~ r sqrt(2 / (e + 2))` near the axis). Shirley and
/// Chiu's concentric map takes the square to that disk preserving area, so uniform numbers
/// stay uniform (the estimate is unchanged in expectation) while a stratum stays a compact
/// patch: the edge of a rectangle then cuts few strata, each by little, which is what
/// stratifying is for.
pub fn compact_strata(u: Vec2) -> Vec2 {
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};
    let (a, b) = (2.0 * u.x - 1.0, 2.0 * u.y - 1.0);
    if a == 0.0 && b == 0.0 {
        return Vec2::new(1.0, 0.0);
    }
    let (r, phi) = if a.abs() > b.abs() {
        (a, FRAC_PI_4 * (b / a))
    } else {
        (b, FRAC_PI_2 - FRAC_PI_4 * (a / b))
    };
    // A negative radius is the opposite direction.
    let phi = if r < 0.0 { phi + PI } else { phi };
    let turns = phi / TAU;
    Vec2::new((1.0 - r * r).clamp(0.0, 1.0), turns - turns.floor())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Where `compact_strata`'s output puts a point in the disk of the doc comment.
    fn disk(v: Vec2) -> Vec2 {
        let r = (1.0 - v.x).max(0.0).sqrt();
        let phi = std::f32::consts::TAU * v.y;
        Vec2::new(r * phi.cos(), r * phi.sin())
    }

    #[test]
    fn a_samples_own_density_is_the_models() {
        // The density `sample` reports from its own numbers against `pdf` recomputed in f64
        // from the direction, over the lobe (grazing view, as on the water) and two glosses.
        for gloss in [200.0, 1000.0] {
            let model = ReflectionModel::new(gloss, 1.33);
            let (n, wo) = (Vec3::Y, Vec3::new(0.0, 0.15, 1.0).normalize());
            let mut checked = 0;
            for i in 0..40 {
                for j in 0..40 {
                    let u = Vec2::new((i as f32 + 0.5) / 40.0, (j as f32 + 0.5) / 40.0);
                    let Some(s) = model.sample(n, wo, u) else {
                        continue;
                    };
                    let want = model.pdf(n, wo, s.wi);
                    assert!(
                        (s.pdf - want).abs() <= 1e-4 * want,
                        "e {gloss}, u {u}: {} against {want}",
                        s.pdf
                    );
                    checked += 1;
                }
            }
            assert!(checked > 1000);
        }
    }

    #[test]
    fn compact_strata_keeps_uniform_numbers_uniform() {
        // A fine regular grid in, a histogram of 5 x 5 cells of the output: an area-preserving
        // map fills every cell equally.
        let n = 1000;
        let mut counts = [[0u32; 5]; 5];
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let v = compact_strata(u);
                assert!((0.0..=1.0).contains(&v.x) && (0.0..1.0).contains(&v.y));
                counts[((v.x * 5.0) as usize).min(4)][((v.y * 5.0) as usize).min(4)] += 1;
            }
        }
        let expected = (n * n) as f32 / 25.0;
        for c in counts.iter().flatten() {
            assert!(
                (*c as f32 - expected).abs() < 0.01 * expected,
                "{c} vs {expected}"
            );
        }
    }

    #[test]
    fn compact_strata_makes_strata_compact() {
        // Each of 6 x 6 strata: its image in the disk (diameter 2) spans at most a third of
        // it. Without the map, the same strata are ring sectors a sixth of a turn wide, up to
        // a whole radius long.
        let strata = 6;
        let sub = 12;
        let mut worst = 0f32;
        let mut worst_plain = 0f32;
        for s in 0..strata * strata {
            let (sx, sy) = ((s % strata) as f32, (s / strata) as f32);
            let mut points = Vec::new();
            let mut plain = Vec::new();
            for i in 0..=sub {
                for j in 0..=sub {
                    let u = Vec2::new(
                        ((sx + i as f32 / sub as f32) / strata as f32).min(0.999_999),
                        ((sy + j as f32 / sub as f32) / strata as f32).min(0.999_999),
                    );
                    points.push(disk(compact_strata(u)));
                    plain.push(disk(u));
                }
            }
            let span = |p: &[Vec2]| {
                p.iter()
                    .flat_map(|a| p.iter().map(move |b| a.distance(*b)))
                    .fold(0f32, f32::max)
            };
            worst = worst.max(span(&points));
            worst_plain = worst_plain.max(span(&plain));
        }
        assert!(worst < 0.67, "largest stratum spans {worst}");
        assert!(worst_plain > 0.9, "ring sectors span {worst_plain}");
    }
}
