//! The lobe of the statistical water model (method §10): microfacets whose slopes are Gaussian
//! with a variance of their own along each of two tangent axes.
//!
//! Beckmann microfacets are exactly this with the same variance `alpha^2 / 2` on both axes
//! (Walter, Marschner, Li and Torrance 2007, eq. 25: the Beckmann `D` is the Gaussian density
//! of the facet slopes `tan theta_h (cos phi, sin phi)` seen through `1 / cos^4 theta_h`), and
//! the paper's Blinn-Phong `e` maps to it by `alpha^2 = 2 / (e + 2)`. Waves that tilt the mean
//! surface by Gaussian slopes of variances `(v_t, v_b)` add to them per axis (Bruneton, Neyret
//! and Holzschuch 2010): the lobe of the mean surface has slope variances
//! `1 / (e + 2) + v_t` and `1 / (e + 2) + v_b` ([`GaussianSlopes::microfacets_and_waves`]).
//!
//! Sampling draws the slope `p = (p_t, p_b)` itself by Box-Muller, `p = sigma sqrt(-2 ln xi)
//! (cos 2 pi u.y, sin 2 pi u.y)` per axis, with `xi = CONE_LOST_MASS + (1 - CONE_LOST_MASS)
//! u.x`: continuous in `u` and stratification-preserving, and truncated, like the isotropic
//! lobe, to the ellipse that holds all but `CONE_LOST_MASS` of the slopes. The facet normal is
//! `h = normalize(n - p_t t - p_b b)`; a slope's solid angle is `d omega_h = cos^3 theta_h
//! d^2 p`, so `pdf_h(h) = P(p) / cos^3 theta_h = D(h) (n.h) / (1 - CONE_LOST_MASS)`, and the
//! weight `f (n.wi) / pdf(wi)` simplifies to the isotropic lobe's, `KEEP F G (wo.h) /
//! ((n.wo)(n.h))`.

use glam::{Vec2, Vec3};

use super::fresnel::fresnel_dielectric;
use super::lobe::{LobeSample, ReflectionModel};
use super::microfacet::CONE_LOST_MASS;
use super::shadowing::{energy_cap, smith_g1_alpha, Shadowing};

const KEEP: f32 = (1.0 - CONE_LOST_MASS) as f32;

/// Gaussian facet slopes with variance `variance[0]` along a tangent `t` and `variance[1]`
/// along `b = n x t` (dimensionless: slope is rise over run).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaussianSlopes {
    /// Slope variances along `t` and along `b`; each finite and > 0.
    pub variance: [f32; 2],
}

impl GaussianSlopes {
    /// The isotropic lobe of Blinn-Phong gloss `e`, as Beckmann slopes: `1 / (e + 2)` per axis.
    pub fn from_gloss(gloss: f32) -> Self {
        let v = 1.0 / (gloss + 2.0);
        GaussianSlopes { variance: [v, v] }
    }

    /// The microfacets of gloss `e` under waves of slope variances `waves` (along `t`, `b`;
    /// each >= 0): the variances add (module doc).
    pub fn microfacets_and_waves(gloss: f32, waves: [f32; 2]) -> Self {
        let m = Self::from_gloss(gloss).variance;
        GaussianSlopes {
            variance: [m[0] + waves[0].max(0.0), m[1] + waves[1].max(0.0)],
        }
    }

    /// Draws `wi` for the view direction `wo` at a mean surface of unit normal `n`, with `t`
    /// a unit tangent (the first axis of the slopes), from two uniform numbers `u` in
    /// [0, 1)^2; `ior` and `shadowing` from `model` (its gloss is not read: the slopes are
    /// `self`). `None` as for [`ReflectionModel::sample`]: `wo` or `wi` below the surface, or
    /// `wo.h <= 0`.
    #[inline]
    pub fn sample(
        &self,
        model: &ReflectionModel,
        n: Vec3,
        t: Vec3,
        wo: Vec3,
        u: Vec2,
    ) -> Option<LobeSample> {
        self.sample_drawn(model, n, t, wo, &self.draw(u))
    }

    /// [`sample`](Self::sample) from the slope `draw` (of [`draw`](Self::draw)): the same
    /// sample to the last bit. Where many water points read the same uniform pairs (the
    /// control variate's grid), the draws are made once.
    #[inline]
    pub fn sample_drawn(
        &self,
        model: &ReflectionModel,
        n: Vec3,
        t: Vec3,
        wo: Vec3,
        draw: &SlopeDraw,
    ) -> Option<LobeSample> {
        self.sample_in(model, &self.view(model, n, t, wo)?, draw)
    }

