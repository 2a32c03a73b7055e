//! One trace for many lobes: a statistical water's stored samples weighted again for other
//! slope variances (importance sampling).
//!
//! Under the statistical model the camera rays meet the mean plane whatever the slopes, and
//! a lobe sample's direction `wi` depends on the variances only through where the draw puts
//! it. A sample drawn from a proposal lobe of density `pdf_p(wi)` estimates a target lobe's
//! coefficient with the weight `f_t(wo, wi) (n.wi) / pdf_p(wi)` (the target's BRDF, its
//! masking included, over the proposal's density). So one trace from a lobe at least as broad
//! as the targets serves every fit of a slope search: where the samples land, their kernels
//! and their halves stay; only their weights and each pixel's control variate (the Gaussian
//! matched to the target's lobe) change. The expectation is the target's. The noise changes:
//! for Gaussian slopes of variance `v_t` drawn from `v_p >= v_t` the effective share of the
//! samples per axis is `sqrt(v_t (2 v_p - v_t)) / v_p` (87 % at `v_p = 2 v_t`, 66 % at
//! `4 v_t`), while the kernels, sized by the proposal's strata, smooth more.
//!
//! What makes a search's costs compare is that its fits read one set of samples. A fit
//! minimises over its lights, and so fits some of its samples' noise; how much depends on
//! the samples, not only on the lobe. Measured on the known lobe of `tests/harbour_fit.rs`:
//! the cost over a grid of variances from one proposal had its minimum where the fits traced
//! at each variance had theirs, 1.5 % lower everywhere; a search that traced a new proposal
//! whenever a fit left the old one's range compared costs of different levels and came out
//! 7-18 % off (docs/decisions.md). A fit the proposal does not cover
//! ([`TARGET_OVER_PROPOSAL`]) traces its own samples.

use std::sync::OnceLock;

use glam::Vec3;
use rayon::prelude::*;

use super::control_variate::{lobe_directions, LobeGaussian};
use super::samples::PlaneSamples;
use crate::fitting::light_plane::LightPlane;
use crate::fitting::rect::Rect;
use crate::optics::ReflectionModel;
use crate::render::WaterPoint;
use crate::water_model::StatisticalSurface;

/// The target variances, per axis, as multiples of the proposal's, that a recorded trace
/// serves. Above 1 the target's lobe reaches where the proposal drew nothing (its truncated
/// tail: 0.5 % of the coefficients lost at 1.4) and the weights' variance grows without bound
/// from 2 on. Below, the samples' kernels, sized by the proposal's strata, grow against the
/// target's lobe (at 0.25 about twice its own strata), and the share of effective samples
/// falls (66 % per axis at 0.25).
pub const TARGET_OVER_PROPOSAL: (f32, f32) = (0.25, 1.0);

/// What a stored sample needs to be weighted for another lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct SampleLobe {
    /// The camera ray's direction back to the camera.
    pub wo: Vec3,
    /// The lobe sample's direction.
    pub wi: Vec3,
    /// The solid-angle density it was drawn with; 0 when the ray met something before the
    /// plane (its lobe weight is 0 under every lobe); negative for a direct pixel's sample,
    /// whose weight no lobe changes.
    pub pdf: f32,
    /// The same density per unit area of the plane (the control variate divides by it).
    pub area_pdf: f32,
}

impl SampleLobe {
    /// A direct pixel's sample.
    pub const DIRECT: SampleLobe = SampleLobe {
        wo: Vec3::ZERO,
        wi: Vec3::ZERO,
        pdf: -1.0,
        area_pdf: 0.0,
    };
}

/// One pixel's record from the trace: its stored samples' lobes in store order, the water
/// point its control variate was matched at (`None`: no camera ray met the water, or a
/// direct pixel), and the share of its camera rays that met the water.
#[derive(Clone, Debug, Default)]
pub(super) struct PixelRecord {
    pub lobes: Vec<SampleLobe>,
    pub water: Option<WaterPoint>,
    pub drew: f32,
}

/// A recorded trace: per plane, the lobes of its stored samples (in the plane's order), and
/// per pixel the control variate's water point and share.
pub(super) struct Recorded {
    pub lobes: Vec<Vec<SampleLobe>>,
    pub water: Vec<Option<WaterPoint>>,
    pub drew: Vec<f32>,
}

