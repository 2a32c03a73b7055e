//! The reflection model of method §4: how a point of the water surface reflects the light of
//! the lights towards the camera, and the importance sampler the renderer and the fitter share.
//!
//! Conventions: `n` is the unit surface normal (the interpolated vertex normal), `wo` the unit
//! direction towards the camera, `wi` the unit direction towards the light,
//! `h = normalize(wo + wi)`. The BRDF is
//!
//! ```text
//! f(wo, wi) = D(h) F(wo.h) G(wo, wi) / (4 (n.wo)(n.wi))
//! ```
//!
//! with the paper's Blinn-Phong `D` ([`blinn_phong_d`]), the exact unpolarised dielectric
//! Fresnel term ([`fresnel_dielectric`]) and a geometry term chosen by [`Shadowing`].
//!
//! # Sampling
//!
//! Half vectors are drawn with `cos theta_h = xi^(1/(e+2))`, whose density is exactly
//! `D(h) (n.h)`, and `wi` is `wo` mirrored about `h`. The sample weight
//! `f (n.wi) / pdf(wi)` then simplifies to `F G (wo.h) / ((n.wo)(n.h))`: no power of `n.h`
//! is needed to sample, so the renderer's hot loop stays in f32.
//!
//! # The truncation cone (paper §4.3.1)
//!
//! The paper confines half vectors to a cone of half-angle `theta_0` about `n`, so that every
//! sampled ray lands inside a bounded footprint on a light's plane. Here `theta_0` is chosen so
//! that the cone holds all but [`CONE_LOST_MASS`] = 1e-3 of the half-vector sampling density:
//! since `P(cos theta_h < c) = c^(e+2)`, `cos theta_0 = (1e-3)^(1/(e+2))`
//! ([`ReflectionModel::cone_cos_theta`]). Sampling draws `xi` uniformly in [1e-3, 1], i.e.
//! from the density renormalised to the cone, and multiplies every weight by `1 - 1e-3`; the
//! estimator is then unbiased for the integral of `f (n.wi)` over the `wi` whose half vector
//! lies in the cone. That integral is the model: [`ReflectionModel::eval_cos`] and
//! [`ReflectionModel::pdf`] are zero outside the cone too. It is smaller than the untruncated
//! one by at most ~1e-3 of the albedo (exactly 1e-3 of the projected facet area, weighted by
//! `F G (wo.h)/((n.wo)(n.h))`, which varies slowly over the lobe).
//!
//! # Energy
//!
//! With the paper's `G = 1` the albedo exceeds 1 near grazing views (it is the model, not the
//! code: the facets' projected area exceeds the surface's by the masked facets, by the factor
//! `1 + Lambda(wo)` of Smith's theory; 1.46 at 89 degrees for e = 10). [`Shadowing::None`]
//! therefore caps `G` so that no sample weight exceeds 1, which bounds the albedo by 1 by
//! construction and leaves the paper's model unchanged for every view more than ~4 degrees above
//! the surface; see [`energy_cap`]. [`Shadowing::Smith`] needs no cap (its albedo stays below
//! 0.77 everywhere tested, up to 89 degrees).

mod coefficient;
mod frame;
mod fresnel;
mod gaussian_slopes;
mod lobe;
mod microfacet;
mod shadowing;

pub use coefficient::reflection_coefficient;
pub use frame::orthonormal_basis;
pub use fresnel::{fresnel_dielectric, fresnel_dielectric_sp};
pub use gaussian_slopes::{GaussianSlopes, SlopeDraw, SlopeView};
pub use lobe::{compact_strata, HalfDraw, LobeSample, ReflectionModel};
pub use microfacet::{blinn_phong_d, cone_cos_theta, CONE_LOST_MASS};
pub use shadowing::{beckmann_alpha, energy_cap, smith_g1, smith_g1_alpha, Shadowing};
