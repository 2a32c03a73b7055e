//! The trace a search over the water's lobe keeps ([`super::reweight`]): the lobe it was
//! drawn from (the proposal), which targets it serves, and the samples of a fit from it.

use std::sync::OnceLock;

use glam::Vec3;

use super::region::KeptRegion;
use super::reweight::{reweighted, Recorded};
use super::samples::PlaneSamples;
use crate::fitting::light_plane::LightPlane;
use crate::fitting::rect::Rect;
use crate::optics::{GaussianSlopes, ReflectionModel};
use crate::water_model::{ExactSurface, StatisticalSurface, ViewedLobe, WaterModel};

/// The target variances, per axis, as multiples of the proposal's, that a recorded trace
/// serves. Above 1 the target's lobe reaches where the proposal drew nothing (its truncated
/// tail: 0.5 % of the coefficients lost at 1.4) and the weights' variance grows without bound
/// from 2 on. Below, the samples' kernels, sized by the proposal's strata, grow against the
/// target's lobe (at 0.25 about twice its own strata), and the share of effective samples
/// falls (66 % per axis at 0.25).
pub const TARGET_OVER_PROPOSAL: (f32, f32) = (0.25, 1.0);

/// A lobe of the water as a search varies it: the water model, and the microfacets' gloss.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Lobe {
    /// The scene's water mesh (the exact model) with microfacets of gloss `gloss`: what the
    /// gloss search varies.
    Exact { gloss: f32 },
    /// A statistical water with microfacets of gloss `gloss`: the slope search varies its
    /// waves.
    Statistical {
        water: StatisticalSurface,
        gloss: f32,
    },
}

impl Lobe {
    /// Its total slope variance per axis (microfacets and waves).
    pub fn variance(&self) -> [f32; 2] {
        match self {
            Lobe::Exact { gloss } => GaussianSlopes::from_gloss(*gloss).variance,
            Lobe::Statistical { water, gloss } => water.slopes(*gloss).variance,
        }
    }

    /// The water model that draws it.
    pub fn water_model(&self) -> &dyn WaterModel {
        match self {
            Lobe::Exact { .. } => &ExactSurface,
            Lobe::Statistical { water, .. } => water,
        }
    }

    /// `model` at this lobe's gloss.
    pub fn model(&self, model: &ReflectionModel) -> ReflectionModel {
        let gloss = match self {
            Lobe::Exact { gloss } | Lobe::Statistical { gloss, .. } => *gloss,
        };
        ReflectionModel { gloss, ..*model }
    }

    /// Whether the camera rays meet the water at the same points under both lobes: both
    /// exact, or statistical over one mean surface.
    fn same_surface(&self, other: &Lobe) -> bool {
        match (self, other) {
            (Lobe::Exact { .. }, Lobe::Exact { .. }) => true,
            (Lobe::Statistical { water: a, .. }, Lobe::Statistical { water: b, .. }) => {
                a.surface == b.surface
            }
            _ => false,
        }
    }

    /// The lobe (`model` at its gloss, [`Self::model`]) seen from `wo` at a water point of
    /// lobe axis `normal`, for its `f cos` towards many directions ([`LobeAt::eval_cos`]).
    pub(super) fn at<'a>(&self, model: &'a ReflectionModel, normal: Vec3, wo: Vec3) -> LobeAt<'a> {
        match self {
            Lobe::Exact { .. } => LobeAt::Exact { model, normal, wo },
            Lobe::Statistical { water, .. } => LobeAt::Statistical(water.viewed(model, wo)),
        }
    }
}

/// A lobe seen from one direction ([`Lobe::at`]).
pub(super) enum LobeAt<'a> {
    Exact {
        model: &'a ReflectionModel,
        normal: Vec3,
        wo: Vec3,
    },
    Statistical(ViewedLobe),
}

impl LobeAt<'_> {
    /// `f cos` of the lobe for light arriving from `wi`.
    #[inline]
    pub(super) fn eval_cos(&self, wi: Vec3) -> f32 {
        match self {
            LobeAt::Exact { model, normal, wo } => model.eval_cos(*normal, *wo, wi),
            LobeAt::Statistical(lobe) => lobe.eval_cos(wi),
        }
    }
}

/// One trace under a proposal lobe, weighted for every target of a search it covers (module
/// doc). Given to the fits of a search through [`super::JointOptions::reweight`]; the first
/// fit it serves traces it. A fit it does not cover traces its own samples, as without it.
pub struct ProposalCache {
    /// The proposal: on each axis at least as broad as every target it serves.
    pub proposal: Lobe,
    pub(super) traced: OnceLock<ProposalTrace>,
    /// The pixels of the search's first fit, which its later fits read again where their
    /// region's key is the same.
    pub(super) region: OnceLock<KeptRegion>,
}

