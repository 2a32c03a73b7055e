//! The forward model the fits invert (method §4-5): how a pixel of the photo sees the water,
//! and which way the water sends the light it reflects towards the camera.
//!
//! Every fitter builds its coefficients from the same two questions, and asks them here:
//!
//! 1. where does the camera ray through a (jittered) image position meet the water, and with
//!    what frame for its reflection ([`WaterModel::water_point`]);
//! 2. from that point, which direction does a lobe sample take, and with what weight and
//!    density ([`WaterModel::reflect`], [`WaterModel::reflect_direction`]).
//!
//! A pixel's coefficient for a rectangle on a light's plane, `c(p; R)`, is then the mean over
//! the camera rays through the pixel's footprint and their lobe samples of the sample's
//! weight where its ray's first hit lies on the plane inside `R` (0 for a camera ray that
//! misses the water or a sample the model rejects). Tracing the reflected rays against the
//! scene's walls is the fitters' part: the water model says only how rays leave the water.
//! Who asks:
//!
//! - the paper's estimate (method §5 steps 7 and 9): the plane search
//!   ([`crate::fitting::light_plane::find_plane`]) and the per-pixel footprints
//!   ([`crate::fitting::footprint`]), one jittered camera ray per lobe sample
//!   ([`crate::fitting::light_plane::reflected_sample`]);
//! - the joint fit (method §5, last paragraph): the pixels whose lobes reach a light
//!   (`fitting::joint::region`, one ray from the pixel's centre and a grid of lobe
//!   directions), the stored plane samples (`fitting::joint::samples`, stratified camera rays
//!   each with a stratified set of lobe samples, and each sample's cell from its neighbours'
//!   directions), and the control variate's Gaussian (`fitting::joint::control_variate`,
//!   matched to a fixed grid of lobe samples of a pixel's first water point).
//!
//! Two models are meant to answer: [`ExactSurface`], the scene's water mesh is the photo's
//! water (the paper's setting, and the renderer's model); and a statistical one, where the
//! scene gives the mean surface and the waves are a distribution of slopes folded into the
//! lobe. The fitters take a `&dyn WaterModel` ([`crate::fitting::fit_paper_with`],
//! [`crate::fitting::joint::fit_joint_with`]); the plain entry points use the exact model.

pub mod draws;
pub mod exact;
pub mod mean_surface;
pub mod statistical;

use glam::{Vec2, Vec3};

pub use draws::LobeDraws;
pub use exact::ExactSurface;
pub use mean_surface::{clearly_wavy, water_statistics, MeanSurface, WaterStatistics};
pub use statistical::{StatisticalSurface, ViewedLobe};

use crate::optics::{LobeSample, ReflectionModel};
use crate::render::WaterPoint;
use crate::scene_in::Scene;

/// What the fitters need from the forward model: for a pixel of the photo, where its camera
/// rays meet the water and how its reflected lobe leaves it.
///
/// Frames and units: every point and direction is in the scene frame (camera-centred,
/// metres, as [`Scene`] holds them); image positions are in pixels of a `width` x `height`
/// image, fractional, (0, 0) the top-left corner of the top-left pixel.
///
/// An implementation must be deterministic (the same arguments give the same answer: the
/// fits' reproducibility and their common random numbers across parameter values rest on it)
/// and draws no random number of its own; one that samples its surface derives what it needs
/// from its arguments. It is shared by the fitters' threads (`Sync`), and shows itself in the
/// fits' options (`Debug`).
pub trait WaterModel: Sync + std::fmt::Debug {
    /// Where the camera ray through image position (`x`, `y`) of a `width` x `height` image
    /// meets the water, or `None` when it sees anything else first (or nothing): such a
    /// camera ray counts in the pixel's mean with weight 0.
    ///
    /// The point's `start` is where the reflected rays leave from (lifted off the surface on
    /// the camera's side, so that they do not hit the water they leave), `wo` the unit
    /// direction back to the camera, `normal` the lobe's axis and `face` the side of the
    /// surface the reflected rays must stay on. The fitters read only `start` themselves and
    /// hand the point back to [`reflect`](Self::reflect) and
    /// [`reflect_direction`](Self::reflect_direction), so a model may put in `normal` and
    /// `face` whatever its lobe needs (the exact model: the mesh's shading and geometric
    /// normals; a statistical one: the mean surface's).
    ///
    /// Used by the plane search and the footprints (one call per lobe sample), the joint
    /// fit's region (one per candidate pixel, at its centre) and its stored samples (one per
    /// stratified camera ray, shared by that ray's lobe samples and, for the pixel's first
    /// ray to meet the water, by its control variate).
    fn water_point(
        &self,
        scene: &Scene,
        x: f32,
        y: f32,
        width: u32,
        height: u32,
    ) -> Option<WaterPoint>;

