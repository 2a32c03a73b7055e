//! Fresnel reflectance of a smooth dielectric interface, for light arriving from air.

/// Exact reflectance of s- and p-polarised light, `(R_s, R_p)`, arriving from air (index 1) at
/// an interface with a medium of index `ior`, with `cos_i` the cosine of the angle of
/// incidence (for the microfacet model, `wo.h`).
///
/// For `ior < 1` total internal reflection gives `(1, 1)`. `cos_i` is clamped to [0, 1]:
/// grazing incidence reflects everything.
#[inline]
pub fn fresnel_dielectric_sp(cos_i: f32, ior: f32) -> (f32, f32) {
    let c = cos_i.clamp(0.0, 1.0);
    let sin2_t = (1.0 - c * c) / (ior * ior);
    if sin2_t >= 1.0 {
        return (1.0, 1.0);
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (c - ior * cos_t) / (c + ior * cos_t);
    let rp = (ior * c - cos_t) / (ior * c + cos_t);
    (rs * rs, rp * rp)
}

/// Exact unpolarised reflectance `(R_s + R_p) / 2` of light arriving from air at a medium of
/// index `ior` (water: 1.33), with `cos_i` the cosine of the angle of incidence.
///
/// Uses Cook and Torrance's (1982) closed form with `g = sqrt(ior^2 - 1 + c^2)`, which is the
/// same quantity as [`fresnel_dielectric_sp`] averaged, with one square root fewer.
#[inline]
pub fn fresnel_dielectric(cos_i: f32, ior: f32) -> f32 {
    let c = cos_i.clamp(0.0, 1.0);
    let g2 = ior * ior - 1.0 + c * c;
    if g2 <= 0.0 {
        return 1.0;
    }
    let g = g2.sqrt();
    let a = (g - c) / (g + c);
    let b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    0.5 * a * a * (1.0 + b * b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_form_matches_the_polarised_average() {
        // (Not ior -> 1: there g -> c and both forms lose f32 digits to cancellation.)
        for ior in [1.1, 1.33, 1.5, 2.4] {
            for k in 0..=1000 {
                let c = k as f32 / 1000.0;
                let (rs, rp) = fresnel_dielectric_sp(c, ior);
                let f = fresnel_dielectric(c, ior);
                // Two f32 evaluations of the same quantity, each good to a few ulps.
                assert!(
                    (f - 0.5 * (rs + rp)).abs() < 2e-6,
                    "ior {ior} cos {c}: {f} vs {rs} {rp}"
                );
            }
        }
    }

    #[test]
    fn total_internal_reflection() {
        assert_eq!(fresnel_dielectric_sp(0.1, 0.75), (1.0, 1.0));
        assert_eq!(fresnel_dielectric(0.1, 0.75), 1.0);
    }
}
