//! The joint fit's optimisation (method §5, last paragraph): a descent from the start lights,
//! then, for overlapping streaks, a split, a boundary search and another descent.
//!
//! Overlapping streaks (two lights whose reflections merge into one region, the paper's
//! §5.3): when the residual of a fit is structured along the image rows
//! ([`Problem::structured`]), each light is tried as two, one above the other or side by side
//! ([`try_split`]), and the split is kept when it removes most of that structure. A light the
//! photo shows whole (every edge pinned by its direct image within a pixel's footprint:
//! [`Problem::image_bounds`]; or, after a search, as its first fit found it:
//! `JointOutcome::seen_whole`) is not tried: it is one lamp's image, whose direct pixels
//! refuse a cut in half, and under the statistical model, whose residual is the glitter and
//! always structured, its trials were most of the final fit's time. The second
//! light of a split then reads a sample set of its own, drawn independently on the same
//! plane, and the boundary between the two is searched globally ([`search_boundary`]) before
//! the final descent. A repeat on other samples ([`Problem::replay`]) starts from where the
//! last descent started.

use super::boundary::{search_boundary, CANDIDATE_SWEEPS};
use super::problem::{Problem, State};
use super::samples::{sample_extent, PlaneSamples};
use super::split::{try_split, Split, SplitWay};
use crate::fitting::rect::Rect;
use crate::fitting::{EdgeSide, EdgeStatus, FittedLight};
use crate::progress::Reporter;

/// Fits the lights from `start`: a descent, then a split of any light whose residual is
/// structured (see [`try_split`]), the second light of each split given a sample set of its
/// own (`fresh(origin, draw)`: the `draw`-th extra set on start light `origin`'s plane) and
/// the boundary between the two placed by [`search_boundary`], and another descent. Returns
/// the optimum and the state its last descent started from (the start, or the split lights
/// after their boundary search): a repeat on other samples starts there (see
/// [`Problem::replay`]), and the splits made. A light of `known` (split by a fit before, from
/// the same start) is tried only the way that fit cut it. With `end_at_split` the fit
/// returns at its first accepted split, the two halves as the trial left them
/// ([`super::JointOptions::end_at_split`]). `progress` hears each split (so
/// that a fit announced with N lights that ends with more says why) and the count of
/// boundary candidates descended.
#[allow(clippy::too_many_arguments)]
pub(super) fn optimise(
    problem: &mut Problem,
    start: &[FittedLight],
    extents: &mut Vec<Option<Rect>>,
    sweeps: u32,
    split: bool,
    known: &[Split],
    end_at_split: bool,
    fresh: &dyn Fn(usize, u32) -> PlaneSamples,
    progress: Reporter<'_>,
    held: &[Option<Rect>],
    resume: &[Option<Rect>],
) -> (State, State, Vec<Split>) {
    let mut st = start_state(problem, start, extents, held, resume);
    let mut replay = st.clone();
    let near: Vec<bool> = (0..start.len())
        .map(|k| {
            resume.len() == start.len()
                && resume[k].is_some()
                && !(held.len() == start.len() && held[k].is_some())
        })
        .collect();
    problem.descend_near(&mut st, extents, sweeps, &near);
    let mut splits = Vec::new();
    // A light whose every edge its direct image pins (`image_bound`) is one lamp's image:
    // its reflections need no second light (lamps with images of their own start lights of
    // their own, `lamp_starts`), so it is not tried as two. So is one a search's first fit
    // found whole (`held`, `resume`: its edges pinned or beyond what the photo shows).
    let given = |rects: &[Option<Rect>], k: usize| rects.len() == start.len() && rects[k].is_some();
    let seen: Vec<bool> = if split {
        problem
            .image_bounds(&st)
            .iter()
            .enumerate()
            .map(|(k, b)| b.iter().all(Option::is_some) || given(held, k) || given(resume, k))
            .collect()
    } else {
        Vec::new()
    };
    if split && seen.contains(&false) && problem.structured(&st) {
        let tried: Vec<usize> = (0..start.len()).filter(|&k| !seen[k]).collect();
        let whole = start.len() - tried.len();
        progress.stage(&format!(
            "joint fit: the residual is structured, as where two lights' reflections merge \
             into one streak: trying light(s) {tried:?} as two{}",
            if whole > 0 {
                format!(" ({whole} seen whole in the photo, one lamp each, are not tried)")
            } else {
                String::new()
            }
        ));
        for k in tried {
            let ways = match known.iter().find(|s| s.light == k) {
                Some(s) => std::slice::from_ref(&s.way),
                None => &SplitWay::ALL[..],
            };
            let Some((trial, way, inner)) = try_split(problem, &st, k, extents, ways, progress)
            else {
                continue;
            };
            splits.push(Split { light: k, way });
            st = trial;
            let b = st.rects.len() - 1;
            let next = if end_at_split {
                "this fit ends here, to be made again with the split known".to_string()
            } else {
                format!("tracing light {b}'s own samples")
            };
            progress.stage(&format!(
                "joint fit: the residual of light {k} is structured, as where two lights' \
                 reflections merge into one streak: split into lights {k} and {b}, {}; {next}",
                way.words()
            ));
            if end_at_split {
                return (st.clone(), st, splits);
            }
            // The two lights of a split read independent samples: with one set shared, the
            // cost's noise along their common boundary has minima far from the truth
            // (BENCHMARKS.md, the stacked sample).
            let origin = problem.set_origin[st.set_of[k]];
            let draw = (problem.planes.len() - start.len()) as u32 + 1;
            let samples = fresh(origin, draw);
            extents.push(sample_extent(&samples));
            let set = problem.add_set(samples, origin);
            problem.move_to_set(&mut st, b, set);
            progress.stage(&format!(
                "joint fit: searching where lights {k} and {b} meet"
            ));
            let starts = search_boundary(problem, &st, k, b, inner);
            progress.stage(&format!(
                "joint fit: lights {k} and {b}: descents from {} candidate boundaries",
                starts.len()
            ));
            let candidates = starts.len() as u64;
            let mut best: Option<(State, f64)> = None;
            for (done, mut cand) in starts.into_iter().enumerate() {
                progress.advance(done as u64, candidates);
                problem.descend(&mut cand, extents, CANDIDATE_SWEEPS);
                let c = problem.cost(&cand);
                if best.as_ref().is_none_or(|(_, b)| c < *b) {
                    best = Some((cand, c));
                }
            }
            progress.advance(candidates, candidates);
            if let Some((cand, _)) = best {
                st = cand;
            }
        }
        if problem.planes.len() > start.len() {
            progress.stage(&format!(
                "joint fit: descent of the {} light(s) after the split",
                st.rects.len()
            ));
            replay = st.clone();
            problem.descend_with_pattern_moves(&mut st, extents, sweeps);
        }
    }
    (st, replay, splits)
}

