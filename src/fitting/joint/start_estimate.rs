//! The paper's estimate that starts a joint fit, made with few samples where the lamps'
//! images pin its lights.
//!
//! A joint fit that reads the direct view starts each light whose lamp the photo shows whole
//! on that lamp's image ([`super::place_starts`]), and the image pins every edge of it within
//! a fraction of a pixel's footprint, whatever the start's noise. There the estimate only
//! has to say which streaks are which lamp's: a noisier one, from fewer lobe samples a
//! pixel, does that as well in a fraction of the time. Where a light it starts lies on no
//! whole image (out of frame, hidden, cut by the frame) the reflections alone place it and
//! every fit descends from the start, whose noise then moves the lights: the estimate is
//! made again at the full samples.

use std::sync::Mutex;

use super::direct_start::enclosing_image;
use crate::fitting::rect::Rect;
use crate::fitting::{FitOutcome, FittedLight};
use crate::photo_in::Photo;
use crate::progress::Reporter;
use crate::scene_in::Scene;
use crate::Result;

/// Start lights placed on their lamps' whole direct images.
pub struct PlacedStart {
    /// The lights, as the caller's `place` put them.
    pub lights: Vec<FittedLight>,
    /// Where each light's lamp ends (its whole direct image's rectangle and a pixel's
    /// footprint there), for the joint fits that start from them
    /// ([`JointOptions::start_images`](super::JointOptions::start_images)).
    pub images: Vec<Option<(Rect, f32)>>,
}

/// A caller's test of a first estimate not kept ([`start_estimate`]'s `unkept`): true ends
/// the start there.
pub type UnkeptTest<'a> = &'a dyn Fn(&FitOutcome) -> Result<bool>;

/// The estimate a joint fit starts from ([`start_estimate`]).
pub struct StartEstimate {
    /// The paper's estimate kept.
    pub fit: FitOutcome,
    /// Its lights as the caller's `place` put them, when the estimate with few samples was
    /// kept; `None` when the estimate was made at the full samples (not placed yet).
    pub placed: Option<PlacedStart>,
    /// Lobe samples per traced pixel of the kept estimate.
    pub samples: u32,
    /// Whether the caller's test of the first estimate not kept (`unkept`) ended it there:
    /// `fit` is that estimate, made at `samples`, and no estimate at the full samples was
    /// made.
    pub ended: bool,
}

/// The paper's estimate `estimate(samples)`, first at `quick` samples when given and fewer
/// than `full`: kept when `place` (telling the reporter it is given what it changes) puts
/// every light it starts on a lamp's whole direct image (module doc), else made again at
/// `full`. `progress` hears what placing the kept estimate changed, and nothing of an
/// estimate not kept. `unkept`, when given, is asked about a first estimate with lights that
/// is not kept, before the estimate at `full` is made: where it answers true, that estimate
/// is returned as it is ([`StartEstimate::ended`]).
#[allow(clippy::too_many_arguments)]
pub fn start_estimate(
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    quick: Option<u32>,
    full: u32,
    estimate: &dyn Fn(u32) -> Result<FitOutcome>,
    place: &dyn Fn(&FitOutcome, Reporter<'_>) -> Result<Vec<FittedLight>>,
    unkept: Option<UnkeptTest<'_>>,
    progress: Reporter<'_>,
) -> Result<StartEstimate> {
    if let Some(quick) = quick.filter(|&q| q < full) {
        let fit = estimate(quick)?;
        if !fit.lights.is_empty() {
            let heard: Mutex<Vec<String>> = Mutex::new(Vec::new());
            let hear = |line: &str| {
                if let Ok(mut lines) = heard.lock() {
                    lines.push(line.to_string());
                }
            };
            let placed = place(&fit, Reporter::new(&hear))?;
            let images: Option<Vec<(Rect, f32)>> = placed
                .iter()
                .map(|light| enclosing_image(scene, photo, water, light))
                .collect();
            if let Some(images) = images {
                for line in heard.into_inner().unwrap_or_default() {
                    progress.stage(&line);
                }
                return Ok(StartEstimate {
                    fit,
                    placed: Some(PlacedStart {
                        lights: placed,
                        images: images.into_iter().map(Some).collect(),
                    }),
                    samples: quick,
                    ended: false,
                });
            }
            if let Some(unkept) = unkept {
                if unkept(&fit)? {
                    return Ok(StartEstimate {
                        fit,
                        placed: None,
                        samples: quick,
                        ended: true,
                    });
                }
            }
        }
    }
    Ok(StartEstimate {
        fit: estimate(full)?,
        placed: None,
        samples: full,
        ended: false,
    })
}

#[cfg(test)]
mod tests {
    use std::sync::Mutex;

    use super::*;
    use crate::fitting::joint::place_starts;
    use crate::fitting::{fit_paper, FitOptions};
    use crate::progress::Reporter;

    /// The samples each estimate was made with, and what `start_estimate` kept, on sample
    /// photo `photo` with a first try at 32 and the full estimate at 128.
    fn tries(photo: &str) -> (Vec<u32>, StartEstimate) {
        let crate::samples::Fixture {
            scene,
            photo,
            water,
            observations,
        } = crate::samples::fixture(photo);
        let made = Mutex::new(Vec::new());
        let estimate = |samples: u32| {
            made.lock().unwrap().push(samples);
            fit_paper(
                scene,
                photo,
                water,
                observations,
                &FitOptions {
                    samples,
                    ..FitOptions::for_scene(scene)
                },
            )
        };
        let place = |fit: &FitOutcome, progress: Reporter<'_>| {
            Ok(place_starts(
                scene,
                photo,
                water,
                observations,
                &fit.lights,
                progress,
            ))
        };
        let kept = start_estimate(
            scene,
            photo,
            water,
            Some(32),
            128,
            &estimate,
            &place,
            None,
            Reporter::default(),
        )
        .unwrap();
        (made.into_inner().unwrap(), kept)
    }

    /// Table 1's lamp is in the photo, whole: the estimate at 32 samples is kept, its light
    /// placed on the lamp's image (within a footprint of it, so within a few of the truth).
    #[test]
    fn a_light_on_its_lamps_whole_image_keeps_the_quick_estimate() {
        let (made, kept) = tries("table1.png");
        assert_eq!(made, [32]);
        assert_eq!(kept.samples, 32);
        let placed = kept.placed.expect("placed");
        assert_eq!(placed.lights.len(), 1);
        assert_eq!(placed.images.len(), 1);
        let (image, footprint) = placed.images[0].expect("the lamp's whole image");
        let scene = &crate::samples::fixture("table1.png").scene;
        let truth =
            crate::fitting::joint::direct_start::tests::table1_rect(scene, &placed.lights[0].plane);
        for (got, want) in [
            (image.u_min, truth.u_min),
            (image.u_max, truth.u_max),
            (image.v_min, truth.v_min),
            (image.v_max, truth.v_max),
        ] {
            assert!(
                (got - want).abs() < 2.0 * footprint,
                "image edge {got} against {want} (footprint {footprint})"
            );
        }
    }

    /// Table 3's second lamp is cut by the photo's right border: the reflections alone place
    /// that light's far edge, so the estimate is made again at the full samples and not
    /// placed.
    #[test]
    fn a_lamp_cut_by_the_frame_makes_the_estimate_again_in_full() {
        let (made, kept) = tries("table3.png");
        assert_eq!(made, [32, 128]);
        assert_eq!(kept.samples, 128);
        assert!(kept.placed.is_none());
        assert_eq!(kept.fit.lights.len(), 2);
    }
}
