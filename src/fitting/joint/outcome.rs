//! What a joint fit returns ([`JointOutcome`]).

use super::problem::{Problem, State};
use super::uncertainty::{edge_statuses, facing_edges, Uncertainty, FACING_REASON};
use super::{ModelledPixel, PixelShare, Split};
use crate::fitting::{EdgeSide, EdgeStatus, FittedLight, Rect};
use crate::progress::Reporter;

/// The result of a joint fit.
#[derive(Clone, Debug)]
pub struct JointOutcome {
    /// The refined lights, in the order given.
    pub lights: Vec<FittedLight>,
    /// Their uncertainties, in the same order.
    pub uncertainty: Vec<Uncertainty>,
    /// Pixels in the fitted region: the water pixels and, with the direct view, those that
    /// see a light's wall directly.
    pub pixels: usize,
    /// Which pixels of its region the fit read ([`JointOptions::thin_seen_whole`](super::JointOptions::thin_seen_whole)).
    pub share: PixelShare,
    /// Residual sum of squares per pixel and channel at the optimum (radiance units squared).
    pub residual_variance: f64,
    /// The fit's cost at the optimum: the residual sum of squares less the samples' own noise
    /// (module doc); comparable between fits of the same pixels. Not positive when the fit
    /// has broken down (the photo's own noise keeps a sound fit's cost positive).
    pub cost: f64,
    /// Wall-clock seconds: "footprints" and "optimise".
    pub timings: Vec<(String, f64)>,
    /// The fitted water pixels (index `y * width + x` into the photo) with their modelled
    /// radiance at the optimum, per channel: the expected image the photo was compared with
    /// (the direct view's pixels left out).
    pub modelled: Vec<ModelledPixel>,
    /// Things the user should know: the lights dropped because the photo cannot tell them
    /// from nothing (`significance`), with why.
    pub warnings: Vec<String>,
    /// The start lights the fit explained as two, and which way
    /// ([`JointOptions::known_splits`](super::JointOptions::known_splits) of a refit).
    pub splits: Vec<Split>,
    /// Per fitted pixel, the scale its row was weighted by (`glitter`), when it was.
    pub row_scales: Option<Vec<f32>>,
    /// Whether the fit ended at its start, as its
    /// [`JointOptions::start_gate`](super::JointOptions::start_gate) said: then it has no
    /// light, and `modelled` is the start lights' expected image.
    pub stopped_at_start: bool,
    /// Whether the fit ended at its first split, as
    /// [`JointOptions::end_at_split`](super::JointOptions::end_at_split) asked: then it has
    /// no light, and [`splits`](Self::splits) holds that split.
    pub ended_at_split: bool,
    /// By start light as the fit took them (after the starts are moved onto and split by the
    /// lamps' direct images): the fitted rectangle of each the photo shows whole, every edge
    /// pinned by its direct image within a pixel's footprint
    /// ([`Uncertainty::image_bound`]) or not told by the photo (a flat cost, or a sigma larger
    /// than the light: the frame cuts the lamp there, and its reflections with it), else
    /// `None`. Its image holds it there
    /// whatever the water's lobe, so a search may too
    /// ([`JointOptions::held`](super::JointOptions::held)).
    pub seen_whole: Vec<Option<Rect>>,
}

impl JointOutcome {
    /// The outcome of a fit that fitted nothing, over the pixels `share` gives.
    pub(super) fn empty(share: PixelShare) -> Self {
        JointOutcome {
            lights: Vec::new(),
            uncertainty: Vec::new(),
            pixels: 0,
            share,
            residual_variance: 0.0,
            cost: 0.0,
            timings: Vec::new(),
            modelled: Vec::new(),
            warnings: Vec::new(),
            splits: Vec::new(),
            row_scales: None,
            stopped_at_start: false,
            ended_at_split: false,
            seen_whole: Vec::new(),
        }
    }

