//! Lights the photo cannot tell from nothing, dropped before they are written.
//!
//! A fit can end with a light that explains almost nothing: the second light of a split that
//! took up a wrong lobe's error, a light whose radiance went to zero. Writing it would put a
//! lamp into the scene the photo does not show. Two measures decide:
//!
//! - its **share**: of the modelled light in the water pixels it lights, the part that is its
//!   own, weighted by its own contribution (`sum_p m_k(p)^2 / m(p) / sum_p m_k(p)`, `m_k`
//!   its modelled pixel, `m` all lights'). A light alone in its streak has share 1, however
//!   faint; two lights that share a streak evenly about one half each.
//! - its **significance**: its largest radiance channel in units of that channel's sigma.
//! - its **image's significance**: its whole modelled image (every fitted pixel, each channel)
//!   in units of the photo's noise, `sqrt(sum_p sum_c (m_k(p, c))^2 / s2)` with `s2` the
//!   fit's residual variance per pixel and channel: how far the photo without the light
//!   would lie from the photo with it.
//!
//! A light is dropped when its share is below [`MIN_SHARE`] (it explains almost nothing, as a
//! light of zero radiance), when its image's significance is below [`MIN_IMAGE_SIGNIFICANCE`]
//! (alone in its pixels, it lights them less than the photo's noise does), or when its share
//! is below [`WEAK_SHARE`] while no channel of its radiance is [`MIN_SIGNIFICANCE`] sigmas
//! from zero (the photo would look the same without it). A real faint light beside a bright
//! one is kept: its radiance is measured (the stacked samples' lower lights carry a third to
//! a half of their streak, at tens of sigmas). The radiance's significance alone cannot
//! stand for the image's: out of frame a real light's height trades against its radiance,
//! so its radiance's sigma can exceed its radiance while its reflection, the product, is
//! measured at tens of sigmas (the harbour lights out of frame: 34-250; the lights left at a
//! hundredth of their streak's radiance there: 1.2-2.7).

use super::problem::{Problem, State};
use super::uncertainty::Uncertainty;

/// A light's share below which it explains almost nothing.
pub(super) const MIN_SHARE: f64 = 0.01;

/// A light's share below which it is dropped unless its radiance is significant.
pub(super) const WEAK_SHARE: f64 = 0.25;

/// Sigmas from zero a radiance channel needs to count as measured.
pub(super) const MIN_SIGNIFICANCE: f64 = 2.0;

/// The photo's noise sigmas a light's whole modelled image needs to count as seen.
pub(super) const MIN_IMAGE_SIGNIFICANCE: f64 = 3.0;

/// Per light, its modelled image's significance (module doc).
pub(super) fn image_significance(problem: &Problem, st: &State) -> Vec<f64> {
    let variance = problem.residual_variance(st);
    (0..st.rects.len())
        .map(|k| {
            let l = st.radiance[k];
            let energy: f64 = st.coef[k]
                .iter()
                .map(|&c| l.iter().map(|&l| (c as f64 * l).powi(2)).sum::<f64>())
                .sum();
            (energy / variance).sqrt()
        })
        .collect()
}

/// Per light, its share of the modelled light in the water pixels it lights (module doc); 0
/// for a light that lights none.
pub(super) fn shares(problem: &Problem, st: &State) -> Vec<f64> {
    let lights = st.rects.len();
    let mut own = vec![0.0; lights];
    let mut weighted = vec![0.0; lights];
    let brightness: Vec<f64> = st.radiance.iter().map(|l| l.iter().sum()).collect();
    let mut per = vec![0.0; lights];
    for i in 0..problem.first_direct {
        for k in 0..lights {
            per[k] = st.coef[k][i].max(0.0) as f64 * brightness[k];
        }
        let all: f64 = per.iter().sum();
        if all <= 0.0 {
            continue;
        }
        for k in 0..lights {
            own[k] += per[k];
            weighted[k] += per[k] * per[k] / all;
        }
    }
    own.iter()
        .zip(&weighted)
        .map(|(&o, &w)| if o > 0.0 { w / o } else { 0.0 })
        .collect()
}

