//! Fragments of one light (method §5 step 5): waves can break one light's streak into several
//! pieces. Pieces whose lights land on the same face and overlap are one light: their pixels are
//! merged and the union is fitted again.
//!
//! [`group`] decides which streaks are one light, and the joint fit's start merges lights
//! that start on one lamp's direct image (`joint::direct_start`): `fit` fits the
//! groups ([`super::fit_paper_with`]) and starts its joint fit from them, and `segment`
//! reports the streaks of the same lights ([`lights`]).

use super::observation::StreakObservation;
use super::single::{fit_streak, StageTimes};
use super::{FitOptions, FittedLight, Skipped};
use crate::photo_in::Photo;
use crate::scene_in::Scene;
use crate::water_model::WaterModel;

/// Which streaks are one light.
#[derive(Clone, Debug)]
pub struct Grouping {
    /// One entry per light: the union of its streaks as one observation, and the ids of
    /// those streaks (sorted); in the order of their first streak's coarse fit.
    pub groups: Vec<(StreakObservation, Vec<usize>)>,
    /// Streaks whose coarse fit gave no light (they are in no group).
    pub skipped: Vec<Skipped>,
    /// Unions that could not be fitted.
    pub warnings: Vec<String>,
    /// The coarse fit of each group, in the order of `groups` (empty when there was one
    /// streak: nothing to group, and nothing fitted).
    pub coarse: Vec<FittedLight>,
}

/// Groups the fragments of one light (method §5 step 5): every streak is fitted coarsely (an
/// eighth of `options`' samples: plenty to see whether two rectangles overlap, and merged
/// streaks are then traced in full only once), and pairs on one face whose rectangles
/// overlap are merged, the union refitted, until no such pair is left. A single streak is its
/// own group, unfitted.
pub fn group(
    water_model: &dyn WaterModel,
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    streaks: &[StreakObservation],
    options: &FitOptions,
) -> Grouping {
    let mut grouping = Grouping {
        groups: Vec::new(),
        skipped: Vec::new(),
        warnings: Vec::new(),
        coarse: Vec::new(),
    };
    if streaks.len() <= 1 {
        grouping.groups = streaks.iter().map(|s| (s.clone(), vec![s.id])).collect();
        return grouping;
    }
    let coarse = coarse_options(options);
    let mut scratch = StageTimes::default();
    let mut fitted: Vec<(StreakObservation, FittedLight)> = Vec::new();
    for obs in streaks {
        match fit_streak(water_model, scene, photo, water, obs, &coarse, &mut scratch) {
            Ok(light) => fitted.push((obs.clone(), light)),
            Err(s) => grouping.skipped.push(s),
        }
    }
    while let Some((i, j)) = overlapping_pair(fitted.iter().map(|f| &f.1)) {
        let (obs_j, light_j) = fitted.remove(j);
        let (obs_i, light_i) = fitted.remove(i);
        let mut ids: Vec<usize> = light_i
            .streak_ids
            .iter()
            .chain(&light_j.streak_ids)
            .copied()
            .collect();
        ids.sort_unstable();
        let refit = merge(&obs_i, &obs_j, photo).map(|m| {
            let fit = fit_streak(water_model, scene, photo, water, &m, &coarse, &mut scratch);
            (m, fit)
        });
        match refit {
            Some((m, Ok(mut light))) => {
                light.streak_ids = ids;
                fitted.insert(i, (m, light));
            }
            _ => {
                grouping.warnings.push(format!(
                    "streaks {} and {} overlap on one face but their union could not be \
                     fitted; kept streak {} alone",
                    obs_i.id, obs_j.id, obs_i.id
                ));
                fitted.insert(i, (obs_i, light_i));
            }
        }
    }
    (grouping.groups, grouping.coarse) = fitted
        .into_iter()
        .map(|(obs, light)| ((obs, light.streak_ids.clone()), light))
        .unzip();
    grouping
}

/// The options of [`group`]'s coarse fits for a fit with `options`: an eighth of its samples,
/// at least 32.
pub fn coarse_options(options: &FitOptions) -> FitOptions {
    FitOptions {
        samples: (options.samples / 8).max(32),
        ..*options
    }
}

/// The streaks of each light `fit` fits from `streaks` (by their ids, sorted; in the order of
/// the lights): the fragments [`group`] puts together, with the groups whose lights start on
/// one lamp's direct image merged, as the joint fit's start merges them
/// (`joint::direct_start::direct_starts`). Streaks that give no light are in no
/// group ([`Grouping::skipped`] says why).
pub fn lights(
    water_model: &dyn WaterModel,
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    streaks: &[StreakObservation],
    options: &FitOptions,
) -> (Vec<Vec<usize>>, Grouping) {
    let grouping = group(water_model, scene, photo, water, streaks, options);
    let groups = if grouping.coarse.is_empty() {
        grouping.groups.iter().map(|g| g.1.clone()).collect()
    } else {
        super::joint::direct_start::direct_starts(scene, photo, water, &grouping.coarse)
            .into_iter()
            .map(|l| l.streak_ids)
            .collect()
    };
    (groups, grouping)
}

/// The first pair (i, j), i < j, of lights on the same face whose rectangles overlap.
pub fn overlapping_pair<'a>(
    lights: impl IntoIterator<Item = &'a FittedLight>,
) -> Option<(usize, usize)> {
    let lights: Vec<&FittedLight> = lights.into_iter().collect();
    for i in 0..lights.len() {
        for j in i + 1..lights.len() {
            let (a, b) = (lights[i], lights[j]);
            if a.plane.same_face(&b.plane) && overlaps_in_plane(a, b) {
                return Some((i, j));
            }
        }
    }
    None
}

/// Overlap of two rectangles on the same face, whose frames may have different origins.
fn overlaps_in_plane(a: &FittedLight, b: &FittedLight) -> bool {
    let shift = a.plane.coords(b.plane.point);
    let rb = super::rect::Rect {
        u_min: b.u_min + shift.x,
        u_max: b.u_max + shift.x,
        v_min: b.v_min + shift.y,
        v_max: b.v_max + shift.y,
    };
    a.rect().overlaps(&rb)
}

/// The union of two streaks' pixels as one observation: edges recomputed for the union (an edge
/// pixel of one piece can be inside the other), brightest pixel the brighter of the two.
pub fn merge(
    a: &StreakObservation,
    b: &StreakObservation,
    photo: &Photo,
) -> Option<StreakObservation> {
    let pixels: Vec<u32> = a.pixels.iter().chain(&b.pixels).copied().collect();
    let mut merged = StreakObservation::from_pixels(
        a.id.min(b.id),
        pixels,
        photo.width,
        photo.height,
        &photo.radiance,
    )?;
    merged.brightest = crate::streaks::brighter(&photo.radiance, a.brightest, b.brightest);
    Some(merged)
}