/// The state a fit starts from: the `start` lights, each inside its samples' extent, with an
/// edge held where no streak-edge pixel looks at it and the photo does not show it directly;
/// a light `held` gives a rectangle (when it has one per start light) is there, all its
/// edges held ([`super::JointOptions::held`]).
pub(super) fn start_state(
    problem: &Problem,
    start: &[FittedLight],
    extents: &[Option<Rect>],
    held: &[Option<Rect>],
    resume: &[Option<Rect>],
) -> State {
    let given = |rects: &[Option<Rect>], k: usize| {
        rects
            .get(k)
            .copied()
            .flatten()
            .filter(|_| rects.len() == start.len())
    };
    let held = |k: usize| given(held, k);
    let rects: Vec<Rect> = start
        .iter()
        .zip(extents.iter())
        .enumerate()
        .map(|(k, (l, e))| {
            held(k)
                .or(given(resume, k))
                .unwrap_or_else(|| e.map_or(l.rect(), |e| l.rect().clamp_to(&e)))
        })
        .collect();
    // An edge no streak-edge pixel looks at is held, unless the photo shows it directly.
    let pinned = start
        .iter()
        .zip(&rects)
        .enumerate()
        .map(|(k, (l, r))| {
            let direct = problem.direct_edge_pixels(k, r);
            EdgeSide::ALL.map(|side| {
                held(k).is_some()
                    || matches!(
                        l.edges[side],
                        EdgeStatus::Unconstrained { unseen: true, .. }
                    ) && direct[side] == 0
            })
        })
        .collect();
    problem.state(
        (0..start.len()).collect(),
        pinned,
        rects,
        start.iter().map(|l| l.radiance.map(f64::from)).collect(),
    )
}

impl Problem {
    /// The fit that `optimise` made, repeated on this problem's samples: from `from`, the
    /// state its last descent started from, whose extra sample sets (one per light a split
    /// added, on start light `extra_origins[j]`'s plane) `fresh` draws anew, as in
    /// [`optimise`].
    pub(super) fn replay(
        &mut self,
        from: &State,
        extra_origins: &[usize],
        extents: &mut Vec<Option<Rect>>,
        sweeps: u32,
        fresh: &dyn Fn(usize, u32) -> PlaneSamples,
    ) -> State {
        for (draw, &origin) in extra_origins.iter().enumerate() {
            let samples = fresh(origin, draw as u32 + 1);
            extents.push(sample_extent(&samples));
            self.add_set(samples, origin);
        }
        let mut st = self.state(
            from.set_of.clone(),
            from.pinned.clone(),
            from.rects.clone(),
            from.radiance.clone(),
        );
        if extra_origins.is_empty() {
            self.descend(&mut st, extents, sweeps);
        } else {
            self.descend_with_pattern_moves(&mut st, extents, sweeps);
        }
        st
    }
}