    /// [`seen_whole`](Self::seen_whole), for a search (`what`, as its progress lines name it)
    /// whose later fits hold those lights ([`JointOptions::held`](super::JointOptions::held));
    /// `progress` hears how many there are.
    pub fn to_hold(&self, what: &str, progress: Reporter<'_>) -> Vec<Option<Rect>> {
        let seen = self.seen_whole.iter().filter(|r| r.is_some()).count();
        if seen > 0 {
            progress.stage(&format!(
                "{what}: {seen} light(s) seen whole in the photo held where this fit put them"
            ));
        }
        self.seen_whole.clone()
    }

    /// The refined lights, each edge's status taken from its uncertainty ([`edge_statuses`]:
    /// an edge the photo does not constrain is marked so).
    pub fn lights_with_statuses(&self) -> Vec<FittedLight> {
        self.lights
            .iter()
            .zip(&self.uncertainty)
            .map(|(l, u)| FittedLight {
                edges: edge_statuses(l, u),
                ..l.clone()
            })
            .collect()
    }
}

/// By start light (of `starts`): the rectangle of each light of `st` whose direct image pins
/// it, unless a split made two lights of it ([`JointOutcome::seen_whole`]). Every edge is
/// pinned within a pixel's footprint (its `uncertainty`'s `image_bound`) or not told by the
/// photo (a flat cost, or a sigma larger than the light: where the frame cuts the lamp and
/// its reflections alike), and at least one is pinned.
pub(super) fn seen_whole(
    problem: &Problem,
    st: &State,
    uncertainty: &[Uncertainty],
    starts: usize,
) -> Vec<Option<Rect>> {
    let mut seen_whole: Vec<Option<Rect>> = vec![None; starts];
    for (k, u) in uncertainty.iter().enumerate() {
        let origin = problem.set_origin[st.set_of[k]];
        let alone =
            (0..st.rects.len()).all(|j| j == k || problem.set_origin[st.set_of[j]] != origin);
        let pinned = u.image_bound.iter().filter(|b| b.is_some()).count();
        let r = st.rects[k];
        let size = [r.u_max - r.u_min, r.v_max - r.v_min];
        // An edge whose sigma exceeds the light's size along it is one the photo does not
        // tell: the tails of a broad lobe reaching it are all that move the cost.
        let unseen = |e: usize| u.edges[e].is_none_or(|sigma| sigma > size[e / 2]);
        let settled = (0..4).all(|e| u.image_bound[e].is_some() || unseen(e));
        if alone && pinned > 0 && settled {
            seen_whole[origin] = Some(st.rects[k]);
        }
    }
    seen_whole
}

/// The lights of `st`, each with its start light's streaks and plane (from `start`) and its
/// edges' statuses: the start's, an edge facing another light of its streak unconstrained,
/// an edge the photo shows directly constrained by the pixels it crosses.
pub(super) fn fitted_lights(
    problem: &Problem,
    st: &State,
    start: &[FittedLight],
) -> Vec<FittedLight> {
    let facing = facing_edges(problem, st);
    (0..st.rects.len())
        .map(|k| {
            let origin = &start[problem.set_origin[st.set_of[k]]];
            let (r, rad) = (st.rects[k], st.radiance[k]);
            let direct = problem.direct_edge_pixels(st.set_of[k], &r);
            let mut edges = origin.edges.clone();
            for side in EdgeSide::ALL {
                if facing[k][side] {
                    edges[side] = EdgeStatus::Unconstrained {
                        reason: FACING_REASON.into(),
                        pixels: 0,
                        unseen: false,
                    };
                }
                // An edge the photo shows directly is constrained by the pixels it crosses,
                // whatever the reflections say of it.
                if direct[side] > 0 {
                    let reflected = match edges[side] {
                        EdgeStatus::Constrained { pixels } => pixels,
                        EdgeStatus::Unconstrained { .. } => 0,
                    };
                    edges[side] = EdgeStatus::Constrained {
                        pixels: reflected + direct[side],
                    };
                }
            }
            FittedLight {
                streak_ids: origin.streak_ids.clone(),
                plane: origin.plane.clone(),
                u_min: r.u_min,
                u_max: r.u_max,
                v_min: r.v_min,
                v_max: r.v_max,
                radiance: rad.map(|c| c as f32),
                edges,
            }
        })
        .collect()
}
