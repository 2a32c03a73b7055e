//! Fragments of one light as one streak: once the fitter has grouped the streaks of one light
//! ([`crate::fitting::fragments::group`]), each group becomes one streak, so that `segment`
//! lists lights, as `fit` fits them.

use super::{box_and_mean, brighter, number, Segmentation, Streak, StreakEdges};
use crate::photo_in::Photo;

impl Segmentation {
    /// The segmentation with each group of streaks (by their ids) merged into one streak, the
    /// streaks numbered again from left to right; a streak in no group stays alone. Each
    /// streak's [`Streak::fragments`] lists the ids (in `self`) of the streaks it is made of.
    pub fn merged(&self, photo: &Photo, groups: &[Vec<usize>]) -> Segmentation {
        let mut group_of: Vec<Option<usize>> = vec![None; self.streaks.len()];
        for (g, ids) in groups.iter().enumerate() {
            for &id in ids {
                if let Some(slot) = group_of.get_mut(id) {
                    slot.get_or_insert(g);
                }
            }
        }
        let mut members: Vec<Vec<&Streak>> = vec![Vec::new(); groups.len()];
        let mut streaks = Vec::new();
        for s in &self.streaks {
            match group_of.get(s.id).copied().flatten() {
                Some(g) => members[g].push(s),
                None => streaks.push(s.clone()),
            }
        }
        streaks.extend(
            members
                .iter()
                .filter(|m| !m.is_empty())
                .map(|m| union(photo, m)),
        );
        number(&mut streaks, self.width, self.height);
        Segmentation {
            streaks,
            ..self.clone()
        }
    }
}

/// One streak made of `parts`: their superpixels and pixels, the brightest of their brightest
/// pixels (the fitter's choice for a union, [`crate::fitting::fragments::merge`]).
fn union(photo: &Photo, parts: &[&Streak]) -> Streak {
    let w = photo.width;
    let mut pixels: Vec<u32> = parts
        .iter()
        .flat_map(|s| s.pixels.iter().copied())
        .collect();
    pixels.sort_unstable();
    let (bbox, mean_colour) = box_and_mean(photo, &pixels);
    let index = |p: (u32, u32)| p.1 * w + p.0;
    let brightest = parts
        .iter()
        .map(|s| index(s.brightest))
        .reduce(|a, b| brighter(&photo.radiance, a, b))
        .unwrap_or(0);
    let mut fragments: Vec<usize> = parts.iter().flat_map(|s| s.fragments.clone()).collect();
    fragments.sort_unstable();
    Streak {
        id: 0,
        superpixels: parts.iter().flat_map(|s| s.superpixels.clone()).collect(),
        pixels,
        bbox,
        brightest: (brightest % w, brightest / w),
        mean_colour,
        edges: StreakEdges::default(),
        fragments,
    }
}
