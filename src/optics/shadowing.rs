//! The geometry term `G(wo, wi)` of the microfacet model: none (the paper, with an energy cap
//! that only acts near grazing) or Smith shadowing-masking.

/// Which geometry (shadowing-masking) term the reflection model uses. The renderer and the
/// fitter must use the same one (method §4).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Shadowing {
    /// The paper's `G = 1`, capped near grazing views so that energy is conserved:
    /// `G = min(1, (n.h)(n.wo) / (F (wo.h)))`, see [`energy_cap`].
    ///
    /// The cap is needed because with `G = 1` the microfacets' projected area towards `wo`,
    /// `integral D(h) max(0, wo.h) dh = (1 + Lambda(wo)) (n.wo)`, exceeds the surface's own
    /// `n.wo` by the area of the masked facets, so the directional albedo grows like
    /// `1 / (n.wo)` and passes 1 near grazing: at 89 degrees it is 1.46 (e = 10), 1.43 (50),
    /// 1.24 (200), 1.07 (500) with water's Fresnel term. The cap is exactly 1 for every view
    /// more than ~4 degrees above the surface (see [`energy_cap`]), so there this is the
    /// paper's model unchanged.
    #[default]
    None,
    /// Smith's separable shadowing-masking `G = G1(wo) G1(wi)`, with `G1` the Walter et al.
    /// (2007) rational approximation of the Beckmann Smith function at the Blinn-Phong
    /// equivalent roughness `alpha = sqrt(2 / (e + 2))`: see [`smith_g1`].
    Smith,
}

/// The Beckmann roughness `alpha = sqrt(2 / (e + 2))` equivalent to Blinn-Phong exponent `e`
/// (Walter et al. 2007, eq. 30 inverted).
#[inline]
pub fn beckmann_alpha(gloss: f32) -> f32 {
    (2.0 / (gloss + 2.0)).sqrt()
}

/// Smith's masking function `G1(v)` for a direction at `cos_v = n.v` from the normal, gloss
/// `e`: Walter, Marschner, Li and Torrance 2007 ("Microfacet Models for Refraction through
/// Rough Surfaces", eq. 27), the rational approximation of the Beckmann `G1`, with
/// `a = 1 / (alpha tan theta_v)`:
/// `G1 = (3.535 a + 2.181 a^2) / (1 + 2.276 a + 2.577 a^2)` for `a < 1.6`, else 1.
///
/// Used for Blinn-Phong through the equivalent roughness [`beckmann_alpha`]. It does not depend
/// on the half vector; the caller ensures `v.h` and `n.v` have the same sign. Returns 0 for
/// `cos_v <= 0`.
#[inline]
pub fn smith_g1(cos_v: f32, gloss: f32) -> f32 {
    smith_g1_alpha(cos_v, beckmann_alpha(gloss))
}

/// [`smith_g1`] for a Beckmann roughness `alpha` given directly (the statistical water
/// model's lobe, whose roughness depends on the direction's azimuth).
#[inline]
pub fn smith_g1_alpha(cos_v: f32, alpha: f32) -> f32 {
    if cos_v <= 0.0 {
        return 0.0;
    }
    if cos_v >= 1.0 {
        return 1.0;
    }
    let sin_v = (1.0 - cos_v * cos_v).sqrt();
    let a = cos_v / (alpha * sin_v);
    if a >= 1.6 {
        1.0
    } else {
        (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a)
    }
}

/// The geometry term of [`Shadowing::None`]: `min(1, (n.h)(n.wo) / (F (wo.h)))`, the largest
/// `G` for which no importance sample weight `F G (wo.h) / ((n.wo)(n.h))` exceeds 1.
///
/// Why: with `G = 1` the albedo at grazing views exceeds 1 (the model, not the code; see
/// [`Shadowing::None`]). A weight is the ratio of what one sample returns to what it brings, so
/// capping it at 1 bounds the albedo by 1 by construction, for every `wo`, and leaves alone
/// every sample that is physically possible on its own. It acts only when
/// `(n.h)(n.wo) < F(wo.h)(wo.h)`, and for water (`ior` 1.33) `c F(c) <= 0.0603` (at
/// `c = 0.169`), so it never acts for `n.wo >= 0.0603 / cos theta_0`: views more than 3.9
/// degrees above the surface for `e >= 50` (6.2 degrees for `e = 10`).
///
/// It depends on `wo` and not on `wi`, so where it acts `f` is not reciprocal; a symmetric cap
/// (also bounding the weight seen from `wi`) was tried and rejected: it must also cut
/// configurations with a grazing *light*, and changed the coefficient at a 60-80 degree view by
/// 1.5-5 % (e = 10 to 500), where the paper's `G = 1` needs no correction. Nothing in
/// streaklight traces from the lights, so reciprocity near grazing buys nothing.
///
/// Arguments are cosines: `cos_o = n.wo`, `cos_h = n.h`, `cos_oh = wo.h`, and the Fresnel
/// reflectance `fresnel = F(wo.h)`.
#[inline]
pub fn energy_cap(cos_o: f32, cos_h: f32, cos_oh: f32, fresnel: f32) -> f32 {
    let bound = cos_h * cos_o;
    let used = fresnel * cos_oh;
    if used <= bound {
        1.0
    } else {
        bound / used
    }
}