/// The recorded trace, with what it was traced for: a fit whose pixels, planes or regions
/// differ traces its own.
pub(super) struct ProposalTrace {
    pub pixels: Vec<u32>,
    pub planes: Vec<LightPlane>,
    pub roi: Vec<Rect>,
    pub stored: Vec<PlaneSamples>,
    pub per_pixel_samples: u32,
    pub recorded: Recorded,
}

impl ProposalCache {
    /// An empty cache for `proposal`.
    pub fn new(proposal: Lobe) -> Self {
        ProposalCache {
            proposal,
            traced: OnceLock::new(),
            region: OnceLock::new(),
        }
    }

    /// Whether a fit under `target` is served: the same water surface, and on each axis a
    /// total slope variance within [`TARGET_OVER_PROPOSAL`] of the proposal's.
    pub fn covers(&self, target: &Lobe) -> bool {
        let (t, p) = (target.variance(), self.proposal.variance());
        let (lo, hi) = TARGET_OVER_PROPOSAL;
        target.same_surface(&self.proposal)
            && (0..2).all(|a| (lo * p[a]..=hi * p[a]).contains(&t[a]))
    }

    /// Whether a fit under `target` would weigh a trace already made: [`Self::covers`], and
    /// a fit has traced it.
    pub fn serves_traced(&self, target: &Lobe) -> bool {
        self.covers(target) && self.traced.get().is_some()
    }
}

impl ProposalTrace {
    /// Whether the trace was made for these pixels, planes and regions.
    fn made_for(&self, pixels: &[u32], planes: &[&LightPlane], roi: &[Rect]) -> bool {
        self.pixels == pixels
            && self.roi == roi
            && self.planes.len() == planes.len()
            && self.planes.iter().zip(planes).all(|(a, b)| a == *b)
            && self.recorded.lobes.len() == planes.len()
    }
}

impl std::fmt::Debug for ProposalCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ProposalCache")
            .field("proposal", &self.proposal)
            .field("traced", &self.traced.get().is_some())
            .finish()
    }
}

/// The lobe a fit is made under, and the cache whose trace may serve it. The fit's water
/// model and its model's gloss must be the target's.
#[derive(Clone, Copy, Debug)]
pub struct Reweight<'a> {
    pub cache: &'a ProposalCache,
    pub target: Lobe,
}

/// What every sample set of one joint fit is traced for: its water model, scene, fitted
/// pixels (of a `size` image; from `first_direct` on, the pixels that see the walls
/// directly).
pub(super) struct FitSamples<'a> {
    pub water_model: &'a dyn crate::water_model::WaterModel,
    pub scene: &'a crate::scene_in::Scene,
    pub pixels: &'a [u32],
    pub size: (u32, u32),
    pub first_direct: usize,
}

impl FitSamples<'_> {
    /// The samples of `planes` inside `roi` for repeat `repeat` and draw `draw` (see
    /// [`super::trace::trace_samples`]) under `options`: the first set of the first
    /// repeat weighted from the proposal's trace where `options.reweight` covers the fit,
    /// every other set traced.
    pub fn samples(
        &self,
        options: &super::JointOptions<'_>,
        planes: &[&LightPlane],
        roi: &[Rect],
        repeat: u32,
        draw: u32,
    ) -> (Vec<PlaneSamples>, u32) {
        let shared = options
            .reweight
            .filter(|_| repeat == 0 && draw == 0 && options.control_variate);
        // Where every light is held, only the samples whose kernels reach its rectangle
        // are ever read.
        let held: Option<Vec<Rect>> = (options.held.len() == planes.len())
            .then(|| options.held.iter().copied().collect::<Option<Vec<Rect>>>())
            .flatten();
        if let Some(out) = shared.and_then(|rw| {
            from_proposal(
                &rw,
                self.scene,
                &options.model,
                planes,
                roi,
                held.as_deref(),
                self.pixels,
                self.size,
                (options.samples, options.seed),
                self.first_direct,
                options.progress,
            )
        }) {
            return out;
        }
        super::trace::trace_samples(
            self.water_model,
            self.scene,
            &options.model,
            planes,
            roi,
            self.pixels,
            self.size.0,
            self.size.1,
            options.samples,
            options.seed,
            repeat,
            draw,
            options.control_variate,
            self.first_direct,
            options.progress,
        )
    }
}