    /// What every sample and value of this lobe seen from `wo` at a mean surface of unit
    /// normal `n` and unit tangent `t` shares (the frame, the view's cosine and its masking
    /// under `model`'s shadowing); `None` when `wo` lies below the surface (no sample, and
    /// every value 0).
    #[inline]
    pub fn view(&self, model: &ReflectionModel, n: Vec3, t: Vec3, wo: Vec3) -> Option<SlopeView> {
        let cos_o = n.dot(wo);
        if cos_o <= 0.0 {
            return None;
        }
        let b = n.cross(t);
        let g1_o = match model.shadowing {
            Shadowing::None => 1.0,
            Shadowing::Smith => self.g1(b, t, wo, cos_o),
        };
        Some(SlopeView {
            n,
            t,
            b,
            wo,
            cos_o,
            g1_o,
        })
    }

    /// [`sample_drawn`](Self::sample_drawn) from its [`view`](Self::view) (made with the
    /// same `model`): the same sample to the last bit, for many draws at one view.
    #[inline]
    pub fn sample_in(
        &self,
        model: &ReflectionModel,
        view: &SlopeView,
        draw: &SlopeDraw,
    ) -> Option<LobeSample> {
        let m = Self::mirror(view, draw)?;
        let fresnel = fresnel_dielectric(m.cos_oh, model.ior);
        let g = match model.shadowing {
            Shadowing::None => energy_cap(view.cos_o, m.cos_h, m.cos_oh, fresnel),
            Shadowing::Smith => view.g1_o * self.g1(view.b, view.t, m.wi, m.cos_i),
        };
        let weight = KEEP * fresnel * g * m.cos_oh / (view.cos_o * m.cos_h);
        // pdf_h = xi / (2 pi sigma_t sigma_b KEEP cos^3 theta_h); pdf(wi) = pdf_h / (4 wo.h).
        let sigma_tb = (self.variance[0] * self.variance[1]).sqrt();
        let cos3 = m.cos_h * m.cos_h * m.cos_h;
        let pdf = m.xi / (std::f32::consts::TAU * sigma_tb * KEEP * cos3 * 4.0 * m.cos_oh);
        Some(LobeSample {
            wi: m.wi,
            weight,
            pdf,
        })
    }

    /// The direction [`sample`](Self::sample) returns for the same arguments, without its
    /// weight.
    #[inline]
    pub fn direction(&self, n: Vec3, t: Vec3, wo: Vec3, u: Vec2) -> Option<Vec3> {
        let view = self.view(&Self::UNMASKED, n, t, wo)?;
        Self::mirror(&view, &self.draw(u)).map(|m| m.wi)
    }

    /// The slope drawn from `u` (module doc): what depends on `u` and the variances alone.
    #[inline]
    pub fn draw(&self, u: Vec2) -> SlopeDraw {
        let xi = CONE_LOST_MASS as f32 + KEEP * u.x;
        let r = (-2.0 * xi.ln()).max(0.0).sqrt();
        let (sin_phi, cos_phi) = (std::f32::consts::TAU * u.y).sin_cos();
        let p_t = self.variance[0].sqrt() * r * cos_phi;
        let p_b = self.variance[1].sqrt() * r * sin_phi;
        SlopeDraw {
            xi,
            p_t,
            p_b,
            inv_len: 1.0 / (1.0 + p_t * p_t + p_b * p_b).sqrt(),
        }
    }

    /// `f(wo, wi) (n.wi)` of this lobe for [`ReflectionModel`]'s `ior` and `shadowing`: the
    /// BRDF times the cosine at the light, 0 outside the truncation ellipse or below the
    /// surface. For tests and brute-force integrals.
    pub fn eval_cos(&self, model: &ReflectionModel, n: Vec3, t: Vec3, wo: Vec3, wi: Vec3) -> f32 {
        self.view(model, n, t, wo)
            .map_or(0.0, |view| self.eval_cos_in(model, &view, wi))
    }

