//! Overlapping streaks, method §5 and the paper's §5.3: whether one light is better
//! explained as two, and which way to cut it (see [`super::optimise`](mod@super::optimise)).
//! Where the two lights meet is [`super::boundary`]'s work.

use super::problem::{Problem, State};
use crate::fitting::rect::Rect;
use crate::fitting::EdgeSide;
use crate::progress::Reporter;

/// Sweeps of the coarse fit that decides whether splitting a light pays, when they are
/// enough: few on purpose. The two halves of a trial read one sample set, and the longer they
/// descend the further their common boundary follows that set's noise, which the boundary
/// search then starts from. Measured on the stacked sample from the reflections alone over
/// fit seeds 1-20: with 3 sweeps the facing edges and radiances 4.1-5.6 % rms off (11.3 % at
/// worst), with 8 sweeps 6.6-16.3 % (43.8 %, four seeds beyond 20 %); over e = 1000 water
/// (seeds 1-8) 1.2 % rms at worst with 3, 1.1 % with 8 (BENCHMARKS.md, "From the
/// reflections alone").
const SPLIT_TRIAL_SWEEPS: u32 = 3;

/// Sweeps the trial goes on to when after [`SPLIT_TRIAL_SWEEPS`] the split does not pay yet:
/// the orange and blue lamps out of frame, whose halves must first sort out the colours, pay
/// only later. With none, halves still at the middle no longer remove the structure the split
/// test asks of them.
const SPLIT_TRIAL_MAX_SWEEPS: u32 = 8;

/// A split is kept when it at least halves the row-summed residual ([`Problem::row_cost`]).
/// Measured: two stacked lights fitted as one leave 7x the row cost of the split, a single
/// light split in two gains nothing (its row cost rises by a few percent). The per-pixel
/// cost cannot decide this: with the coefficients' noise removed it rewards any extra
/// freedom to place edges where that noise happens to be large.
const SPLIT_MIN_ROW_COST_RATIO: f64 = 0.5;

/// Which way a light is cut in two.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplitWay {
    /// One light above the other.
    Stacked,
    /// Side by side.
    SideBySide,
}

impl SplitWay {
    /// Both ways, in the order they are tried.
    pub const ALL: [SplitWay; 2] = [SplitWay::Stacked, SplitWay::SideBySide];

    /// The way in words, for the progress lines.
    pub fn words(self) -> &'static str {
        match self {
            SplitWay::Stacked => "one above the other",
            SplitWay::SideBySide => "side by side",
        }
    }
}

/// A light that a joint fit explained as two: its index among the fit's start lights, and
/// which way it was cut ([`super::JointOutcome::splits`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Split {
    /// The start light's index.
    pub light: usize,
    /// The way it was cut.
    pub way: SplitWay,
}

/// Tries to explain light k as two lights on its plane, each way of `ways` (one above the
/// other, side by side; overlapping streaks merge into one region, method §5 and the paper's
/// §5.3): each candidate starts from the rectangle cut in half and is fitted coarsely, the
/// other lights held ([`SPLIT_TRIAL_SWEEPS`] sweeps, on to [`SPLIT_TRIAL_MAX_SWEEPS`] when
/// the split does not pay by then). Returns the candidate with the lowest row-summed cost
/// among those below [`SPLIT_MIN_ROW_COST_RATIO`] times the unsplit state's, its way, and the
/// two edges that face each other (the first light's, then the second's, the new light last
/// in the state).
/// This only decides whether and which way to split: where the two lights meet is
/// [`search_boundary`](super::boundary::search_boundary)'s work. `progress` hears the count of
/// ways tried (each a descent of the two halves: about a second on the stacked sample).
pub(super) fn try_split(
    problem: &Problem,
    st: &State,
    k: usize,
    extents: &[Option<Rect>],
    ways: &[SplitWay],
    progress: Reporter<'_>,
) -> Option<(State, SplitWay, [EdgeSide; 2])> {
    let r = st.rects[k];
    let before = problem.row_cost(st);
    let mut best: Option<(State, SplitWay, [EdgeSide; 2], f64)> = None;
    for (done, &way) in ways.iter().enumerate() {
        progress.advance(done as u64, ways.len() as u64);
        let (first, second, inner) = match way {
            SplitWay::Stacked => (
                r.with_edge(EdgeSide::Top, 0.5 * (r.v_min + r.v_max)),
                r.with_edge(EdgeSide::Bottom, 0.5 * (r.v_min + r.v_max)),
                [EdgeSide::Top, EdgeSide::Bottom],
            ),
            SplitWay::SideBySide => (
                r.with_edge(EdgeSide::Right, 0.5 * (r.u_min + r.u_max)),
                r.with_edge(EdgeSide::Left, 0.5 * (r.u_min + r.u_max)),
                [EdgeSide::Right, EdgeSide::Left],
            ),
        };
        let mut set_of = st.set_of.clone();
        let mut pinned = st.pinned.clone();
        let mut rects = st.rects.clone();
        let mut radiance = st.radiance.clone();
        rects[k] = first;
        rects.push(second);
        set_of.push(st.set_of[k]);
        pinned.push(st.pinned[k]);
        radiance.push(st.radiance[k]);
        // Only the two halves move: the other lights stay at the optimum of the descent
        // before, so a trial sweeps over two lights rather than all of them (the descent
        // after a split moves them all).
        let held = (0..pinned.len())
            .map(|j| {
                if j == k || j == pinned.len() - 1 {
                    pinned[j]
                } else {
                    [true; 4]
                }
            })
            .collect();
        let mut trial = problem.state(set_of, held, rects, radiance);
        let mut windows = problem.descent_windows(&trial, &[]);
        let converged =
            problem.descend_windows(&mut trial, extents, SPLIT_TRIAL_SWEEPS, &mut windows, false);
        let pays = |trial: &State| {
            let both_lit = [k, trial.rects.len() - 1]
                .iter()
                .all(|&j| trial.radiance[j].iter().any(|&l| l > 0.0));
            let c = problem.row_cost(trial);
            (both_lit && c < SPLIT_MIN_ROW_COST_RATIO * before).then_some(c)
        };
        let mut paid = pays(&trial);
        if !converged && paid.is_none() {
            problem.descend_windows(
                &mut trial,
                extents,
                SPLIT_TRIAL_MAX_SWEEPS - SPLIT_TRIAL_SWEEPS,
                &mut windows,
                false,
            );
            paid = pays(&trial);
        }
        trial.pinned = pinned;
        let Some(c) = paid else {
            continue;
        };
        if best.as_ref().is_none_or(|(_, _, _, b)| c < *b) {
            best = Some((trial, way, inner, c));
        }
    }
    progress.advance(ways.len() as u64, ways.len() as u64);
    best.map(|(trial, way, inner, _)| (trial, way, inner))
}
