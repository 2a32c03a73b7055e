//! The joint fit's control variate (method §5, last paragraph): a Gaussian on the light's
//! plane per pixel, whose mass inside any rectangle is known exactly, subtracted from the lobe
//! samples and added back in closed form.
//!
//! A coefficient is the lobe's mass inside a rectangle, estimated from the pixel's lobe
//! samples, and the fit's error on Table 3 was that estimate's noise (BENCHMARKS.md). With
//! `g` a density on the plane whose mass `G(R)` inside a rectangle is known, the same
//! samples estimate
//!
//! `c(R) = G(R) + (1/N) sum_s (w_s - g(x_s) / p(x_s)) k_s(R)`
//!
//! (`w_s` the sample's weight, `p` the density on the plane it was drawn with, `k_s(R)` its
//! kernel's share inside `R`). Its expectation is the plain estimate's whatever `g` is, as
//! long as `g` does not depend on the samples. Where `g` follows the lobe, each sample
//! carries only the small difference, so an edge cutting through the samples moves the
//! estimate by far less noise. `g` here is a product of two normal densities along the
//! plane's axes, matched in mass, mean and variance to the pixel's lobe as a fixed grid of
//! lobe directions lands on the plane.
//!
//! On Table 3 the noise of a coefficient's derivative by an edge is about a fifth in variance
//! of the plain estimate's, and the fit's errors what 16 times the samples give without it
//! (docs/decisions.md, "A control variate for the joint fit's coefficients").

use glam::{Vec2, Vec3};

use crate::fitting::light_plane::LightPlane;
use crate::fitting::rect::Rect;
use crate::optics::{compact_strata, ReflectionModel};
use crate::render::WaterPoint;
use crate::water_model::{LobeDraws, WaterModel};

/// Strata per side of the fixed grid of lobe directions a [`LobeGaussian`] is matched to.
/// 8 (64 directions) reduced Table 3's error as much as 16 within the seeds' spread, for a
/// quarter of the time (BENCHMARKS.md).
const GRID: u32 = 8;

/// Standard deviations either side beyond which the Gaussian is cut off (and the rest
/// renormalised): it then has a box for support, which bounds the pixels an edge move must
/// revisit. (The lobe's samples stop at the cone that keeps all but `CONE_LOST_MASS` of it,
/// 3.7 deviations of the half vector; what the Gaussian has beyond the cone is never
/// subtracted by a sample, a bias of at most that mass. Measured: 0.07 % of the
/// coefficients, see the test below.)
pub(super) const REACH: f32 = 4.5;

/// A product of normal densities along the plane's axes, scaled to a mass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct LobeGaussian {
    /// Total mass (the lobe's, as estimated by the weights of the grid directions landing
    /// on the plane); 0 for no control variate.
    pub mass: f32,
    pub mean: Vec2,
    pub sd: Vec2,
}

impl LobeGaussian {
    /// No control variate: the plain estimate.
    pub const NONE: LobeGaussian = LobeGaussian {
        mass: 0.0,
        mean: Vec2::ZERO,
        sd: Vec2::ONE,
    };

    pub fn is_none(&self) -> bool {
        self.mass == 0.0
    }

    /// Matched to the lobe directions `dirs` (direction, weight; from
    /// [`lobe_directions`]) of a water point at `start`, out of `count` drawn, as they land
    /// on `plane`.
    pub fn matched(plane: &LightPlane, start: Vec3, dirs: &[(Vec3, f32)], count: usize) -> Self {
        let (mut sw, mut su, mut sv, mut suu, mut svv) = (0f64, 0f64, 0f64, 0f64, 0f64);
        for &(wi, weight) in dirs {
            let Some((_, q)) = plane.hit(start, wi) else {
                continue;
            };
            let (w, qx, qy) = (weight as f64, q.x as f64, q.y as f64);
            sw += w;
            su += w * qx;
            sv += w * qy;
            suu += w * qx * qx;
            svv += w * qy * qy;
        }
        if sw <= 0.0 || count == 0 {
            return LobeGaussian::NONE;
        }
        let (mu, mv) = (su / sw, sv / sw);
        // A lobe landing in one point (never on a real plane) would give a zero width.
        let (vu, vv) = (
            (suu / sw - mu * mu).max(1e-10),
            (svv / sw - mv * mv).max(1e-10),
        );
        let g = LobeGaussian {
            mass: (sw / count as f64) as f32,
            mean: Vec2::new(mu as f32, mv as f32),
            sd: Vec2::new(vu.sqrt() as f32, vv.sqrt() as f32),
        };
        if g.mean.is_finite() && g.sd.is_finite() && g.mass.is_finite() {
            g
        } else {
            LobeGaussian::NONE
        }
    }

    /// The density at `q`.
    pub fn density(&self, q: Vec2) -> f32 {
        if self.is_none() {
            return 0.0;
        }
        let z = (q - self.mean) / self.sd;
        let reach = REACH;
        if z.x.abs() >= reach || z.y.abs() >= reach {
            return 0.0;
        }
        let kept = truncated_mass() as f32;
        self.mass * (-0.5 * z.length_squared()).exp()
            / (std::f32::consts::TAU * self.sd.x * self.sd.y * kept * kept)
    }