    /// [`eval_cos`](Self::eval_cos) from its [`view`](Self::view) (made with the same
    /// `model`): the same value to the last bit, for many directions at one view.
    #[inline]
    pub fn eval_cos_in(&self, model: &ReflectionModel, view: &SlopeView, wi: Vec3) -> f32 {
        let SlopeView {
            n, t, b, wo, cos_o, ..
        } = *view;
        let cos_i = n.dot(wi);
        if cos_i <= 0.0 {
            return 0.0;
        }
        let h = (wo + wi).normalize();
        let cos_h = n.dot(h);
        if cos_h <= 0.0 {
            return 0.0;
        }
        let p = Vec2::new(-t.dot(h), -b.dot(h)) / cos_h;
        let q = p.x * p.x / self.variance[0] + p.y * p.y / self.variance[1];
        if q > -2.0 * (CONE_LOST_MASS as f32).ln() {
            return 0.0;
        }
        let sigma_tb = (self.variance[0] * self.variance[1]).sqrt();
        let d = (-0.5 * q).exp() / (std::f32::consts::TAU * sigma_tb * cos_h.powi(4));
        let cos_oh = wo.dot(h);
        let fresnel = fresnel_dielectric(cos_oh, model.ior);
        let g = match model.shadowing {
            Shadowing::None => energy_cap(cos_o, cos_h, cos_oh, fresnel),
            Shadowing::Smith => view.g1_o * self.g1(b, t, wi, cos_i),
        };
        d * fresnel * g / (4.0 * cos_o)
    }

    /// Smith's masking of direction `w` (of cosine `cos_w` to `n`) by these slopes: the
    /// Beckmann `G1` with the roughness of the slopes projected on `w`'s azimuth (Heitz 2014,
    /// "Understanding the Masking-Shadowing Function", §5.3: `alpha_w^2 = cos^2 phi alpha_t^2
    /// + sin^2 phi alpha_b^2`, `alpha^2 = 2 variance`).
    #[inline]
    fn g1(&self, b: Vec3, t: Vec3, w: Vec3, cos_w: f32) -> f32 {
        let (wt, wb) = (w.dot(t), w.dot(b));
        let r2 = wt * wt + wb * wb;
        if r2 <= 0.0 {
            return 1.0;
        }
        let alpha2 = 2.0 * (wt * wt * self.variance[0] + wb * wb * self.variance[1]) / r2;
        smith_g1_alpha(cos_w, alpha2.sqrt())
    }

    #[inline]
    fn mirror(view: &SlopeView, draw: &SlopeDraw) -> Option<Mirrored> {
        let SlopeView { n, t, b, wo, .. } = *view;
        let SlopeDraw {
            xi,
            p_t,
            p_b,
            inv_len,
        } = *draw;
        let h = (n - t * p_t - b * p_b) * inv_len;
        let cos_h = inv_len;
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
            cos_h,
            cos_oh,
            cos_i,
        })
    }

    /// A model whose view computes no masking, for directions alone.
    const UNMASKED: ReflectionModel = ReflectionModel {
        gloss: 1.0,
        ior: 1.0,
        shadowing: Shadowing::None,
    };
}

/// What every sample and value of one lobe seen from one direction shares
/// ([`GaussianSlopes::view`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlopeView {
    n: Vec3,
    t: Vec3,
    /// `n x t`.
    b: Vec3,
    wo: Vec3,
    /// `n.wo`, > 0.
    cos_o: f32,
    /// Smith's masking of `wo` under the view's model (1 without masking).
    g1_o: f32,
}

/// A slope drawn for [`GaussianSlopes::sample`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlopeDraw {
    /// `CONE_LOST_MASS + (1 - CONE_LOST_MASS) u.x`, as drawn.
    xi: f32,
    /// The slope along `t` and along `b`.
    p_t: f32,
    p_b: f32,
    /// `1 / sqrt(1 + p_t^2 + p_b^2)`: `n.h`.
    inv_len: f32,
}

/// A drawn direction and the cosines its weight needs.
struct Mirrored {
    wi: Vec3,
    xi: f32,
    cos_h: f32,
    cos_oh: f32,
    cos_i: f32,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::orthonormal_basis;

    fn frame() -> (Vec3, Vec3) {
        (Vec3::Y, Vec3::Z)
    }

    /// The isotropic case is the paper's lobe up to the Blinn-Phong/Beckmann difference:
    /// at gloss 500 the two reflect the same fraction of light to within a fraction of a
    /// percent (their `D`s differ by `O(1/e)`), by brute-force integration of both.
    #[test]
    fn isotropic_slopes_reflect_as_the_blinn_phong_lobe() {
        let (n, t) = frame();
        let model = ReflectionModel::new(500.0, 1.33);
        let slopes = GaussianSlopes::from_gloss(500.0);
        let wo = Vec3::new(0.0, 0.3, 1.0).normalize();
        let mirror = Vec3::new(0.0, 0.3, -1.0).normalize();
        let (a, b) = orthonormal_basis(mirror);
        // Integrate f cos over a square of directions around the mirror direction.
        let (half, steps) = (0.25f32, 400);
        let (mut sum_g, mut sum_b) = (0.0f64, 0.0f64);
        for i in 0..steps {
            for j in 0..steps {
                let x = -half + (i as f32 + 0.5) * 2.0 * half / steps as f32;
                let y = -half + (j as f32 + 0.5) * 2.0 * half / steps as f32;
                let d = mirror + a * x + b * y;
                let dw = (2.0 * half / steps as f32).powi(2) / d.length().powi(3);
                let wi = d.normalize();
                sum_g += (slopes.eval_cos(&model, n, t, wo, wi) * dw) as f64;
                sum_b += (model.eval_cos(n, wo, wi) * dw) as f64;
            }
        }
        assert!(sum_b > 0.01, "{sum_b}");
        assert!((sum_g / sum_b - 1.0).abs() < 5e-3, "{sum_g} vs {sum_b}");
    }

