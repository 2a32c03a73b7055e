//! Estimating the water's gloss exponent `e` from the photo together with the lights (the
//! library side of a `--gloss auto`; the converter does not call it yet).
//!
//! The paper takes `e` as known. A wrong `e` does not stop a fit: the lights come out with
//! the wrong size and radiance (a lobe that is too wide is answered by a light that is too
//! small and too bright, METHOD §6), so `e` has to be measured too. What tells it apart is the
//! streak's profile: the width of the lobe sets how fast each edge of the streak fades, and a
//! rectangle cannot mimic that at every edge at once. So `e` is the gloss whose best lights
//! explain the photo best:
//!
//! ```text
//! e_hat = argmin_e  min_{lights} S(e, lights)
//! ```
//!
//! with `S` the joint fit's noise-debiased residual sum of squares over the water near the
//! streaks ([`super::joint`]). The inner minimum is [`fit_joint`] with the model
//! `ReflectionModel { gloss: e, .. }`; the outer one is a one-dimensional search over `ln e`
//! (gloss acts multiplicatively: the lobe's width goes as `1/sqrt(e)`; on the samples the
//! cost is close to a parabola in `ln e` over a factor of about 1.3 either side of its
//! minimum, and rises steadily, though not always symmetrically, beyond).
//!
//! # Comparable costs
//!
//! * Every candidate starts from the same lights, the paper fit at the starting gloss, so the
//!   fitted region (the streaks, dilated, and the pixels that can see the start lights'
//!   surroundings) is the same up to its fringe, and the costs are sums over nearly the same
//!   pixels. The cost compared is the sum `S`, not `S` per degree of freedom: the region test
//!   depends on the lobe, so the region still gains or loses a few hundred of its ~50,000
//!   pixels at its dark fringe across `e` (on `gloss1000.png`), which add ~0 to the sum but
//!   would change a mean.
//! * The random numbers are common across candidates (one seed), so the cost is a smooth
//!   function of `e` rather than one with fresh noise at every evaluation.
//! * The fits use the joint fit's full samples per pixel. With fewer the cost is not to be
//!   trusted: the edge search picks, among thousands of rectangles, ones whose coefficients'
//!   estimated noise (which the cost subtracts) happens to be large, and with a wide lobe and
//!   32 samples that wins outright (on `gloss200.png` at e = 100-125: a rectangle a sixth of
//!   the true height, seven times too bright, with a cost below zero; at 72 samples, a cost at
//!   e = 75 below that at 100). Rescoring such fits on independent samples removes that bias,
//!   but at 32 samples the rescored cost is still too noisy: its minimum moved between 205 and
//!   225 with the seed. At 128 samples the fit's own cost is smooth in `e` and its minimum
//!   agrees with that of 512-sample rescoring (202 and 204 on `gloss200.png`), so the search
//!   uses it as it is. A fit whose cost still comes out non-positive counts as no evidence
//!   (infinite cost). The fits of the search run fewer coordinate-descent sweeps than a
//!   final fit ([`GlossSearch::search_sweeps`]): the cost at the optimum moves by 0.3 % and
//!   uniformly across `e`.
//!
//! # Search
//!
//! Three points around the start, `ln e` apart by [`GlossSearch::first_step_ln`]. While the
//! lowest point is an outermost one, step beyond it to the vertex of the parabola through it
//! and its two neighbours (at least one first step, at most [`GlossSearch::max_step_ln`]),
//! or, when that vertex lies between it and its neighbour (a long step overshot), try the
//! vertex.
//! Once the minimum is bracketed, step to the vertex of the parabola through the lowest point
//! and its neighbours, or, when that vertex is already within [`GlossSearch::tolerance_ln`]
//! of the lowest point but the bracket is wider than [`GlossSearch::max_bracket_ln`] (too
//! wide to trust a parabola over: the cost is skewed), narrow the bracket's wider side. Stop
//! when the vertex is within the tolerance of the lowest point in a narrow bracket; the
//! estimate is that vertex. On the samples that took 3 evaluations from the right gloss and 6
//! or 7 from a start 2 or 2.5 times off, each about 2.5 s on 2 quiet cores, and then one full
//! joint fit at the estimate (about 3 s): 11 s in all for Table 1.
//!
//! # Uncertainty
//!
//! Near the minimum `S(x) ~ S0 + k (x - x0)^2` with `x = ln e`; a one-sigma change of `x` raises
//! the cost by the residual variance per degree of freedom `s2`, so `sigma(ln e) = sqrt(s2 / k)`.
//! That is the photo's statistical limit (pixel noise independent): it leaves out the model's
//! own errors and the Monte Carlo noise of the fits, and is a lower bound. On the samples it
//! is 0.1-0.2 %, while the estimates (`tests/gloss.rs`) are 205.6 for e = 200, 500.8 for 500
//! and 1001.2 for 1000, and the seed of the fits moved them by about 1 % (seeds 1-3, measured
//! when the search was written). Read the estimate as good to a few percent. (With the joint
//! fit's own default of 72 samples e = 200 came out 223: see [`SEARCH_SAMPLES`].)
//!
//! # Limits
//!
//! The gloss is whatever lets the fitted lights explain the photo best, so it absorbs any
//! error in the lights' kind: where one rectangle stands for two lights (`stacked.png`, two
//! lights one above the other whose reflections merge into one streak, fitted as one light),
//! the estimate comes out at 813 for a water of 500, the narrower lobe making up for the dark
//! gap between the lights. `table3.png` (two lights side by side, one reaching out of the
//! photo) gives 502.

