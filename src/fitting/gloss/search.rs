//! The one-dimensional search over `x = ln e` that brackets the cost's minimum and refines it
//! by parabolas (the gloss module's doc, "Search" and "Uncertainty").

use super::GlossSearch;
use crate::fitting::joint::place_starts;
use crate::fitting::{EdgeStatus, FittedLight, Skipped, StreakObservation};
use crate::photo_in::Photo;
use crate::progress::Reporter;
use crate::scene_in::Scene;
use crate::{Error, Result};

/// A point of the cost curve: `x = ln e`, its cost and residual variance.
#[derive(Clone, Copy, Debug)]
pub(in crate::fitting) struct Point {
    pub(in crate::fitting) x: f64,
    pub(in crate::fitting) s: f64,
    pub(in crate::fitting) variance: f64,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub(in crate::fitting) enum Stop {
    Converged,
    AtLimit,
    OutOfEvaluations,
    /// The curve said to stop at its first point ([`Curve::abandoned`]).
    Abandoned,
}

#[derive(Clone, Copy, Debug)]
pub(in crate::fitting) struct Found {
    pub(in crate::fitting) x: f64,
    pub(in crate::fitting) sigma_ln: Option<f64>,
    pub(in crate::fitting) stop: Stop,
}

/// The cost curve a search walks. Its points compare only while they stand on one basis (the
/// fits of the gloss search weigh the samples of one trace, which serves a range of glosses,
/// [`crate::fitting::joint::ProposalCache`]); a closure's points always compare.
pub(in crate::fitting) trait Curve {
    /// The point at `x` (an infinite cost: no evidence there).
    fn point(&mut self, x: f64) -> Result<Point>;

    /// Whether a point at `x` compares with the points made on the present basis.
    fn serves(&self, _x: f64) -> bool {
        true
    }

    /// Moves to a basis that serves both `next` and `best` and the points a first step
    /// either side of `best` ([`GlossSearch::first_step_ln`]); the search then makes again
    /// the points it has that the new basis serves.
    fn rebase(&mut self, _next: f64, _best: f64) {}