    /// The importance-sampled mean of the weight converges to the brute-force integral of
    /// `f cos` (an unbiased estimator), for a strongly anisotropic lobe at a grazing view.
    #[test]
    fn sampling_matches_the_brute_force_integral() {
        let (n, t) = frame();
        for shadowing in [Shadowing::None, Shadowing::Smith] {
            let model = ReflectionModel::new(500.0, 1.33).with_shadowing(shadowing);
            let slopes = GaussianSlopes {
                variance: [0.004, 0.0012],
            };
            let wo = Vec3::new(0.05, 0.12, 1.0).normalize();
            // Brute force over the upper hemisphere in (cos theta, phi).
            let (nc, np) = (2000, 2000);
            let b = n.cross(t);
            let mut brute = 0.0f64;
            for i in 0..nc {
                let c = (i as f64 + 0.5) / nc as f64;
                let s = (1.0 - c * c).sqrt();
                for j in 0..np {
                    let phi = std::f64::consts::TAU * (j as f64 + 0.5) / np as f64;
                    let wi =
                        (n * c as f32 + t * (s * phi.cos()) as f32 + b * (s * phi.sin()) as f32)
                            .normalize();
                    brute += slopes.eval_cos(&model, n, t, wo, wi) as f64;
                }
            }
            brute *= std::f64::consts::TAU / (nc * np) as f64;
            let m = 512;
            let mut mc = 0.0f64;
            for i in 0..m {
                for j in 0..m {
                    let u = Vec2::new((i as f32 + 0.5) / m as f32, (j as f32 + 0.5) / m as f32);
                    if let Some(s) = slopes.sample(&model, n, t, wo, u) {
                        mc += s.weight as f64;
                        // The density is that of eval: weight = f cos / pdf.
                        let f = slopes.eval_cos(&model, n, t, wo, s.wi);
                        assert!(
                            (f / s.pdf - s.weight).abs() < 2e-3 * s.weight.max(1e-3),
                            "{f} / {} vs {}",
                            s.pdf,
                            s.weight
                        );
                    }
                }
            }
            mc /= (m * m) as f64;
            assert!(brute > 0.01, "{brute}");
            assert!(
                (mc / brute - 1.0).abs() < 3e-3,
                "{shadowing:?}: sampled {mc} vs brute force {brute}"
            );
        }
    }

    /// The lobe's spread follows each axis's variance: the reflected directions' spread
    /// across the view plane is set by the across slope alone, and grows as its square root.
    #[test]
    fn each_axis_spreads_the_lobe_by_its_own_variance() {
        let (n, t) = frame();
        let b = n.cross(t);
        let wo = Vec3::new(0.0, 0.5, 1.0).normalize();
        let spread_across = |var_b: f32| {
            let slopes = GaussianSlopes {
                variance: [0.002, var_b],
            };
            let m = 128;
            let mut s2 = 0.0f64;
            let mut count = 0.0f64;
            for i in 0..m {
                for j in 0..m {
                    let u = Vec2::new((i as f32 + 0.5) / m as f32, (j as f32 + 0.5) / m as f32);
                    if let Some(wi) = slopes.direction(n, t, wo, u) {
                        s2 += (wi.dot(b) as f64).powi(2);
                        count += 1.0;
                    }
                }
            }
            (s2 / count).sqrt()
        };
        let (a, c) = (spread_across(0.001), spread_across(0.004));
        // The across component of wi is 2 (wo.h) h_b ~ 2 cos(theta_o) p_b for small slopes:
        // its rms doubles when the variance quadruples.
        assert!((c / a - 2.0).abs() < 0.05, "{a} {c}");
        let expected = 2.0 * wo.dot(n) as f64 * 0.001f64.sqrt();
        assert!((a / expected - 1.0).abs() < 0.05, "{a} vs {expected}");
    }
}