impl Recorded {
    /// Gathers the pixels' records into the planes' order (each pixel's samples of plane `k`
    /// in the order they were stored). `hits` and `records` per pixel, `counts` the samples
    /// per plane.
    pub fn gather<H>(
        per_pixel: Vec<(Vec<super::direct::Hit>, H, Option<Box<PixelRecord>>)>,
        planes: usize,
        counts: &[usize],
    ) -> Self {
        let mut lobes: Vec<Vec<SampleLobe>> =
            counts.iter().map(|&n| Vec::with_capacity(n)).collect();
        let mut water = Vec::with_capacity(per_pixel.len());
        let mut drew = Vec::with_capacity(per_pixel.len());
        for (hits, _, record) in per_pixel {
            let record = record.unwrap_or_default();
            for (hit, lobe) in hits.iter().zip(&record.lobes) {
                if let Some(l) = lobes.get_mut(hit.0 as usize) {
                    l.push(*lobe);
                }
            }
            water.push(record.water);
            drew.push(record.drew);
        }
        debug_assert_eq!(lobes.len(), planes);
        Recorded { lobes, water, drew }
    }
}

/// The samples of `plane` recorded under a proposal lobe (`base`, `lobes` its samples'
/// lobes, `water` and `drew` per pixel), weighted for the lobe of `target` under `model`
/// (module doc): each sample's weight is the target's `f cos` over the proposal's density,
/// less the target's control variate, and each pixel's Gaussian is matched to the target.
#[allow(clippy::too_many_arguments)]
pub(super) fn reweighted(
    base: &PlaneSamples,
    lobes: &[SampleLobe],
    water: &[Option<WaterPoint>],
    drew: &[f32],
    plane: &LightPlane,
    target: &StatisticalSurface,
    model: &ReflectionModel,
) -> PlaneSamples {
    let pixels = base.offsets.len() - 1;
    let gauss: Vec<LobeGaussian> = (0..pixels)
        .into_par_iter()
        .map(|i| match water[i] {
            Some(w) => {
                let (dirs, count) = lobe_directions(target, model, &w);
                let mut g = LobeGaussian::matched(plane, w.start, &dirs, count);
                g.mass *= drew[i];
                g
            }
            None => LobeGaussian::NONE,
        })
        .collect();
    let weights: Vec<f32> = (0..pixels)
        .into_par_iter()
        .flat_map_iter(|i| {
            let r = base.range(i);
            let g = gauss[i];
            let old = &base.weights[r.clone()];
            let points = &base.points[r.clone()];
            lobes[r]
                .iter()
                .zip(points)
                .zip(old)
                .map(move |((l, q), &w)| {
                    if l.pdf < 0.0 {
                        return w;
                    }
                    let lobe = if l.pdf > 0.0 {
                        target.eval_cos(model, l.wo, l.wi) / l.pdf
                    } else {
                        0.0
                    };
                    if l.area_pdf > 0.0 {
                        lobe - g.density(*q) / l.area_pdf
                    } else {
                        lobe
                    }
                })
        })
        .collect();
    PlaneSamples {
        offsets: base.offsets.clone(),
        bbox: base.bbox.clone(),
        points: base.points.clone(),
        cells: base.cells.clone(),
        weights,
        halves: base.halves.clone(),
        by_v: base.by_v.clone(),
        reach: base.reach.clone(),
        gauss,
        min_size: base.min_size,
        distance: base.distance,
    }
}

/// One trace under a proposal lobe, weighted for every target of a search it covers (module
/// doc). Given to the fits of a search through [`super::JointOptions::reweight`]; the first
/// fit it serves traces it. A fit it does not cover traces its own samples, as without it.
pub struct ProposalCache {
    /// The proposal: on each axis at least as broad as every target it serves.
    pub proposal: StatisticalSurface,
    pub(super) traced: OnceLock<ProposalTrace>,
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
    pub fn new(proposal: StatisticalSurface) -> Self {
        ProposalCache {
            proposal,
            traced: OnceLock::new(),
        }
    }