impl Reweight<'_> {
    /// The progress stage of a fit under this target over `pixels`, `planes` and `roi` that
    /// weighs the trace the cache already holds, tracing nothing; `None` for a fit that
    /// traces.
    pub(super) fn kept_trace_stage(
        &self,
        pixels: &[u32],
        planes: &[&LightPlane],
        roi: &[Rect],
    ) -> Option<String> {
        let kept = self.cache.covers(&self.target)
            && self
                .cache
                .traced
                .get()
                .is_some_and(|t| t.made_for(pixels, planes, roi));
        kept.then(|| {
            format!(
                "joint fit: weighting the search's traced samples of {} pixels for this lobe",
                pixels.len()
            )
        })
    }
}

/// The samples of a fit under `rw.target` from the proposal's trace, traced on first use
/// (with `model`, the fit's pixels `pixels` of a `size` image, `samples` per pixel and
/// `seed`; the pixels from `first_direct` on see the walls directly): `None` when the trace
/// cannot serve this fit (the target is not covered, or the trace was made for other pixels,
/// planes or regions), and the fit traces its own. With `held` (a rectangle per plane, each
/// light held there), only the samples a held light's coefficients read are weighted
/// ([`reweighted`]).
#[allow(clippy::too_many_arguments)]
pub(super) fn from_proposal(
    rw: &Reweight<'_>,
    scene: &crate::scene_in::Scene,
    model: &ReflectionModel,
    planes: &[&LightPlane],
    roi: &[Rect],
    held: Option<&[Rect]>,
    pixels: &[u32],
    size: (u32, u32),
    (samples, seed): (u32, u64),
    first_direct: usize,
    progress: crate::progress::Reporter<'_>,
) -> Option<(Vec<PlaneSamples>, u32)> {
    let cache = rw.cache;
    if !cache.covers(&rw.target) {
        return None;
    }
    let traced = cache.traced.get_or_init(|| {
        let (stored, per_pixel_samples, recorded) = super::trace::trace_recorded(
            cache.proposal.water_model(),
            scene,
            &cache.proposal.model(model),
            planes,
            roi,
            pixels,
            size,
            (samples, seed, 0, 0),
            true,
            first_direct,
            true,
            progress,
        );
        ProposalTrace {
            pixels: pixels.to_vec(),
            planes: planes.iter().map(|p| (*p).clone()).collect(),
            roi: roi.to_vec(),
            stored,
            per_pixel_samples,
            recorded: recorded.unwrap_or(Recorded {
                lobes: Vec::new(),
                rays: Vec::new(),
                water: Vec::new(),
                drew: Vec::new(),
            }),
        }
    });
    if !traced.made_for(pixels, planes, roi) {
        return None;
    }
    let stored = reweighted(
        &traced.stored,
        &traced.recorded.lobes,
        &traced.recorded.rays,
        &traced.recorded.water,
        &traced.recorded.drew,
        planes,
        &rw.target,
        model,
        held,
    );
    Some((stored, traced.per_pixel_samples))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fitting::slopes::{water_with_total, MICROFACET_GLOSS};
    use crate::water_model::MeanSurface;

    /// A target broader than the proposal on either axis, or far narrower, is not served,
    /// nor one over another mean surface or under the other water model.
    #[test]
    fn the_cache_serves_only_targets_it_covers() {
        let surface = MeanSurface::new(Vec3::new(0.0, -1.0, 0.0), Vec3::Y, Vec3::Z, Vec3::Y);
        let at = |v: [f32; 2]| Lobe::Statistical {
            water: water_with_total(surface, v),
            gloss: MICROFACET_GLOSS,
        };
        let cache = ProposalCache::new(at([4e-3, 4e-3]));
        assert!(cache.covers(&at([4e-3, 4e-3])));
        assert!(cache.covers(&at([1.1e-3, 3e-3])));
        assert!(!cache.covers(&at([4.2e-3, 3e-3])));
        assert!(!cache.covers(&at([3e-3, 0.9e-3])));
        let mut moved = water_with_total(surface, [3e-3, 3e-3]);
        moved.surface.point.y += 0.1;
        assert!(!cache.covers(&Lobe::Statistical {
            water: moved,
            gloss: MICROFACET_GLOSS
        }));
        assert!(!cache.covers(&Lobe::Exact { gloss: 300.0 }));

        // Gloss e has variance 1 / (e + 2): from e = 100, the glosses 100-406 are served (1 / 408 a quarter of 1 / 102).
        let cache = ProposalCache::new(Lobe::Exact { gloss: 100.0 });
        for (gloss, served) in [
            (99.0, false),
            (100.0, true),
            (250.0, true),
            (400.0, true),
            (420.0, false),
        ] {
            assert_eq!(cache.covers(&Lobe::Exact { gloss }), served, "{gloss}");
        }
        assert!(!cache.covers(&at([4e-3, 4e-3])));
    }
}
