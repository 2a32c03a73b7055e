//! How far the statistical model's lights can be trusted (method §10).
//!
//! The joint fit's uncertainties assume each pixel's residual independent of its neighbours'.
//! Under the statistical model the residual is the photo's glitter about its expectation, and
//! a wave facet lights many neighbouring pixels at once: near the camera, in the paper's close
//! geometry, one of the longest waves tilts a whole streak. So the residual's correlation is
//! measured, and every uncertainty grows by the square root of its correlation area (the
//! pixels per independent residual: the sum of the residual's autocorrelation over lags up
//! to [`MAX_LAG`] pixels each way, at least 1), the effective sample size argument for a
//! least-squares fit with correlated errors.
//!
//! The lights also move with the slope variances, which are estimated with an uncertainty of
//! their own: each light parameter's derivative by the logarithm of each variance (a
//! least-squares line through the search's last pass on that axis, every fit of which
//! re-optimised the lights) times that variance's uncertainty is added in quadrature.

use rayon::prelude::*;

use crate::fitting::joint::{PixelShare, Uncertainty};
use crate::fitting::{EdgeSide, FittedLight};
use crate::pixel_index::PixelIndex;

/// The largest lag, in pixels along each axis, of the residual's correlation area on the
/// samples' photos; on a finer photo it grows with the rows per degree
/// ([`crate::pixel_scale`]), so that it spans the same angle.
pub const MAX_LAG: i64 = 8;

/// The residual's correlation area, in pixels read: the sum of its autocorrelation over lags
/// within `max_lag` each way (lag 0 counts 1), over the fitted pixels `modelled` of a
/// `width`-wide `photo` (sum of channels), read as `share` reads the water; at least 1. A lag
/// between two pixels of the share is on its lattice, so only those lags are summed.
pub fn correlation_area(
    photo: &[[f32; 3]],
    width: u32,
    modelled: &[(u32, [f32; 3])],
    max_lag: i64,
    share: PixelShare,
) -> f64 {
    let w = width as i64;
    // In the order given, so that every sum is taken in one order (determinism); the index
    // only finds a pixel's neighbours.
    let residual: Vec<(i64, f64)> = modelled
        .iter()
        .map(|&(p, m)| {
            let o = photo.get(p as usize).copied().unwrap_or([0.0; 3]);
            let r = (o[0] + o[1] + o[2]) as f64 - (m[0] + m[1] + m[2]) as f64;
            (p as i64, r)
        })
        .collect();
    if residual.len() < 2 || w == 0 {
        return 1.0;
    }
    let n_all = residual.len() as f64;
    let mean = residual.iter().map(|r| r.1).sum::<f64>() / n_all;
    let var = residual.iter().map(|r| (r.1 - mean).powi(2)).sum::<f64>() / n_all;
    if var <= 0.0 {
        return 1.0;
    }
    let index = PixelIndex::new(modelled.iter().map(|m| m.0), width);
    let lags: Vec<(i64, i64)> = (-max_lag..=max_lag)
        .flat_map(|dy| (-max_lag..=max_lag).map(move |dx| (dx, dy)))
        .filter(|&(dx, dy)| share.lag_between_read(dx, dy))
        .collect();
    let by_lag: Vec<f64> = lags
        .par_iter()
        .map(|&(dx, dy)| {
            let (mut sum, mut n) = (0.0, 0usize);
            for &(p, r) in &residual {
                if let Some(j) = index.at(p % w + dx, p / w + dy) {
                    let s = residual[j].1;
                    sum += (r - mean) * (s - mean);
                    n += 1;
                }
            }
            if n > 0 {
                sum / n as f64 / var
            } else {
                0.0
            }
        })
        .collect();
    by_lag.iter().sum::<f64>().max(1.0)
}

/// The relative uncertainty, at least, of a radiance the reflections alone give under the
/// statistical model: how far one realisation of the waves moves the light a streak holds
/// from the model's expectation over all of them. No residual shows it: the fit explains
/// the whole streak's light by the radiance (docs/decisions.md). Measured by `cargo bench
/// --bench realisations` (BENCHMARKS.md): the harbour's sign, its image clipped in every
/// channel, rendered over 16 wave fields of the harbour's statistics and fitted against the
/// flat quad, came out 7.8 % rms off (from 20.0 % low to 11.3 % high, mean -1.6 %); Table 1's
/// lamp, close to the water, 5.2 % low on average with 1.9 % of scatter. 10 % covers both as
/// one sigma: the largest, 20.0 % low, is 2.5 sigmas of the radiance it was fitted at.
pub const REALISATION_FLUX: f64 = 0.10;