use std::time::Instant;

use super::joint::{self, fit_joint, JointOptions, Uncertainty};
use super::{fit_paper, EdgeStatus, FitOptions, FittedLight, Skipped, StreakObservation};
use crate::optics::ReflectionModel;
use crate::photo_in::Photo;
use crate::scene_in::Scene;
use crate::{Error, Result};

/// How to search for the gloss.
#[derive(Clone, Copy, Debug)]
pub struct GlossSearch {
    /// The paper fit that gives every candidate its start: samples, seed, IOR and shadowing,
    /// and `model.gloss`, the first guess of the gloss (the scene's, typically). The seed is
    /// also the joint fits'.
    pub fit: FitOptions,
    /// Smallest gloss considered.
    pub min_gloss: f32,
    /// Largest gloss considered.
    pub max_gloss: f32,
    /// Spacing of the first three points, in `ln e`, and the smallest step beyond a bracket.
    pub first_step_ln: f32,
    /// Largest step beyond the points so far, in `ln e` (ln 2: at most a factor 2 at once).
    pub max_step_ln: f32,
    /// Stop when the parabola's vertex is this close to the lowest point, in `ln e`.
    pub tolerance_ln: f32,
    /// Trust a parabola's vertex only over a bracket at most this wide, in `ln e`.
    pub max_bracket_ln: f32,
    /// At most this many cost evaluations (each a joint fit).
    pub max_evaluations: usize,
    /// Joint-fit samples per pixel during the search (module doc: fewer are not to be
    /// trusted).
    pub search_samples: u32,
    /// Coordinate-descent sweeps of the search's joint fits.
    pub search_sweeps: u32,
    /// Joint-fit samples per pixel of the final fit at the estimate (which runs the joint
    /// fit's default sweeps).
    pub final_samples: u32,
    /// Independent final fits at the estimate whose mean is the result
    /// ([`JointOptions::repeats`]).
    pub final_repeats: u32,
    /// Whether the final fit reads a checkerboard half of its region's pixels
    /// ([`JointOptions::checkerboard`]; the search always does).
    pub final_checkerboard: bool,
    /// Told a line as each joint fit of the search, and the final fit (and its repeats),
    /// starts (None: silent): the search takes tens of seconds.
    pub progress: Option<fn(&str)>,
}

/// Joint-fit samples per pixel of the search and of the final fit (module doc: the cost is
/// not to be trusted with fewer; the joint fit's own default is lower).
pub const SEARCH_SAMPLES: u32 = 128;

impl GlossSearch {
    /// Defaults for a scene: start at its water's gloss, search `e` in [50, 5000].
    pub fn for_scene(scene: &Scene) -> Self {
        Self::starting_from(FitOptions::for_scene(scene))
    }

    /// Defaults for the paper fit `fit` (whose model's gloss is the start).
    pub fn starting_from(fit: FitOptions) -> Self {
        GlossSearch {
            fit,
            min_gloss: 50.0,
            max_gloss: 5000.0,
            first_step_ln: 0.15,
            max_step_ln: std::f32::consts::LN_2,
            tolerance_ln: 0.03,
            max_bracket_ln: 0.35,
            max_evaluations: 12,
            search_samples: SEARCH_SAMPLES,
            search_sweeps: 6,
            final_samples: SEARCH_SAMPLES,
            final_repeats: 1,
            final_checkerboard: true,
            progress: None,
        }
    }