    /// [`water_point`](Self::water_point) for each image position of `positions` (pixel
    /// units), into `points` (as long): the same points. A model that traces the camera's
    /// rays traces them together here (a pixel's camera rays run close together).
    fn water_points(
        &self,
        scene: &Scene,
        positions: &[Vec2],
        width: u32,
        height: u32,
        points: &mut [Option<WaterPoint>],
    ) {
        for (p, point) in positions.iter().zip(points) {
            *point = self.water_point(scene, p.x, p.y, width, height);
        }
    }

    /// The lobe sample of `point` for the uniform pair `u` in [0, 1)^2, under the microfacet
    /// model `model` (its gloss and IOR: the fits vary the gloss): the unit direction `wi`
    /// towards the light, its weight `f cos / pdf` (Fresnel and everything else included, so
    /// that the mean of `weight * L(wi)` over uniform `u` is the reflected radiance) and the
    /// solid-angle density `pdf` it was drawn with. `None` when it reflects nothing (the
    /// model rejects it, or it would leave below `face`): it still counts, with weight 0.
    ///
    /// The map from `u` to `wi` must be continuous and stratification-preserving: the joint
    /// fit stratifies `u` (through [`crate::optics::compact_strata`]) and sizes each sample's
    /// kernel by where directions a fraction of a stratum away land. A statistical model
    /// samples the microfacet lobe folded with its slope distribution.
    ///
    /// Used by every estimate of a coefficient (footprints, plane search, stored samples) and
    /// by the control variate's fixed grid of lobe directions.
    fn reflect(&self, point: &WaterPoint, model: &ReflectionModel, u: Vec2) -> Option<LobeSample>;

    /// The direction of [`reflect`](Self::reflect)'s sample for `u`, without its weight:
    /// whenever `reflect` gives a sample this gives its `wi`, and `None` exactly when it gives
    /// none. Used where only directions matter (the joint fit's region probe and the
    /// neighbours that measure a sample's cell), because it is cheaper.
    fn reflect_direction(
        &self,
        point: &WaterPoint,
        model: &ReflectionModel,
        u: Vec2,
    ) -> Option<Vec3>;

    /// What [`reflect`](Self::reflect) draws from each of `pairs` under `model` that depends
    /// on the pair and the lobe alone, made once for the many points that read the same
    /// pairs ([`draws`]). By default the pairs themselves.
    fn lobe_draws(&self, model: &ReflectionModel, pairs: &[Vec2]) -> LobeDraws {
        let _ = model;
        LobeDraws::pairs(pairs)
    }

    /// [`reflect`](Self::reflect) of `point` under `model` for the `i`-th pair of `draws`:
    /// the same sample to the last bit, from draws this model made for `model` without
    /// drawing again (from any others, drawn again from the pair).
    fn reflect_drawn(
        &self,
        point: &WaterPoint,
        model: &ReflectionModel,
        draws: &LobeDraws,
        i: usize,
    ) -> Option<LobeSample> {
        self.reflect(point, model, draws.pair(i))
    }

    /// [`reflect_drawn`](Self::reflect_drawn) of `point` for every pair of `draws` in
    /// order, into `out` (cleared first) as each sample's `wi` and weight, the pairs it
    /// rejects left out: the same samples to the last bit. A model may share what the
    /// point's samples have in common.
    fn reflect_all_drawn(
        &self,
        point: &WaterPoint,
        model: &ReflectionModel,
        draws: &LobeDraws,
        out: &mut Vec<(Vec3, f32)>,
    ) {
        reflect_each_drawn(self, point, model, draws, out);
    }
}

/// [`WaterModel::reflect_all_drawn`] one pair at a time, by
/// [`WaterModel::reflect_drawn`].
fn reflect_each_drawn<M: WaterModel + ?Sized>(
    water: &M,
    point: &WaterPoint,
    model: &ReflectionModel,
    draws: &LobeDraws,
    out: &mut Vec<(Vec3, f32)>,
) {
    out.clear();
    out.extend(
        (0..draws.len())
            .filter_map(|i| water.reflect_drawn(point, model, draws, i))
            .map(|s| (s.wi, s.weight)),
    );
}

#[cfg(test)]
mod tests;