/// The lights to drop (indices, ascending) with why, from their shares and uncertainties
/// (module doc); never every light (the best-measured one stays: the caller has a streak
/// to explain).
pub(super) fn insignificant(
    problem: &Problem,
    st: &State,
    uncertainty: &[Uncertainty],
) -> Vec<(usize, String)> {
    let shares = shares(problem, st);
    let significance: Vec<f64> = (0..st.rects.len())
        .map(|k| {
            (0..3)
                .map(|c| {
                    let sigma = uncertainty.get(k).map_or(0.0, |u| u.radiance[c] as f64);
                    let l = st.radiance[k][c];
                    if sigma > 0.0 {
                        l / sigma
                    } else if l > 0.0 {
                        f64::INFINITY
                    } else {
                        0.0
                    }
                })
                .fold(0.0, f64::max)
        })
        .collect();
    let image = image_significance(problem, st);
    let mut drop: Vec<(usize, String)> = (0..st.rects.len())
        .filter_map(|k| {
            let (share, sig) = (shares[k], significance[k]);
            if share < MIN_SHARE {
                Some((
                    k,
                    format!(
                        "it explained {:.1} % of the light where it lit the water (under {:.0} %)",
                        100.0 * share,
                        100.0 * MIN_SHARE
                    ),
                ))
            } else if image[k] < MIN_IMAGE_SIGNIFICANCE {
                Some((
                    k,
                    format!(
                        "its whole modelled image came to {:.1} sigma of the photo's noise \
                         (under {MIN_IMAGE_SIGNIFICANCE:.0}): the photo cannot tell it from \
                         nothing",
                        image[k]
                    ),
                ))
            } else if share < WEAK_SHARE && sig < MIN_SIGNIFICANCE {
                Some((
                    k,
                    format!(
                        "it explained {:.0} % of the light where it lit the water and its \
                         radiance was within {sig:.1} sigma of zero: the photo cannot tell it \
                         from nothing",
                        100.0 * share
                    ),
                ))
            } else {
                None
            }
        })
        .collect();
    if drop.len() == st.rects.len() {
        // Keep the light that explains the most.
        let best = (0..shares.len())
            .max_by(|&a, &b| shares[a].total_cmp(&shares[b]))
            .unwrap_or(0);
        drop.retain(|(k, _)| *k != best);
    }
    drop
}

