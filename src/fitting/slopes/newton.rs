//! The slope search's along pass after the across pass moved, as one Newton step (the
//! module doc of [`super`]).

use super::VARIANCE_RANGE;
use crate::fitting::gloss::search::Point;
use crate::fitting::gloss::GlossSearch;
use crate::fitting::FittedLight;
use crate::Result;

/// The along pass after across moved, as one Newton step: the fit at `anchor` (made) and
/// one a first step above it along, with the first along pass's `curvature` `k` (of `S ~
/// S0 + k (x - x0)^2` in `x = ln v`), give the gradient and the vertex; the vertex is the
/// estimate when it lies within the tolerance of the anchor, else `None` (the full pass
/// runs, and reads the two fits again).
pub(super) fn newton_along(
    point_at: &mut impl FnMut([f32; 2]) -> Result<(Point, Vec<FittedLight>)>,
    anchor: [f32; 2],
    curvature: Option<f64>,
    options: &GlossSearch,
) -> Result<Option<f32>> {
    let Some(k) = curvature.filter(|k| k.is_finite() && *k > 0.0) else {
        return Ok(None);
    };
    let (lo, hi) = VARIANCE_RANGE;
    let x0 = (anchor[0] as f64).ln();
    let h = options.first_step_ln as f64;
    if x0 + h > (hi as f64).ln() {
        return Ok(None);
    }
    // The step above first: where it grows the search's proposal, the anchor's fit is then
    // made again on the new trace, and the two compare.
    let (p1, _) = point_at([(x0 + h).exp() as f32, anchor[1]])?;
    let (p0, _) = point_at(anchor)?;
    if !(p0.s.is_finite() && p1.s.is_finite()) {
        return Ok(None);
    }
    let g = (p1.s - p0.s - k * h * h) / h;
    let v = x0 - g / (2.0 * k);
    Ok(((v - x0).abs() < options.tolerance_ln as f64).then(|| (v.exp() as f32).clamp(lo, hi)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a cost quadratic in `ln v` along (curvature 40, the across variance playing no
    /// part), the step from the anchor's fit and one a first step above it lands on the
    /// vertex when that lies within the tolerance; a vertex farther off, or no curvature,
    /// gives `None`.
    #[test]
    fn the_along_pass_again_is_one_newton_step() {
        let options = GlossSearch {
            first_step_ln: 0.3,
            tolerance_ln: 0.06,
            ..GlossSearch::default()
        };
        let k = 40.0;
        for (vertex, want) in [(2.95e-3f64, true), (3.25e-3, true), (2.0e-3, false)] {
            let mut fits = 0;
            let mut cost = |v: [f32; 2]| -> Result<(Point, Vec<FittedLight>)> {
                fits += 1;
                let x = (v[0] as f64).ln();
                let s = 100.0 + k * (x - vertex.ln()).powi(2);
                Ok((
                    Point {
                        x,
                        s,
                        variance: 1.0,
                    },
                    Vec::new(),
                ))
            };
            let got = newton_along(&mut cost, [3.1e-3, 2.5e-3], Some(k), &options).unwrap();
            assert_eq!(fits, 2);
            match got {
                Some(v) if want => assert!((v as f64 / vertex - 1.0).abs() < 1e-4, "{v}"),
                None if !want => {}
                other => panic!("vertex {vertex}: {other:?}"),
            }
        }
        let mut cost = |_: [f32; 2]| -> Result<(Point, Vec<FittedLight>)> { unreachable!() };
        assert_eq!(
            newton_along(&mut cost, [3.1e-3, 2.5e-3], None, &options).unwrap(),
            None
        );
    }
}
