//! The glitter's noise, for a fit over water whose waves the scene does not hold.
//!
//! Under a statistical water model the photo is one draw of the glitter about the expected
//! image. A water pixel whose footprint holds few wave facets shows a glint or nothing, one
//! whose footprint holds many shows nearly the expectation: for facets that each reflect the
//! light or not, a pixel's variance about its expectation `m` is about `m (g - m) / N`, `g` a
//! glint's brightness and `N` the facets in its footprint, so about `a m / A + b` with `A` the
//! footprint's area on the water (facets of one size) and `b` the photo's own noise. The
//! unweighted fit lets the few large near waves, whose draw moves their rows' light by tens
//! of percent, outweigh the many far rows that hold the expectation.
//!
//! [`glitter_scales`] measures `a` and `b` from a first fit's residual (least squares of the
//! squared residual on `m / A` and 1 over the water pixels) and gives each water pixel the
//! scale `1 / sqrt(a m / A + b)` (normalised to a mean square of 1), by which the fit's
//! observations and coefficients are multiplied: weighted least squares, as ordinary least
//! squares over scaled rows. Pixels that see a light directly keep a scale of 1.
//!
//! Which residual: an unweighted descent's, after which the fit descends again weighted;
//! or, where every light starts on its lamp's whole direct image or where a search fit put
//! it, the start's (its radiances solved), and the fit descends once. Such a start's edges
//! lie within a pixel's footprint of the optimum, so the squared residual it leaves is the
//! glitter's but for a few rows along the edges, which the least squares over every water
//! pixel hardly feel: on the harbour's in-frame photos the lights came out as the two
//! descents put them to 0.1 % of their size and radiance, the slope variances within 2.5 %,
//! and the fits took 3-14 % less time (docs/decisions.md).

use super::problem::{Problem, State};
use super::samples::PlaneSamples;
use crate::scene_in::Scene;
use crate::water_model::WaterModel;

/// The fitted variance model `a m / A + b` (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct GlitterNoise {
    /// The glitter's term, per unit of expected radiance over footprint area.
    pub glint: f64,
    /// The floor (the photo's own noise), per pixel and channel sum.
    pub floor: f64,
}

/// The footprint area on the water of each of `problem`'s water pixels, relative: the
/// squared distance to the camera over the cosine of the view on the water (the camera ray
/// through the pixel's centre); `None` for a pixel whose centre sees no water.
pub(super) fn footprint_areas(
    water_model: &dyn WaterModel,
    scene: &Scene,
    problem: &Problem,
    height: u32,
) -> Vec<Option<f64>> {
    use rayon::prelude::*;
    problem.pixel_ids[..problem.first_direct]
        .par_iter()
        .map(|&p| {
            let (x, y) = (p % problem.width, p / problem.width);
            let w = water_model.water_point(
                scene,
                x as f32 + 0.5,
                y as f32 + 0.5,
                problem.width,
                height,
            )?;
            let cos = w.wo.dot(w.face).abs() as f64;
            (cos > 1e-6).then(|| w.start.length_squared() as f64 / cos)
        })
        .collect()
}

/// The variance model fitted to `st`'s residual over the water pixels with an area
/// (unclipped ones), and the per-pixel scales it gives (module doc); `None` when the
/// residual shows no glitter term (`a` not positive) or too few pixels.
pub(super) fn glitter_scales(
    problem: &Problem,
    st: &State,
    areas: &[Option<f64>],
) -> Option<(GlitterNoise, Vec<f32>)> {
    // Per usable pixel: (m / A, squared residual), channels summed.
    let rows: Vec<(usize, f64, f64)> = (0..problem.first_direct)
        .filter(|&i| !problem.clipped[i])
        .filter_map(|i| {
            let area = areas.get(i).copied().flatten()?;
            let m = problem.model(st, i);
            let o = problem.obs[i];
            let r2: f64 = (0..3).map(|c| (o[c] as f64 - m[c]).powi(2)).sum();
            let expected: f64 = m.iter().map(|v| v.max(0.0)).sum();
            Some((i, expected / area, r2))
        })
        .collect();
    let noise = fit_variance(rows.iter().map(|r| (r.1, r.2)))?;
    let var = |x: f64| noise.glint * x + noise.floor;
    let mut scales = vec![1f32; problem.n()];
    let mean_weight = rows.iter().map(|r| 1.0 / var(r.1)).sum::<f64>() / rows.len() as f64;
    // Pixels left out of the measurement (clipped, or no water at their centre) keep the
    // mean weight.
    for &(i, x, _) in &rows {
        scales[i] = (1.0 / (var(x) * mean_weight)).sqrt() as f32;
    }
    Some((noise, scales))
}

/// The glitter's noise measured on `st`'s residual ([`glitter_scales`]) and `problem`'s
/// rows scaled by it ([`scale_rows`]): the scales, or `None` with nothing scaled.
pub(super) fn weigh(
    water_model: &dyn WaterModel,
    scene: &Scene,
    problem: &mut Problem,
    st: &State,
    height: u32,
) -> Option<Vec<f32>> {
    let areas = footprint_areas(water_model, scene, problem, height);
    let (_, scales) = glitter_scales(problem, st, &areas)?;
    scale_rows(problem, &scales);
    Some(scales)
}