    fn validate(&self) -> Result<()> {
        let bad = |what: &str| Err(Error::Usage(format!("gloss search: {what}")));
        if !(self.min_gloss.is_finite() && self.min_gloss > 0.0) {
            return bad(&format!(
                "the smallest gloss must be positive, not {}",
                self.min_gloss
            ));
        }
        if !(self.max_gloss.is_finite() && self.max_gloss > self.min_gloss) {
            return bad(&format!(
                "the largest gloss ({}) must be finite and above the smallest ({})",
                self.max_gloss, self.min_gloss
            ));
        }
        if !(self.fit.model.gloss.is_finite() && self.fit.model.gloss > 0.0) {
            return bad(&format!(
                "the starting gloss must be positive, not {}",
                self.fit.model.gloss
            ));
        }
        for (name, v) in [
            ("first step", self.first_step_ln),
            ("largest step", self.max_step_ln),
            ("tolerance", self.tolerance_ln),
            ("largest bracket", self.max_bracket_ln),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return bad(&format!("the {name} must be positive, not {v}"));
            }
        }
        if self.max_evaluations < 3 {
            return bad("at least 3 evaluations are needed to bracket a minimum");
        }
        if self.search_samples == 0 || self.final_samples == 0 || self.fit.samples == 0 {
            return bad("the fits need at least one sample per pixel");
        }
        if self.final_repeats == 0 {
            return bad("the final fit needs at least one repeat");
        }
        Ok(())
    }
}

/// The estimated gloss, and the lights fitted with it.
#[derive(Clone, Debug)]
pub struct GlossEstimate {
    /// The estimated gloss exponent `e`.
    pub gloss: f32,
    /// One-sigma statistical uncertainty of `ln e` (so roughly the relative uncertainty of
    /// `e`), from the curvature of the cost. A lower bound: the fits' Monte Carlo noise and
    /// the parabola's shape each add about 1 % (module doc). `None` when the minimum was not
    /// bracketed (it lies at a limit of the search, or the evaluations ran out).
    pub sigma_ln: Option<f32>,
    /// Every cost evaluation in the order made: (gloss, residual sum of squares of the joint
    /// fit at it, radiance units squared; infinite where the fit broke down).
    pub evaluations: Vec<(f32, f64)>,
    /// The lights jointly fitted at the estimated gloss ([`GlossSearch::final_samples`]
    /// samples), edges the photo does not constrain marked as such.
    pub lights: Vec<FittedLight>,
    /// Their uncertainties at that gloss (the gloss's own uncertainty not included).
    pub uncertainty: Vec<Uncertainty>,
    /// The final fit's residual variance per pixel and channel.
    pub residual_variance: f64,
    /// Streaks the paper fit could not turn into a light (left out of the search).
    pub skipped: Vec<Skipped>,
    /// Things the user should know (the paper fit's warnings, a minimum at a search limit).
    pub warnings: Vec<String>,
    /// Wall-clock seconds per stage: "paper fit", "search (N evaluations)", "final joint
    /// fit".
    pub timings: Vec<(String, f64)>,
}

