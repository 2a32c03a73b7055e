//! The slope search's fits, kept by the proposal trace they weighed (the module doc of
//! [`super`]): a fit on a trace the search has since replaced is made again rather than
//! compared with the fits on the present one, whose costs share their samples.

use crate::fitting::gloss::search::{Curve, Point};
use crate::fitting::FittedLight;
use crate::Result;

/// A fit of the search: its point and lights, and the generation of the proposal whose trace
/// it weighed (`None`: it lay below the proposal's reach and traced its own samples, which
/// are the same whatever the proposal).
pub(super) type Fit = (Point, Vec<FittedLight>, Option<u32>);

/// Every fit made so far, in order, with its variances: the search's evaluations.
#[derive(Default)]
pub(super) struct Fits {
    made: Vec<([f32; 2], Fit)>,
}

impl Fits {
    /// The fit at variances `v` on proposal generation `now`: one made already (on `now`, or
    /// on its own samples) or the one `eval` makes (given its number, from 1).
    pub(super) fn at(
        &mut self,
        v: [f32; 2],
        now: u32,
        eval: impl FnOnce([f32; 2], usize) -> Result<Fit>,
    ) -> Result<Fit> {
        // The same variances to rounding (the logarithm and back).
        let same = |m: &[f32; 2]| (0..2).all(|a| (m[a] / v[a] - 1.0).abs() < 1e-6);
        if let Some((_, fit)) = self
            .made
            .iter()
            .rev()
            .find(|(m, fit)| same(m) && on(fit.2, now))
        {
            return Ok(fit.clone());
        }
        let fit = eval(v, self.made.len() + 1)?;
        self.made.push((v, fit.clone()));
        Ok(fit)
    }

    /// The variances and point of the fit of lowest cost among those that compare on
    /// generation `now`.
    pub(super) fn best(&self, now: u32) -> Option<([f32; 2], Point)> {
        self.made
            .iter()
            .filter(|(_, fit)| fit.0.s.is_finite() && on(fit.2, now))
            .min_by(|a, b| a.1 .0.s.total_cmp(&b.1 .0.s))
            .map(|(v, fit)| (*v, fit.0))
    }

    /// Every fit's variances and cost, in the order made.
    pub(super) fn evaluations(&self) -> Vec<([f32; 2], f64)> {
        self.made.iter().map(|(v, fit)| (*v, fit.0.s)).collect()
    }
}

/// Whether a fit on generation `basis` compares with the fits on generation `now`.
fn on(basis: Option<u32>, now: u32) -> bool {
    basis.is_none_or(|g| g == now)
}

/// The last fit of a pass at each of its points `(ln variance, lights, generation)` that
/// compares on generation `now`: the lights' derivatives by the variance compare as the
/// costs do.
pub(super) fn last_on(
    points: Vec<(f64, Vec<FittedLight>, Option<u32>)>,
    now: u32,
) -> Vec<(f64, Vec<FittedLight>)> {
    let mut kept: Vec<(f64, Vec<FittedLight>)> = Vec::new();
    for (x, lights, basis) in points {
        if on(basis, now) {
            kept.retain(|k| k.0 != x);
            kept.push((x, lights));
        }
    }
    kept
}

/// A pass of the slope search over one axis as the search's curve: its fits, which of them
/// the present proposal serves (none above its reach), and the proposal grown to a fit
/// above it, after which the search makes its points again on the new trace.
pub(super) struct Pass<P, S, R> {
    pub(super) point: P,
    pub(super) serves: S,
    pub(super) rebase: R,
}

impl<P, S, R> Curve for Pass<P, S, R>
where
    P: FnMut(f64) -> Result<Point>,
    S: Fn(f64) -> bool,
    R: FnMut(f64),
{
    fn point(&mut self, x: f64) -> Result<Point> {
        (self.point)(x)
    }

    fn serves(&self, x: f64) -> bool {
        (self.serves)(x)
    }

    fn rebase(&mut self, next: f64, _best: f64) {
        (self.rebase)(next)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(s: f64) -> Point {
        Point {
            x: 0.0,
            s,
            variance: 1.0,
        }
    }

    /// A fit is read again on its own generation and made again on a later one; one that
    /// traced its own samples is read again on any; the best and a pass's points compare
    /// only fits of the present generation (or their own samples).
    #[test]
    fn fits_compare_on_one_trace() {
        let mut fits = Fits::default();
        let mut made = 0;
        let mut eval = |s: f64, basis: Option<u32>| {
            made += 1;
            move |_: [f32; 2], _: usize| -> Result<Fit> { Ok((point(s), Vec::new(), basis)) }
        };
        let (a, b) = ([2e-3, 1e-3], [3e-3, 1e-3]);
        fits.at(a, 0, eval(10.0, Some(0))).unwrap();
        fits.at(b, 0, eval(12.0, None)).unwrap();
        assert_eq!(fits.at(a, 0, eval(0.0, Some(0))).unwrap().0.s, 10.0);
        assert_eq!(fits.best(0).map(|b| b.0), Some(a));
        // On generation 1 the fit at `a` is stale: the best is the own-samples one at `b`
        // until `a` is made again.
        assert_eq!(fits.best(1).map(|b| b.0), Some(b));
        assert_eq!(fits.at(a, 1, eval(13.0, Some(1))).unwrap().0.s, 13.0);
        assert_eq!(fits.at(b, 1, eval(0.0, Some(1))).unwrap().0.s, 12.0);
        assert_eq!(fits.best(1).map(|b| b.0), Some(b));
        assert_eq!(fits.evaluations().len(), 3);
        let kept = last_on(
            vec![
                (1.0, Vec::new(), Some(0)),
                (2.0, Vec::new(), None),
                (1.0, Vec::new(), Some(1)),
                (3.0, Vec::new(), Some(0)),
            ],
            1,
        );
        assert_eq!(kept.iter().map(|k| k.0).collect::<Vec<_>>(), [2.0, 1.0]);
    }
}