/// Least squares of `y` on `a x + b` over `(x, y)`; `None` without a positive `a` (no
/// glitter term) or with fewer than 16 points. A floor `b` at or below zero is raised to a
/// thousandth of the mean `y`, so that no pixel's weight is unbounded.
fn fit_variance(points: impl Iterator<Item = (f64, f64)>) -> Option<GlitterNoise> {
    let (mut n, mut sx, mut sy, mut sxx, mut sxy) = (0f64, 0f64, 0f64, 0f64, 0f64);
    for (x, y) in points {
        n += 1.0;
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
    }
    if n < 16.0 {
        return None;
    }
    let det = n * sxx - sx * sx;
    if det.is_nan() || det <= 0.0 {
        return None;
    }
    let glint = (n * sxy - sx * sy) / det;
    let floor = (sy - glint * sx) / n;
    if !(glint > 0.0 && glint.is_finite()) {
        return None;
    }
    Some(GlitterNoise {
        glint,
        floor: floor.max(1e-3 * sy / n),
    })
}

/// Multiplies pixel i's observation and every coefficient of it (its samples' weights and
/// its control variate's mass, in every sample set) by `scales[i]`.
pub(super) fn scale_rows(problem: &mut Problem, scales: &[f32]) {
    for (o, &s) in problem.obs.iter_mut().zip(scales) {
        *o = o.map(|v| v * s);
    }
    for set in &mut problem.planes {
        scale_set(set, scales);
    }
}

/// Multiplies every coefficient of pixel i in one sample set by `scales[i]` (a set traced
/// after the rows were scaled).
pub(super) fn scale_set(set: &mut PlaneSamples, scales: &[f32]) {
    for (i, &s) in scales.iter().enumerate() {
        let r = set.range(i);
        for w in &mut set.weights[r] {
            *w *= s;
        }
        set.gauss[i].mass *= s;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fitting::joint::fixture::table3_light0;

    /// Scaled rows are the weighted problem: every coefficient of pixel i, over any
    /// rectangle, and its observation come out `scales[i]` times what they were (the control
    /// variate's Gaussian part included), and pixels of scale 1 are untouched.
    #[test]
    fn scaled_rows_scale_every_coefficient_and_observation() {
        let t = table3_light0();
        let (planes, per_pixel) = t.trace(32, 1, 0, true);
        let truth = t.light.rect();
        let mut problem = t.problem(planes, 1.0 / per_pixel as f32, &truth);
        let n = problem.n();
        let scales: Vec<f32> = (0..n).map(|i| [1.0, 0.5, 2.0][i % 3]).collect();
        let rects = [
            truth,
            crate::fitting::rect::Rect {
                v_max: truth.v_min + 0.3 * truth.height(),
                ..truth
            },
        ];
        let coefficients = |p: &Problem| -> Vec<Vec<(f32, f32)>> {
            rects
                .iter()
                .map(|r| {
                    (0..n)
                        .map(|i| p.planes[0].coefficient(i, r, p.inv_samples))
                        .collect()
                })
                .collect()
        };
        let before = coefficients(&problem);
        let obs = problem.obs.clone();
        assert!(before[0].iter().filter(|c| c.0 > 0.0).count() > n / 4);
        assert!(problem.planes[0].gauss.iter().any(|g| !g.is_none()));
        scale_rows(&mut problem, &scales);
        let after = coefficients(&problem);
        for (b, a) in before.iter().zip(&after) {
            for i in 0..n {
                let s = scales[i];
                assert!(
                    (a[i].0 - s * b[i].0).abs() <= 1e-5 * (1.0 + b[i].0.abs()),
                    "{i}"
                );
                assert!(
                    (a[i].1 - s * b[i].1).abs() <= 1e-5 * (1.0 + b[i].1.abs()),
                    "{i}"
                );
            }
        }
        for i in 0..n {
            assert_eq!(problem.obs[i], obs[i].map(|v| v * scales[i]));
        }
    }

    #[test]
    fn the_variance_model_is_recovered_from_its_own_points() {
        // y = 2 x + 0.5 exactly, over 20 points.
        let pts: Vec<(f64, f64)> = (0..20).map(|i| (i as f64, 2.0 * i as f64 + 0.5)).collect();
        let got = fit_variance(pts.into_iter());
        assert_eq!(
            got,
            Some(GlitterNoise {
                glint: 2.0,
                floor: 0.5
            })
        );
        // No glitter term (a falling line) or too few points: nothing.
        let falling = (0..20).map(|i| (i as f64, 10.0 - 0.1 * i as f64));
        assert_eq!(fit_variance(falling), None);
        assert_eq!(fit_variance((0..10).map(|i| (i as f64, i as f64))), None);
    }

    #[test]
    fn a_negative_floor_is_raised() {
        // y = x - 1 over x in 2..22: the floor -1 becomes a thousandth of the mean y (10.5).
        let got = fit_variance((2..22).map(|i| (i as f64, i as f64 - 1.0)));
        let got = got.unwrap_or(GlitterNoise {
            glint: 0.0,
            floor: 0.0,
        });
        assert!((got.glint - 1.0).abs() < 1e-9, "{got:?}");
        assert!((got.floor - 1e-3 * 10.5).abs() < 1e-9, "{got:?}");
    }
}