    /// The mass inside `r`.
    pub fn mass_inside(&self, r: &Rect) -> f32 {
        if self.is_none() {
            return 0.0;
        }
        (self.mass as f64 * self.share_u(r.u_min, r.u_max) * self.share_v(r.v_min, r.v_max)) as f32
    }

    /// The share of the mass between `lo` and `hi` along u.
    pub fn share_u(&self, lo: f32, hi: f32) -> f64 {
        normal_between(lo, hi, self.mean.x, self.sd.x)
    }

    /// The share of the mass between `lo` and `hi` along v.
    pub fn share_v(&self, lo: f32, hi: f32) -> f64 {
        normal_between(lo, hi, self.mean.y, self.sd.y)
    }

    /// The box beyond which the density counts as zero.
    pub fn reach(&self) -> Rect {
        Rect::around(self.mean, self.sd * REACH)
    }
}

/// The fixed grid's uniform pairs (strata centres, through [`compact_strata`]), drawn by
/// `water_model` under `model` once for every water point that [`lobe_directions`] reads
/// them for.
pub(super) fn grid_draws(water_model: &dyn WaterModel, model: &ReflectionModel) -> LobeDraws {
    let pairs: Vec<Vec2> = (0..GRID * GRID)
        .map(|i| {
            compact_strata(Vec2::new(
                ((i % GRID) as f32 + 0.5) / GRID as f32,
                ((i / GRID) as f32 + 0.5) / GRID as f32,
            ))
        })
        .collect();
    water_model.lobe_draws(model, &pairs)
}

/// The fixed grid of lobe directions (strata centres) of a water point, with their sample
/// weights, and how many were drawn (those the model rejects are left out, as zeros).
/// `grid` is [`grid_draws`] of the same model.
pub(super) fn lobe_directions(
    water_model: &dyn WaterModel,
    model: &ReflectionModel,
    water: &WaterPoint,
    grid: &LobeDraws,
) -> (Vec<(Vec3, f32)>, usize) {
    let mut dirs = Vec::with_capacity(grid.len());
    water_model.reflect_all_drawn(water, model, grid, &mut dirs);
    (dirs, grid.len())
}

/// The normal distribution's mass between `lo` and `hi`.
pub(super) fn normal_between(lo: f32, hi: f32, mean: f32, sd: f32) -> f64 {
    if hi <= lo {
        return 0.0;
    }
    normal_cdf(hi, mean, sd) - normal_cdf(lo, mean, sd)
}

/// The distribution function of the normal distribution truncated to [`REACH`] deviations
/// either side (and renormalised): linear interpolation in a fine table (error below 1e-7,
/// far under the estimates' noise, and many times cheaper than `erfc`; the edge profiles
/// call it millions of times).
#[inline]
pub(super) fn normal_cdf(x: f32, mean: f32, sd: f32) -> f64 {
    const STEPS: usize = 16384;
    static TABLE: std::sync::OnceLock<Vec<f32>> = std::sync::OnceLock::new();
    let reach = REACH;
    let z = (x - mean) / sd;
    if z <= -reach {
        return 0.0;
    }
    if z >= reach {
        return 1.0;
    }
    let table = TABLE.get_or_init(|| {
        let (r, h) = (reach as f64, 2.0 * reach as f64 / STEPS as f64);
        let below = 0.5 * erfc(r / std::f64::consts::SQRT_2);
        let kept = truncated_mass();
        (0..=STEPS)
            .map(|k| {
                let phi = 0.5 * erfc((r - h * k as f64) / std::f64::consts::SQRT_2);
                ((phi - below) / kept) as f32
            })
            .collect()
    });
    let f = (z + reach) * (STEPS as f32 / (2.0 * reach));
    let k = (f as usize).min(STEPS - 1);
    let t = f - k as f32;
    (table[k] + t * (table[k + 1] - table[k])) as f64
}

/// The standard normal's mass within [`REACH`] deviations of its mean.
fn truncated_mass() -> f64 {
    1.0 - erfc(REACH as f64 / std::f64::consts::SQRT_2)
}

/// The complementary error function (Numerical Recipes' `erfcc`, relative error below
/// 1.2e-7 everywhere).
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let r = t * poly.exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

#[cfg(test)]
mod tests {
    use super::super::fixture::table3_light0;
    use super::super::samples::PlaneSamples;
    use super::*;
    use crate::fitting::EdgeSide;