/// The uncertainty, at least, of the natural logarithm of each slope variance estimated from
/// the photo (along, across the view), as a description of the water the streaks reflect: the
/// search's own sigma is the photo's noise about the best Gaussian lobe, and says nothing of
/// how far one realisation's waves under a streak are from a Gaussian lobe. Measured by
/// `cargo bench --bench realisations` (BENCHMARKS.md): over 16 wave fields of the harbour's
/// statistics, the sign's estimates against each field's mesh under its streak
/// ([`crate::samples::streak_slopes::lobe_under_streaks`]) were off by 0.24 (along) and 0.43
/// (across) in the logarithm, rms, where the search's sigmas were 0.03-0.11 and 0.05-0.33: up
/// to 12.8 sigmas off. The lights do not take this on (`widen` carries the search's own
/// sigma into them): their scatter over realisations is [`REALISATION_FLUX`]'s.
pub const SLOPE_REALISATION_LN: [f32; 2] = [0.24, 0.43];

/// Every radiance sigma of a light whose radiance the reflections alone give (not
/// [`Uncertainty::radiance_seen`]) raised to at least [`REALISATION_FLUX`] of that radiance
/// (`radiance`: per light, in the order of `uncertainty`). The floor is rounded down to an
/// `f32`, so that it never reaches above [`REALISATION_FLUX`] by rounding. It lies above
/// the report's large uncertainty ([`crate::report::LARGE_UNCERTAINTY`], 5 %): such a light
/// is always warned about, with what would let the photo give its radiance.
///
/// The relative variance the floor adds to the light's strongest channel is a scale error of
/// its radiance, and it carries into each edge by its
/// [`radiance_response`](Uncertainty::radiance_response): Table 1 over a flat quad (its
/// radiance 7.5 % low) put its bottom edge 0.74 mm off, where the fit's own sigma, the lamp's
/// image alone, was 0.24 mm.
pub fn realisation_floor(uncertainty: &mut [Uncertainty], radiance: &[[f32; 3]]) {
    for (u, light) in uncertainty.iter_mut().zip(radiance) {
        if u.radiance_seen {
            continue;
        }
        let strongest = (0..3)
            .max_by(|&a, &b| light[a].abs().total_cmp(&light[b].abs()))
            .unwrap_or(0);
        let l = light[strongest].abs() as f64;
        if l > 0.0 {
            let own = u.radiance[strongest] as f64 / l;
            let added = (REALISATION_FLUX * REALISATION_FLUX - own * own).max(0.0);
            for side in EdgeSide::ALL {
                let response = u.radiance_response[side as usize];
                u.edges[side] =
                    u.edges[side].map(|sd| (sd as f64).hypot(response * added.sqrt()) as f32);
            }
            u.bound_by_image();
        }
        for (sd, l) in u.radiance.iter_mut().zip(light) {
            let exact = REALISATION_FLUX * l.abs() as f64;
            let mut floor = exact as f32;
            if floor as f64 > exact {
                floor = floor.next_down();
            }
            *sd = sd.max(floor);
        }
    }
}

/// The least-squares slope of each light's parameters (left, right, bottom, top edges, then
/// the three radiances) against `x`, over `points` (x and the lights fitted there, all with
/// the same lights in the same order); `None` with fewer than two distinct x.
pub fn parameter_slopes(points: &[(f64, Vec<FittedLight>)]) -> Option<Vec<[f64; 7]>> {
    let n = points.len() as f64;
    if points.len() < 2 {
        return None;
    }
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if sxx <= 1e-12 {
        return None;
    }
    let lights = points[0].1.len();
    if points.iter().any(|p| p.1.len() != lights) {
        return None;
    }
    let params = |l: &FittedLight| -> [f64; 7] {
        [
            l.u_min as f64,
            l.u_max as f64,
            l.v_min as f64,
            l.v_max as f64,
            l.radiance[0] as f64,
            l.radiance[1] as f64,
            l.radiance[2] as f64,
        ]
    };
    Some(
        (0..lights)
            .map(|k| {
                let mut slope = [0.0; 7];
                let mean: Vec<f64> = (0..7)
                    .map(|i| points.iter().map(|p| params(&p.1[k])[i]).sum::<f64>() / n)
                    .collect();
                for (i, s) in slope.iter_mut().enumerate() {
                    let sxy: f64 = points
                        .iter()
                        .map(|p| (p.0 - mx) * (params(&p.1[k])[i] - mean[i]))
                        .sum();
                    *s = sxy / sxx;
                }
                slope
            })
            .collect(),
    )
}