impl Shadowing {
    /// The geometry term `G(wo, wi)` for this choice and gloss `e`, from the cosines
    /// `cos_o = n.wo`, `cos_i = n.wi`, `cos_h = n.h`, `cos_oh = wo.h` and `fresnel = F(wo.h)`.
    #[inline]
    pub fn g(
        self,
        gloss: f32,
        cos_o: f32,
        cos_i: f32,
        cos_h: f32,
        cos_oh: f32,
        fresnel: f32,
    ) -> f32 {
        match self {
            Shadowing::None => energy_cap(cos_o, cos_h, cos_oh, fresnel),
            Shadowing::Smith => smith_g1(cos_o, gloss) * smith_g1(cos_i, gloss),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn g1_limits_and_continuity() {
        assert_eq!(smith_g1(1.0, 500.0), 1.0);
        assert_eq!(smith_g1(0.0, 500.0), 0.0);
        assert_eq!(smith_g1(-0.3, 500.0), 0.0);
        // The approximation is continuous at a = 1.6 (Walter et al. chose the constants so):
        // evaluate just either side of the switch.
        let e = 50.0;
        let alpha = beckmann_alpha(e);
        let cos_at = |a: f32| {
            let t = 1.0 / (alpha * a); // tan theta
            1.0 / (1.0 + t * t).sqrt()
        };
        let below = smith_g1(cos_at(1.5999), e);
        let above = smith_g1(cos_at(1.6001), e);
        assert!((below - above).abs() < 1e-4, "{below} vs {above}");
        // Monotone in the angle, and rougher surfaces mask more.
        let mut last = 0.0;
        for k in 1..=100 {
            let g = smith_g1(k as f32 / 100.0, e);
            assert!(g >= last, "G1 not monotone at cos = {}", k as f32 / 100.0);
            last = g;
        }
        assert!(smith_g1(0.1, 10.0) < smith_g1(0.1, 1000.0));
    }

    #[test]
    fn g1_matches_the_exact_beckmann_value() {
        // Exact Beckmann Smith G1 = 2 / (1 + erf(a) + exp(-a^2) / (a sqrt(pi))). At a = 1 it is
        // 2 / (1 + 0.8427008 + 0.3678794 / 1.7724539) = 0.9811. Walter et al. quote the rational
        // fit as good to better than 0.35 % relative.
        let e = 98.0; // alpha = sqrt(2/100)
        let alpha = beckmann_alpha(e);
        let cos = 1.0 / (1.0 + 1.0 / (alpha * alpha)).sqrt(); // a = 1
        let exact = 2.0 / (1.0 + 0.842_700_8 + 0.367_879_4 / 1.772_453_9);
        let g = smith_g1(cos, e);
        assert!((g - exact).abs() / exact < 3.5e-3, "{g} vs {exact}");
    }

    #[test]
    fn cap_is_one_unless_a_sample_would_gain_energy() {
        // Mirror-like configuration at 60 degrees: F ~ 0.06, nothing to cap.
        assert_eq!(energy_cap(0.5, 1.0, 0.5, 0.06), 1.0);
        // Grazing view, facet turned towards the viewer: capped so the weight
        // F (wo.h) G / ((n.wo)(n.h)) is exactly 1.
        let (co, ch, coh, f) = (0.02, 0.95, 0.3, 0.2);
        let g = energy_cap(co, ch, coh, f);
        assert!(g < 1.0);
        let w = f * coh * g / (co * ch);
        assert!((w - 1.0).abs() < 1e-6, "{w}");
    }

    #[test]
    fn cap_never_acts_a_few_degrees_above_the_surface() {
        // The documented threshold: c F(c) <= 0.0603 for water, so (n.h)(n.wo) >= 0.0603 is
        // never capped. Scan every wo.h with n.h (n.wo) just above the threshold.
        let bound = 0.0604;
        let mut worst = 0.0f32;
        for k in 0..=100_000 {
            let c = k as f32 / 100_000.0;
            let f = crate::optics::fresnel_dielectric(c, 1.33);
            worst = worst.max(c * f);
            assert_eq!(energy_cap(bound, 1.0, c, f), 1.0, "capped at wo.h = {c}");
        }
        // ... and the threshold is tight, so the docs' numbers are right.
        assert!(worst > 0.0601, "max c F(c) = {worst}");
    }
}