/// Removes light k from `st` (its sample set stays: another light may read it).
pub(super) fn remove(st: &mut State, k: usize) {
    st.set_of.remove(k);
    st.pinned.remove(k);
    st.rects.remove(k);
    st.radiance.remove(k);
    st.coef.remove(k);
    st.dev.remove(k);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fitting::rect::Rect;

    /// 20 water pixels; light k has coefficient `coef[k][i]` and radiance `radiance[k]`; the
    /// photo is the lights' image with noise of 0.01 (see [`noisy_case`]).
    fn case(coef: Vec<Vec<f32>>, radiance: Vec<[f64; 3]>) -> (Problem, State) {
        noisy_case(coef, radiance, 0.01)
    }

    /// [`case`] with the photo the lights' image plus or minus `noise` in every pixel and
    /// channel, alternately: the residual's mean square is `noise^2`.
    fn noisy_case(coef: Vec<Vec<f32>>, radiance: Vec<[f64; 3]>, noise: f64) -> (Problem, State) {
        let n = coef[0].len();
        let lights = coef.len();
        let obs = (0..n)
            .map(|i| {
                std::array::from_fn(|c| {
                    let m: f64 = (0..lights)
                        .map(|k| coef[k][i] as f64 * radiance[k][c])
                        .sum();
                    let sign = if (i + c) % 2 == 0 { 1.0 } else { -1.0 };
                    (m + sign * noise) as f32
                })
            })
            .collect();
        let problem = Problem {
            width: n as u32,
            pixel_ids: (0..n as u32).collect(),
            obs,
            clipped: vec![false; n],
            clipped_channels: vec![[false; 3]; n],
            planes: Vec::new(),
            set_origin: vec![0],
            inv_samples: 1.0,
            first_direct: n,
            encoding: (crate::photo_rounding::Rounding::Float, 1.0),
            edges_by_image: false,
        };
        let st = State {
            set_of: vec![0; lights],
            pinned: vec![[false; 4]; lights],
            rects: vec![Rect::around(glam::Vec2::ZERO, glam::Vec2::ONE); lights],
            radiance,
            dev: vec![vec![0.0; n]; lights],
            coef,
        };
        (problem, st)
    }

    fn sigma(radiance: f32) -> Uncertainty {
        Uncertainty {
            edges: [Some(0.1); 4],
            radiance: [radiance; 3],
            direct_pixels: 0,
            radiance_seen: false,
            image_bound: [None; 4],
            parts: [None; 7],
            radiance_response: [0.0; 4],
        }
    }

    /// `n` pixels of coefficient 1 from `from` on, 0 elsewhere (20 pixels in all).
    fn lit(from: usize, n: usize) -> Vec<f32> {
        (0..20)
            .map(|i| {
                if (from..from + n).contains(&i) {
                    1.0
                } else {
                    0.0
                }
            })
            .collect()
    }

    #[test]
    fn a_faint_light_alone_in_its_streak_has_all_of_it() {
        // A bright light on pixels 0-9, one a hundred times fainter on 10-19.
        let (p, st) = case(vec![lit(0, 10), lit(10, 10)], vec![[10.0; 3], [0.1; 3]]);
        let s = shares(&p, &st);
        assert_eq!(s, vec![1.0, 1.0]);
        // Even unmeasured (its radiance within 1 sigma), it explains its own pixels, which it
        // lights well above the photo's noise (0.01): kept.
        assert!(insignificant(&p, &st, &[sigma(0.1), sigma(0.2)]).is_empty());
    }

    #[test]
    fn a_light_alone_under_the_noise_is_dropped() {
        // The faint light's image: 0.1 in 3 channels of 10 pixels, sqrt(0.3) = 0.55 in all.
        // Over noise of 0.05 it stands at 11 sigma; over noise of 0.5, at 1.1: the photo
        // shows nothing there. The residual variance is the noise's over the 60 values less
        // the 14 parameters: 60/46 of its square.
        let lights = || (vec![lit(0, 10), lit(10, 10)], vec![[10.0; 3], [0.1; 3]]);
        let (c, r) = lights();
        let (p, st) = noisy_case(c, r, 0.05);
        let z = image_significance(&p, &st);
        let want = 0.3f64.sqrt() / (0.05 * (60.0f64 / 46.0).sqrt());
        assert!((z[1] - want).abs() < 1e-3 * want, "{z:?} against {want}");
        assert!(insignificant(&p, &st, &[sigma(0.1), sigma(0.2)]).is_empty());
        let (c, r) = lights();
        let (p, st) = noisy_case(c, r, 0.5);
        let drop = insignificant(&p, &st, &[sigma(0.1), sigma(0.2)]);
        assert_eq!(drop.iter().map(|d| d.0).collect::<Vec<_>>(), vec![1]);
        assert!(drop[0].1.contains("1.0 sigma"), "{}", drop[0].1);
    }

    #[test]
    fn a_light_under_another_is_dropped_only_when_unmeasured() {
        // Both on pixels 0-9, the second with a tenth of the first's radiance: its share in
        // every pixel is 1/11.
        let (p, st) = case(vec![lit(0, 10), lit(0, 10)], vec![[10.0; 3], [1.0; 3]]);
        let s = shares(&p, &st);
        assert!((s[0] - 10.0 / 11.0).abs() < 1e-12 && (s[1] - 1.0 / 11.0).abs() < 1e-12);
        // Measured at 4 sigma: kept.
        assert!(insignificant(&p, &st, &[sigma(0.1), sigma(0.25)]).is_empty());
        // Within 1.5 sigma of zero: dropped.
        let drop = insignificant(&p, &st, &[sigma(0.1), sigma(0.7)]);
        assert_eq!(drop.len(), 1);
        assert_eq!(drop[0].0, 1);
        assert!(drop[0].1.contains("9 %"), "{}", drop[0].1);
    }

    #[test]
    fn a_light_of_no_radiance_is_dropped_however_sure() {
        let (p, st) = case(vec![lit(0, 10), lit(5, 10)], vec![[10.0; 3], [0.0; 3]]);
        assert_eq!(shares(&p, &st)[1], 0.0);
        let drop = insignificant(&p, &st, &[sigma(0.1), sigma(1e-6)]);
        assert_eq!(drop.iter().map(|d| d.0).collect::<Vec<_>>(), vec![1]);
    }

    #[test]
    fn a_weak_light_under_a_strong_one_goes_and_a_lone_light_stays() {
        // Two lights sharing pixels 0-9 at 1 : 9, neither measured: the weak one goes.
        let (p, st) = case(vec![lit(0, 10), lit(0, 10)], vec![[1.0; 3], [9.0; 3]]);
        let drop = insignificant(&p, &st, &[sigma(10.0), sigma(10.0)]);
        assert_eq!(drop.iter().map(|d| d.0).collect::<Vec<_>>(), vec![0]);
        // A light alone stays, even at zero radiance: its streak has nothing else.
        let (p, st) = case(vec![lit(0, 10)], vec![[0.0; 3]]);
        assert!(insignificant(&p, &st, &[sigma(1.0)]).is_empty());
    }

    #[test]
    fn removing_a_light_keeps_the_others_in_order() {
        let (_, mut st) = case(
            vec![lit(0, 5), lit(5, 5), lit(10, 5)],
            vec![[1.0; 3], [2.0; 3], [3.0; 3]],
        );
        remove(&mut st, 1);
        assert_eq!(st.radiance, vec![[1.0; 3], [3.0; 3]]);
        assert_eq!(st.coef, vec![lit(0, 5), lit(10, 5)]);
        assert_eq!(st.rects.len(), 2);
    }
}