    #[test]
    fn the_distribution_function_matches_known_values() {
        // Phi(0) = 1/2, Phi(1) = 0.841344746, Phi(-2) = 0.022750132, Phi(3) = 0.998650102,
        // Phi(-4.5) = 3.397673e-6 (tables of the normal distribution), truncated to +-4.5.
        let below = 3.397_673e-6;
        let truncated = |phi: f64| (phi - below) / (1.0 - 2.0 * below);
        for (z, phi) in [
            (0.0, 0.5),
            (1.0, 0.841_344_746),
            (-2.0, 0.022_750_132),
            (3.0, 0.998_650_102),
        ] {
            let (got, want) = (normal_cdf(z, 0.0, 1.0), truncated(phi));
            assert!((got - want).abs() < 2e-7, "Phi({z}) = {got}, want {want}");
        }
        // Shifted and scaled.
        assert!((normal_cdf(5.0, 3.0, 2.0) - truncated(0.841_344_746)).abs() < 2e-7);
        assert_eq!(normal_cdf(-10.0, 0.0, 1.0), 0.0);
        assert_eq!(normal_cdf(10.0, 0.0, 1.0), 1.0);
    }

    #[test]
    fn the_mass_inside_a_rectangle_is_the_density_integrated() {
        let g = LobeGaussian {
            mass: 0.7,
            mean: Vec2::new(0.3, -0.2),
            sd: Vec2::new(0.5, 1.5),
        };
        let r = Rect {
            u_min: -0.1,
            u_max: 0.9,
            v_min: -1.0,
            v_max: 2.5,
        };
        // Midpoint rule on a fine grid.
        let n = 800;
        let (du, dv) = (
            (r.u_max - r.u_min) / n as f32,
            (r.v_max - r.v_min) / n as f32,
        );
        let mut sum = 0f64;
        for i in 0..n {
            for j in 0..n {
                let q = Vec2::new(
                    r.u_min + (i as f32 + 0.5) * du,
                    r.v_min + (j as f32 + 0.5) * dv,
                );
                sum += g.density(q) as f64 * (du * dv) as f64;
            }
        }
        let exact = g.mass_inside(&r) as f64;
        assert!(
            (sum - exact).abs() < 1e-5,
            "quadrature {sum}, closed form {exact}"
        );
        assert!(exact > 0.3 && exact < 0.7);
    }

    /// The control variate must leave the coefficients' expectation alone and cut their
    /// noise. Reference: the plain estimate with 1152 samples per pixel (16 times the
    /// default's 72). On Table 3's fitted region (every 8th pixel), over 6 seeds of 72
    /// samples: the mean over seeds and pixels of the coefficients, with and without it, must
    /// agree with the reference to within 0.2 % (the fit moves an edge by about as much as a
    /// coefficient bias; measured well under that), the squared error must fall, and the
    /// derivative by the top edge, which is what moves the fit, far more (measured: to 0.45
    /// and 0.05-0.1 of the plain estimate's, BENCHMARKS.md).
    #[test]
    fn the_control_variate_keeps_the_expectation_and_cuts_the_noise() {
        let t = table3_light0();
        let light = &t.light;
        let pixels = &t.pixels;
        let trace = |samples: u32, seed: u64, cv: bool| t.trace(samples, seed, 0, cv);
        let rect = light.rect();
        let moved = rect.with_edge(EdgeSide::Top, rect.v_max + 0.02);
        // Per pixel: the coefficient and its change as the top edge moves up 2 cm.
        let values = |(planes, n): &(Vec<PlaneSamples>, u32)| -> Vec<(f64, f64)> {
            let inv = 1.0 / *n as f32;
            (0..pixels.len())
                .map(|i| {
                    let (c, _) = planes[0].coefficient(i, &rect, inv);
                    let (m, _) = planes[0].coefficient(i, &moved, inv);
                    (c as f64, (m - c) as f64)
                })
                .collect()
        };
        let reference = values(&trace(1152, 1000, false));
        let total: f64 = reference.iter().map(|r| r.0).sum();
        assert!(total > 0.0, "the region sees the light");
        let mut bias = [0f64; 2];
        let mut value_error = [0f64; 2];
        let mut slope_error = [0f64; 2];
        for seed in 1..=6 {
            for (m, cv) in [false, true].into_iter().enumerate() {
                for (got, want) in values(&trace(72, seed, cv)).iter().zip(&reference) {
                    bias[m] += got.0 - want.0;
                    value_error[m] += (got.0 - want.0).powi(2);
                    slope_error[m] += (got.1 - want.1).powi(2);
                }
            }
        }
        let relative_bias = bias.map(|b| b / (6.0 * total));
        eprintln!(
            "bias plain {:.5} cv {:.5}; squared error cv/plain: value {:.3}, slope {:.3}",
            relative_bias[0],
            relative_bias[1],
            value_error[1] / value_error[0],
            slope_error[1] / slope_error[0]
        );
        assert!(
            relative_bias[0].abs() < 0.002,
            "plain bias {}",
            relative_bias[0]
        );
        assert!(
            relative_bias[1].abs() < 0.002,
            "control variate bias {}",
            relative_bias[1]
        );
        assert!(
            value_error[1] < 0.7 * value_error[0],
            "values: {} against {}",
            value_error[1],
            value_error[0]
        );
        assert!(
            slope_error[1] < 0.3 * slope_error[0],
            "slopes: {} against {}",
            slope_error[1],
            slope_error[0]
        );
    }
}