/// Estimates the water's gloss from the photo and fits the lights with it (see the module
/// doc for the method).
///
/// The inputs are those of [`fit_paper`]: the photo, its water mask and the streaks found in
/// it. Fails on inconsistent inputs, bad search options, when there is no streak, and when no
/// streak gives a light (the message says why for each).
pub fn estimate_gloss(
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    streaks: &[StreakObservation],
    options: &GlossSearch,
) -> Result<GlossEstimate> {
    options.validate()?;
    super::check_sizes(photo, water)?;
    if streaks.is_empty() {
        return Err(Error::NothingFound(
            "no streak to estimate the gloss from: the photo shows no reflection of a light".into(),
        ));
    }
    let (lo, hi) = (
        (options.min_gloss as f64).ln(),
        (options.max_gloss as f64).ln(),
    );
    let x0 = (options.fit.model.gloss as f64).ln().clamp(lo, hi);
    let mut timings = Vec::new();

    // The common start: the paper fit at the first guess.
    let t = Instant::now();
    let start_options = FitOptions {
        model: ReflectionModel {
            gloss: options
                .fit
                .model
                .gloss
                .clamp(options.min_gloss, options.max_gloss),
            ..options.fit.model
        },
        ..options.fit
    };
    let paper = fit_paper(scene, photo, water, streaks, &start_options)?;
    timings.push(("paper fit".to_string(), t.elapsed().as_secs_f64()));
    if paper.lights.is_empty() {
        return Err(Error::NothingFound(format!(
            "{} streak(s) found but no light could be fitted, so the gloss cannot be \
             estimated: {}",
            streaks.len(),
            paper
                .skipped
                .iter()
                .map(skipped_message)
                .collect::<Vec<_>>()
                .join("; ")
        )));
    }
    let mut warnings = paper.warnings.clone();
    // The paper fit under the start gloss places an edge it found no pixel for at the lobes'
    // farthest reach, and the joint fit would hold it there; under another gloss that reach
    // is another, so the search lets every edge move.
    let start: Vec<FittedLight> = paper
        .lights
        .iter()
        .map(|l| FittedLight {
            edges: l.edges.clone().map(|e| match e {
                EdgeStatus::Unconstrained { reason, .. } => EdgeStatus::Unconstrained {
                    reason,
                    unseen: false,
                },
                constrained => constrained,
            }),
            ..l.clone()
        })
        .collect();

    let t = Instant::now();
    let mut cost = Cost {
        scene,
        photo,
        water,
        streaks,
        start: &start,
        options,
        evaluations: Vec::new(),
        failed: Vec::new(),
    };
    let found = search(options, x0, lo, hi, |x| cost.point(x))?;
    timings.push((
        format!("search ({} evaluations)", cost.evaluations.len()),
        t.elapsed().as_secs_f64(),
    ));
    let gloss = found.x.exp() as f32;
    if !cost.failed.is_empty() {
        warnings.push(format!(
            "the joint fit broke down (no positive cost) at gloss {:?}; those were left out",
            cost.failed
        ));
    }
    match found.stop {
        Stop::Converged => {}
        Stop::AtLimit => warnings.push(format!(
            "the gloss estimate lies at the search's limit ({gloss:.0}, searched {} to {}): \
             the photo fits best with a gloss at or beyond it",
            options.min_gloss, options.max_gloss
        )),
        Stop::OutOfEvaluations => warnings.push(format!(
            "the gloss search stopped after {} evaluations before converging; the estimate \
             {gloss:.0} may be off by more than its tolerance",
            options.max_evaluations
        )),
    }

    // The lights at the estimate, fitted in full from the same start.
    if let Some(say) = options.progress {
        say(&format!("gloss search: final joint fit at e = {gloss:.0}"));
    }
    let t = Instant::now();
    let final_fit = fit_joint(
        scene,
        photo,
        water,
        streaks,
        &paper.lights,
        &JointOptions {
            samples: options.final_samples,
            repeats: options.final_repeats,
            checkerboard: options.final_checkerboard,
            progress: options.progress,
            ..JointOptions::new(model_at(options, gloss), options.fit.seed)
        },
    )?;
    timings.push(("final joint fit".to_string(), t.elapsed().as_secs_f64()));
    let lights = final_fit
        .lights
        .iter()
        .zip(&final_fit.uncertainty)
        .map(|(l, u)| FittedLight {
            edges: joint::edge_statuses(l, u),
            ..l.clone()
        })
        .collect();
    Ok(GlossEstimate {
        gloss,
        sigma_ln: found.sigma_ln.map(|s| s as f32),
        evaluations: cost
            .evaluations
            .iter()
            .map(|&(x, s)| (x.exp() as f32, s))
            .collect(),
        lights,
        uncertainty: final_fit.uncertainty,
        residual_variance: final_fit.residual_variance,
        skipped: paper.skipped,
        warnings,
        timings,
    })
}

fn skipped_message(s: &Skipped) -> String {
    match s {
        Skipped::NoPlane { streak, message } | Skipped::NoSolution { streak, message } => {
            format!("streak {streak}: {message}")
        }
    }
}

/// The search's reflection model at `gloss`.
fn model_at(options: &GlossSearch, gloss: f32) -> ReflectionModel {
    ReflectionModel {
        gloss,
        ..options.fit.model
    }
}

/// The gloss whose lobe picks the fitted pixels for every candidate: a quarter of the start
/// (no lower than the search's floor), broad enough to hold the streaks of the candidates the
/// search visits from there. Costs are comparable only over the same pixels; with the region
/// following each candidate's own lobe, a broader lobe could add faint pixels and with them
/// cost (on the samples the streaks' boxes bound the region, so it did not change).
fn region_gloss(options: &GlossSearch) -> f32 {
    (options.fit.model.gloss / 4.0).max(options.min_gloss)
}

