//! The normalised Blinn-Phong microfacet distribution of the paper (eq. 3), and the cone that
//! truncates it (§4.3.1).

/// Fraction of the half-vector sampling density left outside the truncation cone.
///
/// The half vector is sampled with `cos theta_h = xi^(1/(e+2))`, so
/// `P(cos theta_h < c) = c^(e+2)`. The cone `cos theta_h >= CONE_LOST_MASS^(1/(e+2))` therefore
/// holds all but this fraction of the sampling density (which is the density of the projected
/// microfacet area, `D(h) (n.h)`). See the [module docs](super) for what this means for
/// the estimator.
pub const CONE_LOST_MASS: f64 = 1e-3;

/// The Blinn-Phong normal distribution `D(h) = (e + 2) / (2 pi) (n.h)^e` (paper eq. 3), per
/// steradian of half vector, normalised so that `integral D(h) (n.h) dh = 1` over the
/// hemisphere.
///
/// Takes `cos_theta_h = n.h` and the gloss exponent `e` in f64: with `e` in the thousands,
/// `(n.h)^e` is a large power of a number within ~1e-4 of one, and f32 would lose a good share
/// of its digits in `n.h` alone. Returns 0 for `n.h <= 0` (no facets face away from `n`).
#[inline]
pub fn blinn_phong_d(cos_theta_h: f64, gloss: f64) -> f64 {
    if cos_theta_h <= 0.0 {
        return 0.0;
    }
    // exp(e ln c) rather than powf only for clarity of intent: both are exact to ~1 ulp here.
    (gloss + 2.0) * std::f64::consts::FRAC_1_PI * 0.5 * (gloss * cos_theta_h.ln()).exp()
}

/// `cos theta_0`, the cosine of the truncation cone's half-angle about the normal, for gloss
/// `e`: `CONE_LOST_MASS^(1/(e+2))`.
#[inline]
pub fn cone_cos_theta(gloss: f64) -> f64 {
    (CONE_LOST_MASS.ln() / (gloss + 2.0)).exp()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `integral D (n.h) dh = 2 pi integral_c_min^1 D(c) c dc` by the midpoint rule in
    /// s = 1 - c, over s <= 60 / e at most: beyond, c^(e+1) < e^-60.
    fn projected_mass(gloss: f64, c_min: f64) -> f64 {
        let n = 200_000;
        let ds = (1.0 - c_min).min(60.0 / gloss.max(1.0)) / n as f64;
        let mut sum = 0.0;
        for k in 0..n {
            let c = 1.0 - (k as f64 + 0.5) * ds;
            sum += blinn_phong_d(c, gloss) * c;
        }
        sum * ds * std::f64::consts::TAU
    }

    #[test]
    fn d_is_normalised() {
        // Midpoint rule with 2e5 steps over at most 60 / e: >= 3000 steps per 1/e, the lobe's
        // width, so the error is ~1e-9.
        for e in [0.0, 1.0, 10.0, 500.0, 5000.0] {
            let m = projected_mass(e, 0.0);
            assert!((m - 1.0).abs() < 1e-6, "e = {e}: integral D cos = {m}");
        }
    }

    #[test]
    fn cone_holds_all_but_the_lost_mass() {
        for e in [10.0, 50.0, 500.0, 5000.0] {
            let c0 = cone_cos_theta(e);
            let inside = projected_mass(e, c0);
            assert!(
                (inside - (1.0 - CONE_LOST_MASS)).abs() < 1e-6,
                "e = {e}: cone mass {inside}"
            );
        }
    }

    #[test]
    fn d_at_the_peak_and_below_the_surface() {
        let e = 500.0;
        assert!((blinn_phong_d(1.0, e) - 502.0 / std::f64::consts::TAU).abs() < 1e-9);
        assert_eq!(blinn_phong_d(0.0, e), 0.0);
        assert_eq!(blinn_phong_d(-0.5, e), 0.0);
        // No underflow to garbage at the cone edge for the largest gloss we support.
        let c0 = cone_cos_theta(5000.0);
        let d = blinn_phong_d(c0, 5000.0) / blinn_phong_d(1.0, 5000.0);
        assert!((d - 1e-3f64.powf(5000.0 / 5002.0)).abs() < 1e-9, "{d}");
    }
}