    /// Whether a fit under `target` (at the model's gloss `gloss`) is served: the same mean
    /// surface, and on each axis a total slope variance within [`TARGET_OVER_PROPOSAL`] of
    /// the proposal's.
    pub fn covers(&self, target: &StatisticalSurface, gloss: f32) -> bool {
        let (t, p) = (
            target.slopes(gloss).variance,
            self.proposal.slopes(gloss).variance,
        );
        let (lo, hi) = TARGET_OVER_PROPOSAL;
        target.surface == self.proposal.surface
            && (0..2).all(|a| (lo * p[a]..=hi * p[a]).contains(&t[a]))
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

/// A statistical water to fit under, and the cache whose trace may serve it.
#[derive(Clone, Copy, Debug)]
pub struct Reweight<'a> {
    pub cache: &'a ProposalCache,
    pub target: StatisticalSurface,
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
    /// [`super::samples::trace_samples`]) under `options`: the first set of the first
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
        if let Some(out) = shared.and_then(|rw| {
            from_proposal(
                &rw,
                self.scene,
                &options.model,
                planes,
                roi,
                self.pixels,
                self.size,
                (options.samples, options.seed),
                self.first_direct,
                options.progress,
            )
        }) {
            return out;
        }
        super::samples::trace_samples(
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
    /// The progress stage of a fit under this target (at the model's gloss `gloss`) over
    /// `pixels`, `planes` and `roi` that weighs the trace the cache already holds, tracing
    /// nothing; `None` for a fit that traces.
    pub(super) fn kept_trace_stage(
        &self,
        gloss: f32,
        pixels: &[u32],
        planes: &[&LightPlane],
        roi: &[Rect],
    ) -> Option<String> {
        let kept = self.cache.covers(&self.target, gloss)
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
/// planes or regions), and the fit traces its own.
#[allow(clippy::too_many_arguments)]
pub(super) fn from_proposal(
    rw: &Reweight<'_>,
    scene: &crate::scene_in::Scene,
    model: &ReflectionModel,
    planes: &[&LightPlane],
    roi: &[Rect],
    pixels: &[u32],
    size: (u32, u32),
    (samples, seed): (u32, u64),
    first_direct: usize,
    progress: crate::progress::Reporter<'_>,
) -> Option<(Vec<PlaneSamples>, u32)> {
    let cache = rw.cache;
    if !cache.covers(&rw.target, model.gloss) {
        return None;
    }
    let traced = cache.traced.get_or_init(|| {
        let (stored, per_pixel_samples, recorded) = super::samples::trace_recorded(
            &cache.proposal,
            scene,
            model,
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
                water: Vec::new(),
                drew: Vec::new(),
            }),
        }
    });
    if !traced.made_for(pixels, planes, roi) {
        return None;
    }
    let stored = (0..planes.len())
        .map(|k| {
            reweighted(
                &traced.stored[k],
                &traced.recorded.lobes[k],
                &traced.recorded.water,
                &traced.recorded.drew,
                planes[k],
                &rw.target,
                model,
            )
        })
        .collect();
    Some((stored, traced.per_pixel_samples))
}

#[cfg(test)]
mod tests {
    use super::super::fixture::{table3_light0, Table3Light0};
    use super::super::samples::trace_recorded;
    use super::*;
    use crate::fitting::slopes::{water_with_total, MICROFACET_GLOSS};
    use crate::water_model::water_statistics;

    /// Table 3's light0 over the statistical water of Table 3's mean plane.
    struct Case {
        t: Table3Light0,
        model: ReflectionModel,
        surface: crate::water_model::MeanSurface,
    }

    fn case() -> Case {
        let t = table3_light0();
        let stats = water_statistics(&t.scene, t.width, t.height).expect("water");
        Case {
            model: ReflectionModel::new(MICROFACET_GLOSS, t.model.ior),
            surface: stats.surface,
            t,
        }
    }

    impl Case {
        fn trace(
            &self,
            variance: [f32; 2],
            samples: u32,
            seed: u64,
        ) -> (Vec<PlaneSamples>, u32, Recorded) {
            let t = &self.t;
            let (stored, n, recorded) = trace_recorded(
                &water_with_total(self.surface, variance),
                &t.scene,
                &self.model,
                &[&t.light.plane],
                &[t.roi],
                &t.pixels,
                (t.width, t.height),
                (samples, seed, 0, 0),
                true,
                t.pixels.len(),
                true,
                crate::progress::Reporter::default(),
            );
            (stored, n, recorded.expect("recorded"))
        }

        fn weighted(
            &self,
            traced: &(Vec<PlaneSamples>, u32, Recorded),
            v: [f32; 2],
        ) -> PlaneSamples {
            let (stored, _, rec) = traced;
            reweighted(
                &stored[0],
                &rec.lobes[0],
                &rec.water,
                &rec.drew,
                &self.t.light.plane,
                &water_with_total(self.surface, v),
                &self.model,
            )
        }

        /// The coefficients of `rect` over the pixels: their sum, and the sum of their
        /// squares less their noise (what the fit's cost reads; it tells lobes apart where
        /// the sum, which a lobe only moves between pixels, does not).
        fn sums(&self, planes: &PlaneSamples, n: u32, rect: &Rect) -> (f64, f64) {
            (0..self.t.pixels.len())
                .map(|i| {
                    let (c, d) = planes.coefficient(i, rect, 1.0 / n as f32);
                    (c as f64, (c as f64).powi(2) - (d as f64).powi(2))
                })
                .fold((0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1))
        }
    }

    const TARGET: [f32; 2] = [2.6e-3, 2.4e-3];

    /// Weighted for the lobe it was drawn from, a sample keeps its weight (the lobe's `f cos`
    /// over its density is the sampler's weight) and a pixel its Gaussian.
    #[test]
    fn weighting_for_the_proposal_itself_changes_nothing() {
        let c = case();
        let traced = c.trace(TARGET, 32, 1);
        let again = c.weighted(&traced, TARGET);
        let stored = &traced.0[0];
        assert!(stored.weights.len() > 10_000, "{}", stored.weights.len());
        let scale = stored.weights.iter().fold(0f32, |m, w| m.max(w.abs()));
        for (a, b) in stored.weights.iter().zip(&again.weights) {
            assert!((a - b).abs() <= 1e-4 * scale, "{a} against {b}");
        }
        assert_eq!(stored.gauss, again.gauss);
    }

    /// From a proposal twice as broad on each axis, the weighted coefficients are the
    /// target's: for the light's rectangle and for a strip 0.3 m wide along its left edge,
    /// their sum over the pixels and their debiased sum of squares within 0.5 % of a plain
    /// trace's at the target with more samples (measured: 0.04-0.38 %). The proposal's own
    /// coefficients of the strip have a sum of squares 28 % under the target's, so the test
    /// tells the two lobes apart.
    #[test]
    fn a_broader_proposal_gives_the_targets_coefficients() {
        let c = case();
        let light = c.t.light.rect();
        let strip = Rect {
            u_max: light.u_min + 0.3,
            ..light
        };
        let rects = [light, strip];
        let broad = TARGET.map(|v| 2.0 * v);
        let seeds = 2;
        let (mut weighted, mut own) = ([(0f64, 0f64); 2], (0f64, 0f64));
        for seed in 1..=seeds {
            let traced = c.trace(broad, 128, seed);
            let w = c.weighted(&traced, TARGET);
            for (k, r) in rects.iter().enumerate() {
                let s = c.sums(&w, traced.1, r);
                weighted[k].0 += s.0 / seeds as f64;
                weighted[k].1 += s.1 / seeds as f64;
            }
            let s = c.sums(&traced.0[0], traced.1, &strip);
            own.0 += s.0 / seeds as f64;
            own.1 += s.1 / seeds as f64;
        }
        let (plain, n_plain, _) = c.trace(TARGET, 288, 7);
        for (k, r) in rects.iter().enumerate() {
            let want = c.sums(&plain[0], n_plain, r);
            for (got, want) in [(weighted[k].0, want.0), (weighted[k].1, want.1)] {
                assert!(
                    (got / want - 1.0).abs() < 0.005,
                    "rectangle {k}: weighted {got} against {want}"
                );
            }
        }
        let want = c.sums(&plain[0], n_plain, &strip);
        assert!(
            (own.1 / want.1 - 1.0).abs() > 0.05,
            "the proposal's own {own:?} against the target's {want:?}"
        );
    }

    /// A target broader than the proposal on either axis, or far narrower, is not served,
    /// nor one over another mean surface.
    #[test]
    fn the_cache_serves_only_targets_it_covers() {
        let c = case();
        let cache = ProposalCache::new(water_with_total(c.surface, [4e-3, 4e-3]));
        let at = |v: [f32; 2]| water_with_total(c.surface, v);
        let g = MICROFACET_GLOSS;
        assert!(cache.covers(&at([4e-3, 4e-3]), g));
        assert!(cache.covers(&at([1.1e-3, 3e-3]), g));
        assert!(!cache.covers(&at([4.2e-3, 3e-3]), g));
        assert!(!cache.covers(&at([3e-3, 0.9e-3]), g));
        let mut moved = at([3e-3, 3e-3]);
        moved.surface.point.y += 0.1;
        assert!(!cache.covers(&moved, g));
    }
}