/// `uncertainty` of each light with the water's share of every variance grown by `area` (the
/// residual's correlation area: the glitter's pixels are not independent, the pixels that see
/// a light directly are, and so is a colour ratio;
/// [`VarianceParts`](crate::fitting::joint::VarianceParts)), and the slope variances'
/// uncertainties `sigma_ln` (already so grown) carried through the parameters' `slopes` by
/// `ln` variance, per axis. Unconstrained edges stay unconstrained, and an edge the light's
/// direct image bounds stays within that bound ([`Uncertainty::bound_by_image`]).
pub fn widen(
    uncertainty: &mut [Uncertainty],
    area: f64,
    slopes: [Option<&Vec<[f64; 7]>>; 2],
    sigma_ln: [Option<f32>; 2],
) {
    for (k, u) in uncertainty.iter_mut().enumerate() {
        let carried = |i: usize| -> f64 {
            (0..2)
                .map(|a| match (slopes[a].and_then(|s| s.get(k)), sigma_ln[a]) {
                    (Some(s), Some(sd)) => (s[i] * sd as f64).powi(2),
                    _ => 0.0,
                })
                .sum()
        };
        u.widen(area.max(1.0), carried);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fitting::joint::VarianceParts;

    /// White noise has a correlation area of 1; noise constant over 2 x 2 blocks, of 4 (the
    /// pixels per independent value: 1 + 4 x 1/2 + 4 x 1/4). The estimate sums 289 lags'
    /// sample correlations, each off by about sqrt(4 / 65536): some 0.3 in all.
    #[test]
    fn correlation_area_counts_pixels_per_independent_value() {
        let (w, h) = (256u32, 256u32);
        let mut rng = crate::random::Rng::new(7, 0);
        let noise: Vec<f32> = (0..w * h).map(|_| rng.next_f64() as f32 - 0.5).collect();
        let white: Vec<[f32; 3]> = noise.iter().map(|&v| [v; 3]).collect();
        let blocks: Vec<[f32; 3]> = (0..w * h)
            .map(|p| [noise[((p % w) / 2 + w * ((p / w) / 2)) as usize]; 3])
            .collect();
        let zero: Vec<(u32, [f32; 3])> = (0..w * h).map(|p| (p, [0.0; 3])).collect();
        let area = |photo: &[[f32; 3]]| correlation_area(photo, w, &zero, MAX_LAG, PixelShare::All);
        let (a, b) = (area(&white), area(&blocks));
        assert!(a < 1.6, "{a}");
        assert!((b - 4.0).abs() < 0.8, "{b}");
        // Read one pixel of each 2 x 2 block, the block noise is white again: each pixel read
        // is an independent value, so the area in pixels read is 1, not 4. Read on a
        // checkerboard, a block's two pixels read are diagonal neighbours along (1, 1): the
        // lags (1, 1) and (-1, -1) each pair half the pixels read with their block's other,
        // the lags (1, -1) and (-1, 1) none, so 1 + 2 x 1/2 = 2.
        let read = |share: PixelShare| -> Vec<(u32, [f32; 3])> {
            zero.iter()
                .copied()
                .filter(|&(p, _)| share.reads(p % w, p / w))
                .collect()
        };
        let quarter = correlation_area(
            &blocks,
            w,
            &read(PixelShare::WaterBlocks(2)),
            MAX_LAG,
            PixelShare::WaterBlocks(2),
        );
        let half = correlation_area(
            &blocks,
            w,
            &read(PixelShare::Checkerboard),
            MAX_LAG,
            PixelShare::Checkerboard,
        );
        assert!(quarter < 1.6, "{quarter}");
        assert!((half - 2.0).abs() < 0.5, "{half}");
    }

    #[test]
    fn slopes_of_a_line_and_widening_in_quadrature() {
        use crate::fitting::light_plane::LightPlane;
        use crate::fitting::EdgeStatus;
        use glam::Vec3;
        let plane = LightPlane::with_frame((0, 0, 0), Vec3::ZERO, Vec3::Z, Vec3::X, 1.0).unwrap();
        let light = |x: f64| FittedLight {
            streak_ids: vec![0],
            plane: plane.clone(),
            u_min: (1.0 + 0.5 * x) as f32,
            u_max: 3.0,
            v_min: 0.0,
            v_max: 2.0,
            radiance: [(10.0 - 2.0 * x) as f32; 3],
            edges: std::array::from_fn(|_| EdgeStatus::Constrained { pixels: 1 }),
        };
        let pts: Vec<(f64, Vec<FittedLight>)> = [-0.2, 0.0, 0.3]
            .iter()
            .map(|&x| (x, vec![light(x)]))
            .collect();
        let s = parameter_slopes(&pts).unwrap();
        assert!(
            (s[0][0] - 0.5).abs() < 1e-5 && (s[0][4] + 2.0).abs() < 1e-4,
            "{s:?}"
        );
        let water = |sd: f64| {
            Some(VarianceParts {
                water: sd * sd,
                other: 0.0,
            })
        };
        // Red: half its variance from the water, half from the lamp's image.
        let red = VarianceParts {
            water: 0.005,
            other: 0.005,
        };
        let mut u = vec![Uncertainty {
            edges: [Some(0.03), None, Some(0.01), Some(0.01)],
            radiance: [0.1; 3],
            direct_pixels: 0,
            radiance_seen: false,
            image_bound: [None, None, Some(0.015), None],
            parts: [
                water(0.03),
                None,
                water(0.01),
                water(0.01),
                Some(red),
                water(0.1),
                water(0.1),
            ],
            radiance_response: [0.0; 4],
        }];
        widen(&mut u, 4.0, [Some(&s), None], [Some(0.1), None]);
        // Left: (0.03 * 2)^2 + (0.5 * 0.1)^2; green: (0.1 * 2)^2 + (2 * 0.1)^2.
        assert!((u[0].edges[EdgeSide::Left].unwrap() - 0.0781).abs() < 1e-3);
        assert_eq!(u[0].edges[EdgeSide::Right], None);
        // Bottom: 0.01 * 2, more than its image allows; top: 0.01 * 2.
        assert_eq!(u[0].edges[EdgeSide::Bottom], Some(0.015));
        assert!((u[0].edges[EdgeSide::Top].unwrap() - 0.02).abs() < 1e-6);
        assert!((u[0].radiance[1] - 0.2828).abs() < 1e-3);
        // Red: 4 x 0.005 + 0.005 + (2 * 0.1)^2 = 0.065; grown whole it would be 0.08.
        assert!((u[0].radiance[0] - 0.065f32.sqrt()).abs() < 1e-5);
    }

    #[test]
    fn radiances_the_reflections_alone_give_get_the_realisations_floor() {
        let lights = [[20.0, 10.0, 0.0]; 2];
        let sigma = |seen: bool| Uncertainty {
            edges: [Some(0.01); 4],
            radiance: [0.3, 1.6, 0.0],
            direct_pixels: 0,
            radiance_seen: seen,
            image_bound: [None; 4],
            parts: [None; 7],
            radiance_response: [0.1, 0.0, 0.0, 0.0],
        };
        let mut u = vec![sigma(false), sigma(true)];
        realisation_floor(&mut u, &lights);
        // Unseen: 10 % of 20 is 2.0 (above 0.3); 10 % of 10 is 1.0 (below 1.6, kept).
        assert!((u[0].radiance[0] - 2.0).abs() < 1e-6, "{:?}", u[0].radiance);
        assert_eq!(u[0].radiance[1..], [1.6, 0.0]);
        // Never above 10 % by rounding, over many radiances.
        for i in 1..2000 {
            let l = 0.37 * i as f32;
            let mut v = vec![sigma(false)];
            v[0].radiance = [0.0; 3];
            realisation_floor(&mut v, &[[l; 3]]);
            let sd = v[0].radiance[0] as f64;
            assert!(sd <= REALISATION_FLUX * l as f64, "{l}: {sd}");
            assert!(sd > 0.999_999 * REALISATION_FLUX * l as f64, "{l}: {sd}");
        }
        // The left edge moves 0.1 m per unit scale: the floor adds 0.1^2 - (0.3 / 20)^2 of
        // relative variance to the strongest channel, so 0.1^2 times that to the edge.
        let left = (0.01f64.powi(2) + 0.01 * (0.01 - 0.015f64.powi(2))).sqrt();
        assert!((u[0].edges[EdgeSide::Left].unwrap() as f64 - left).abs() < 1e-6);
        assert_eq!(u[0].edges[1..], [Some(0.01); 3]);
        assert_eq!(u[1].edges, [Some(0.01); 4]);
        // Seen: left as it was.
        assert_eq!(u[1].radiance, [0.3, 1.6, 0.0]);
    }
}