/// The cost of a candidate gloss, with a record of every evaluation.
struct Cost<'a> {
    scene: &'a Scene,
    photo: &'a Photo,
    water: &'a [bool],
    streaks: &'a [StreakObservation],
    start: &'a [FittedLight],
    options: &'a GlossSearch,
    /// (ln e, cost), in the order evaluated.
    evaluations: Vec<(f64, f64)>,
    /// Evaluations whose fit broke down (module doc), for a warning.
    failed: Vec<f32>,
}

impl Cost<'_> {
    /// The cost at `x = ln e` as a point of the curve.
    fn point(&mut self, x: f64) -> Result<Point> {
        let gloss = x.exp() as f32;
        if let Some(say) = self.options.progress {
            say(&format!(
                "gloss search: joint fit {} of at most {}, at e = {gloss:.0}",
                self.evaluations.len() + 1,
                self.options.max_evaluations
            ));
        }
        let fit = fit_joint(
            self.scene,
            self.photo,
            self.water,
            self.streaks,
            self.start,
            &JointOptions {
                samples: self.options.search_samples,
                sweeps: self.options.search_sweeps,
                // A wrong gloss leaves a structured residual too: splitting lights there
                // would fit the lobe's error, not a second light.
                split: false,
                region_gloss: Some(region_gloss(self.options)),
                ..JointOptions::new(model_at(self.options, gloss), self.options.fit.seed)
            },
        )?;
        let mut s = fit.cost;
        // The residuals hold the photo's own noise, so a cost that is not positive is the fit
        // exploiting its coefficients' noise (module doc): no evidence for this gloss.
        if !(s.is_finite() && s > 0.0) {
            self.failed.push(gloss);
            s = f64::INFINITY;
        }
        self.evaluations.push((x, s));
        Ok(Point {
            x,
            s,
            variance: fit.residual_variance,
        })
    }
}

/// A point of the cost curve: `x = ln e`, its cost and residual variance.
#[derive(Clone, Copy, Debug)]
struct Point {
    x: f64,
    s: f64,
    variance: f64,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Stop {
    Converged,
    AtLimit,
    OutOfEvaluations,
}

#[derive(Clone, Copy, Debug)]
struct Found {
    x: f64,
    sigma_ln: Option<f64>,
    stop: Stop,
}

/// Minimises `cost` over `x = ln e` in [lo, hi] from `x0` (module doc, "Search"); `cost`
/// gives the point at x (an infinite cost: no evidence there).
fn search(
    opts: &GlossSearch,
    x0: f64,
    lo: f64,
    hi: f64,
    mut cost: impl FnMut(f64) -> Result<Point>,
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
        pts.push(cost(x)?);
    }
    loop {
        pts.sort_by(|p, q| p.x.total_cmp(&q.x));
        let ib = (0..pts.len())
            .min_by(|&i, &j| pts[i].s.total_cmp(&pts[j].s))
            .expect("three points at least");
        let best = pts[ib];
        if !best.s.is_finite() {
            return Err(Error::NothingFound(format!(
                "the joint fit broke down at every gloss tried ({}): the gloss cannot be \
                 estimated from this photo",
                pts.iter()
                    .map(|p| format!("{:.0}", p.x.exp()))
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
        if pts.len() >= opts.max_evaluations {
            return Ok(Found {
                x: best.x,
                sigma_ln: None,
                stop: Stop::OutOfEvaluations,
            });
        }
        pts.push(cost(next)?);
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

    /// The search's options without a scene: the defaults of [`GlossSearch::for_scene`].
    fn options() -> GlossSearch {
        GlossSearch::starting_from(FitOptions {
            samples: 1,
            seed: 1,
            model: ReflectionModel::new(500.0, 1.33),
        })
    }

    /// Runs the search on `f(ln e)` from e = 500 in [50, 5000]; returns what it found and the
    /// points it evaluated.
    fn run(opts: &GlossSearch, f: impl Fn(f64) -> f64) -> (Found, Vec<f64>) {
        let mut xs = Vec::new();
        let found = search(opts, 500f64.ln(), 50f64.ln(), 5000f64.ln(), |x| {
            xs.push(x);
            Ok(pt(x, f(x)))
        })
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
        let all_broken = search(&options(), 6.0, 4.0, 8.0, |x| Ok(pt(x, f64::INFINITY)));
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
}