    /// Whether the search should end without an estimate: the gloss search's first fit can
    /// find the exact model unrelated to the photo (`JointOptions::start_gate`).
    fn abandoned(&self) -> bool {
        false
    }
}

impl<F: FnMut(f64) -> Result<Point>> Curve for F {
    fn point(&mut self, x: f64) -> Result<Point> {
        self(x)
    }
}

/// Minimises `cost` over `x = ln e` in [lo, hi] from `x0` (module doc, "Search"). The same
/// search serves any parameter that acts multiplicatively (the waves' slope variances,
/// [`crate::fitting::slopes`]): `name` says what `x` is the logarithm of, `show` prints
/// `exp(x)`, in the error when every fit broke down. When the next point is one `cost` does
/// not serve on its basis, the basis moves ([`Curve::rebase`]) and the points so far are made
/// again on it, those it does not serve dropped; while fewer than three would be left, the
/// best point's neighbours a first step away are added (or the point midway to the next).
/// Points made again do not count against [`GlossSearch::max_evaluations`].
pub(in crate::fitting) fn search(
    opts: &GlossSearch,
    x0: f64,
    (lo, hi): (f64, f64),
    (name, show): (&str, &dyn Fn(f64) -> String),
    mut cost: impl Curve,
) -> Result<Found> {
    let h = opts.first_step_ln as f64;
    let tol = opts.tolerance_ln as f64;
    let max_step = (opts.max_step_ln as f64).max(h);
    let max_bracket = opts.max_bracket_ln as f64;
    // Three points around the start, shifted inside the limits.
    let h0 = h.min(0.5 * (hi - lo));
    let centre = x0.clamp(lo + h0, hi - h0);
    let mut pts = Vec::new();
    for x in [centre - h0, centre, centre + h0] {
        pts.push(cost.point(x)?);
        if cost.abandoned() {
            return Ok(Found {
                x,
                sigma_ln: None,
                stop: Stop::Abandoned,
            });
        }
    }
    // Points made at new places (not made again on a new basis).
    let mut made = pts.len();
    loop {
        pts.sort_by(|p, q| p.x.total_cmp(&q.x));
        let ib = (0..pts.len())
            .min_by(|&i, &j| pts[i].s.total_cmp(&pts[j].s))
            .expect("three points at least");
        let best = pts[ib];
        if !best.s.is_finite() {
            return Err(Error::NothingFound(format!(
                "the joint fit broke down at every {name} tried ({}): the {name} cannot be \
                 estimated from this photo",
                pts.iter()
                    .map(|p| show(p.x.exp()))
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        }
        let left = ib.checked_sub(1).map(|i| pts[i]);
        let right = pts.get(ib + 1).copied();
        let next = match (left, right) {
            (Some(l), Some(r)) => {
                // Bracketed: the parabola through the best point and its neighbours.
                let vertex = parabola(&[l, best, r]);
                if let Some((v, k)) = vertex {
                    if r.x - l.x <= max_bracket + 1e-9 && (v - best.x).abs() < tol {
                        return Ok(Found {
                            x: v.clamp(l.x, r.x),
                            sigma_ln: (k > 0.0).then(|| (best.variance / k).sqrt()),
                            stop: Stop::Converged,
                        });
                    }
                }
                let clear = |x: f64| (x - l.x).min(r.x - x).min((x - best.x).abs()) >= 0.5 * tol;
                match vertex {
                    Some((v, _)) if (v - best.x).abs() >= tol && clear(v) => v,
                    // The vertex says "here" (or there is none, a neighbour's fit having
                    // broken down) but the bracket is too wide to trust a parabola over it:
                    // narrow its wider side.
                    _ => {
                        let (gl, gr) = (best.x - l.x, r.x - best.x);
                        if gl > gr {
                            best.x - (0.5 * gl).min(h)
                        } else {
                            best.x + (0.5 * gr).min(h)
                        }
                    }
                }
            }
            (None, Some(_)) | (Some(_), None) => {
                // The lowest point is the outermost: the minimum lies beyond it. Step by the
                // parabola through it and its two neighbours, at least h, at most max_step.
                let dir = if left.is_none() { -1.0 } else { 1.0 };
                if (dir < 0.0 && best.x <= lo) || (dir > 0.0 && best.x >= hi) {
                    return Ok(Found {
                        x: best.x,
                        sigma_ln: None,
                        stop: Stop::AtLimit,
                    });
                }
                let tri = if dir < 0.0 {
                    [pts[0], pts[1], pts[2]]
                } else {
                    let n = pts.len();
                    [pts[n - 3], pts[n - 2], pts[n - 1]]
                };
                let neighbour = if dir < 0.0 {
                    pts[1]
                } else {
                    pts[pts.len() - 2]
                };
                match parabola(&tri) {
                    // A vertex between the lowest point and its neighbour (after a long step
                    // that overshot): try it; if it is lower, the minimum is bracketed.
                    Some((v, _))
                        if (v - best.x) * dir < 0.0
                            && (v - best.x).abs().min((v - neighbour.x).abs()) >= tol
                            && (v - best.x).abs() < (neighbour.x - best.x).abs() =>
                    {
                        v
                    }
                    vertex => {
                        let step = vertex
                            .map(|(v, _)| (v - best.x) * dir)
                            .unwrap_or(max_step)
                            .clamp(h, max_step);
                        (best.x + dir * step).clamp(lo, hi)
                    }
                }
            }
            (None, None) => unreachable!("three points at least"),
        };
        if made >= opts.max_evaluations {
            return Ok(Found {
                x: best.x,
                sigma_ln: None,
                stop: Stop::OutOfEvaluations,
            });
        }
        if !cost.serves(next) {
            cost.rebase(next, best.x);
            let mut again = Vec::with_capacity(pts.len() + 2);
            for p in &pts {
                if cost.serves(p.x) {
                    again.push(cost.point(p.x)?);
                }
            }
            for x in [best.x - h0, best.x + h0, 0.5 * (best.x + next)] {
                let new = x != next
                    && (lo..=hi).contains(&x)
                    && cost.serves(x)
                    && again.iter().all(|p: &Point| p.x != x);
                if again.len() < 2 && new {
                    again.push(cost.point(x)?);
                    made += 1;
                }
            }
            if again.len() < 2 {
                return Err(Error::NothingFound(format!(
                    "the {name} search could not go on from {} towards {}: too few of its \
                     points compare there",
                    show(best.x.exp()),
                    show(next.exp())
                )));
            }
            pts = again;
        }
        pts.push(cost.point(next)?);
        made += 1;
    }
}

/// The vertex of the parabola through three points and its quadratic coefficient
/// (`S ~ S0 + k (x - v)^2`); `None` when the points do not determine a convex parabola.
fn parabola(p: &[Point; 3]) -> Option<(f64, f64)> {
    let [a, b, c] = p;
    let d1 = (b.s - a.s) / (b.x - a.x);
    let d2 = (c.s - b.s) / (c.x - b.x);
    let k = (d2 - d1) / (c.x - a.x);
    if !(k.is_finite() && k > 0.0) {
        return None;
    }
    // S = a.s + d1 (x - a.x) + k (x - a.x)(x - b.x); dS/dx = 0 at:
    let v = 0.5 * (a.x + b.x) - d1 / (2.0 * k);
    v.is_finite().then_some((v, k))
}

/// [`search_start`] of the paper fit `paper` of `streaks`, placed on the lamps' direct
/// images ([`place_starts`], which tells `placing` what it changes) where the fits read the
/// direct view (`placing` given): every fit of a search starts alike, so the direct view
/// places the starts once.
pub(in crate::fitting) fn placed_search_start(
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    streaks: &[StreakObservation],
    paper: &crate::fitting::FitOutcome,
    what: &str,
    placing: Option<Reporter<'_>>,
) -> Result<Vec<FittedLight>> {
    let start = search_start(paper, streaks.len(), what)?;
    Ok(match placing {
        Some(progress) => place_starts(scene, photo, water, streaks, &start, progress),
        None => start,
    })
}

/// The start of a search over the water's lobe from the paper fit `paper` of `streaks`
/// streaks: its lights with every edge free to move (the paper fit places an edge it found
/// no pixel for at the lobes' farthest reach, and the joint fit would hold it there; under
/// another lobe that reach is another). Fails when the paper fit found no light (`what` is
/// the parameter that then cannot be estimated).
pub(in crate::fitting) fn search_start(
    paper: &crate::fitting::FitOutcome,
    streaks: usize,
    what: &str,
) -> Result<Vec<FittedLight>> {
    if paper.lights.is_empty() {
        return Err(Error::NothingFound(format!(
            "{streaks} streak(s) found but no light could be fitted, so the {what} cannot be \
             estimated: {}",
            paper
                .skipped
                .iter()
                .map(skipped_message)
                .collect::<Vec<_>>()
                .join("; ")
        )));
    }
    Ok(paper
        .lights
        .iter()
        .map(|l| FittedLight {
            edges: l.edges.clone().map(|e| match e {
                EdgeStatus::Unconstrained { reason, pixels, .. } => EdgeStatus::Unconstrained {
                    reason,
                    pixels,
                    unseen: false,
                },
                constrained => constrained,
            }),
            ..l.clone()
        })
        .collect())
}

fn skipped_message(s: &Skipped) -> String {
    match s {
        Skipped::NoPlane { streak, message } | Skipped::NoSolution { streak, message } => {
            format!("streak {streak}: {message}")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pt(x: f64, s: f64) -> Point {
        Point {
            x,
            s,
            variance: 1.0,
        }
    }

    #[test]
    fn parabola_vertex_and_curvature() {
        let f = |x: f64| 3.0 + 2.0 * (x - 0.3) * (x - 0.3);
        let (v, k) = parabola(&[pt(-1.0, f(-1.0)), pt(0.1, f(0.1)), pt(2.0, f(2.0))]).unwrap();
        assert!((v - 0.3).abs() < 1e-12 && (k - 2.0).abs() < 1e-12);
        assert!(parabola(&[pt(0.0, 1.0), pt(1.0, 2.0), pt(2.0, 3.0)]).is_none());
        assert!(parabola(&[pt(0.0, 1.0), pt(1.0, f64::INFINITY), pt(2.0, 3.0)]).is_none());
    }

    /// The search's default options.
    const GLOSS: (&str, &dyn Fn(f64) -> String) = ("gloss", &|e| format!("{e:.0}"));

    fn options() -> GlossSearch {
        GlossSearch::default()
    }

    /// Runs the search on `f(ln e)` from e = 500 in [50, 5000]; returns what it found and the
    /// points it evaluated.
    fn run(opts: &GlossSearch, f: impl Fn(f64) -> f64) -> (Found, Vec<f64>) {
        let mut xs = Vec::new();
        let found = search(
            opts,
            500f64.ln(),
            (50f64.ln(), 5000f64.ln()),
            GLOSS,
            |x: f64| {
                xs.push(x);
                Ok(pt(x, f(x)))
            },
        )
        .unwrap();
        (found, xs)
    }

    /// Like the samples' costs: a parabola in ln e near the minimum, steeper on the low side
    /// and flattening far away.
    fn skewed(x: f64, truth: f64) -> f64 {
        let d = x - truth.ln();
        let near = if d < 0.0 { 6000.0 } else { 3000.0 } * d * d;
        1700.0 + near / (1.0 + d * d)
    }

    #[test]
    fn finds_minima_on_both_sides_of_the_start() {
        for truth in [80.0, 200.0, 450.0, 500.0, 560.0, 1000.0, 3000.0] {
            let (found, xs) = run(&options(), |x| skewed(x, truth));
            let e = found.x.exp();
            assert_eq!(found.stop, Stop::Converged, "truth {truth}: {found:?}");
            assert!((e / truth - 1.0).abs() < 0.03, "truth {truth}: found {e}");
            assert!(found.sigma_ln.is_some_and(|s| s > 0.0));
            // A handful from a start within a factor 3; a few more from farther off.
            let allowed = if (truth / 500.0f64).ln().abs() < 3f64.ln() {
                8
            } else {
                10
            };
            assert!(xs.len() <= allowed, "truth {truth}: evaluated at {xs:?}");
        }
        // A start near the minimum costs the three first points only.
        let (_, xs) = run(&options(), |x| skewed(x, 490.0));
        assert_eq!(xs.len(), 3);
    }

    #[test]
    fn a_minimum_beyond_a_limit_is_reported_there() {
        let (found, _) = run(&options(), |x| -x);
        assert_eq!(found.stop, Stop::AtLimit);
        assert!((found.x - 5000f64.ln()).abs() < 1e-9);
        assert!(found.sigma_ln.is_none());
        let (found, _) = run(&options(), |x| x);
        assert_eq!(found.stop, Stop::AtLimit);
        assert!((found.x - 50f64.ln()).abs() < 1e-9);
    }

    #[test]
    fn broken_fits_are_stepped_around() {
        // No evidence below e = 150 (as a fit that broke down reports); the minimum at 160.
        let f = |x: f64| {
            if x < 150f64.ln() {
                f64::INFINITY
            } else {
                skewed(x, 160.0)
            }
        };
        let (found, _) = run(&options(), f);
        assert!((found.x.exp() / 160.0 - 1.0).abs() < 0.05, "{found:?}");
        // And nothing but broken fits is an error, not a guess.
        let all_broken = search(&options(), 6.0, (4.0, 8.0), GLOSS, |x: f64| {
            Ok(pt(x, f64::INFINITY))
        });
        assert!(matches!(all_broken, Err(Error::NothingFound(_))));
    }

    #[test]
    fn stops_when_the_evaluations_run_out() {
        let opts = GlossSearch {
            max_evaluations: 4,
            ..options()
        };
        let (found, xs) = run(&opts, |x| skewed(x, 60.0));
        assert_eq!(found.stop, Stop::OutOfEvaluations);
        assert_eq!(xs.len(), 4);
        assert!(found.sigma_ln.is_none());
    }

    /// A curve whose points compare only on one basis: each basis serves `x` in
    /// `[b, b + ln 4]` and adds a level of its own, far larger than the curve's changes.
    struct Based {
        truth: f64,
        basis: f64,
        bases: usize,
        xs: Vec<f64>,
    }

    impl Curve for &mut Based {
        fn point(&mut self, x: f64) -> Result<Point> {
            assert!(self.serves(x), "{x} asked off the basis {}", self.basis);
            self.xs.push(x);
            Ok(pt(x, skewed(x, self.truth) + 1e5 * self.bases as f64))
        }

        fn serves(&self, x: f64) -> bool {
            (self.basis..=self.basis + 4f64.ln()).contains(&x)
        }

        fn rebase(&mut self, next: f64, best: f64) {
            self.basis = next.min(best) - 1.6f64.ln();
            self.bases += 1;
        }
    }

    /// From a start 5 times off either way, the search moves its basis as it goes and still
    /// finds the minimum, each basis's points compared among themselves only (a point of an
    /// older basis would sit 1e5 higher and never be the best).
    #[test]
    fn a_search_that_moves_its_basis_compares_points_of_one() {
        for truth in [100.0, 2500.0] {
            let x0 = 500f64.ln();
            let mut curve = Based {
                truth,
                basis: x0 - 1.6f64.ln(),
                bases: 0,
                xs: Vec::new(),
            };
            let found = search(
                &options(),
                x0,
                (50f64.ln(), 5000f64.ln()),
                GLOSS,
                &mut curve,
            )
            .unwrap();
            let e = found.x.exp();
            assert_eq!(found.stop, Stop::Converged, "truth {truth}: {found:?}");
            assert!((e / truth - 1.0).abs() < 0.03, "truth {truth}: found {e}");
            assert!(curve.bases >= 1, "truth {truth}: never moved");
            assert!(found.sigma_ln.is_some_and(|s| s > 0.0));
        }
    }

    /// A curve that says to stop after its first point ends the search there, with no
    /// estimate; one that never does is searched to its minimum as before.
    #[test]
    fn an_abandoned_curve_ends_the_search_at_its_first_point() {
        struct Gated {
            xs: Vec<f64>,
            stop: bool,
        }
        impl Curve for &mut Gated {
            fn point(&mut self, x: f64) -> Result<Point> {
                self.xs.push(x);
                Ok(pt(x, skewed(x, 300.0)))
            }
            fn abandoned(&self) -> bool {
                self.stop && !self.xs.is_empty()
            }
        }
        let range = (50f64.ln(), 5000f64.ln());
        let mut gated = Gated {
            xs: Vec::new(),
            stop: true,
        };
        let found = search(&options(), 500f64.ln(), range, GLOSS, &mut gated).unwrap();
        assert_eq!(found.stop, Stop::Abandoned);
        assert_eq!(gated.xs.len(), 1);
        assert_eq!(found.sigma_ln, None);
        let mut open = Gated {
            xs: Vec::new(),
            stop: false,
        };
        let found = search(&options(), 500f64.ln(), range, GLOSS, &mut open).unwrap();
        assert_eq!(found.stop, Stop::Converged);
        assert!((found.x.exp() / 300.0 - 1.0).abs() < 0.05, "{found:?}");
    }
}
