//! What the pipeline tells the user beyond the lights: why nothing was found, and a warning
//! for lights whose reflections overlap.

use std::collections::BTreeMap;

use super::{light_name, Input, THOROUGH};
use crate::fitting::{FittedLight, Skipped};
use crate::photo_in::Photo;
use crate::settings::Setting;
use crate::streaks::Segmentation;

/// Why the photo shows no reflection when every water pixel holds the same value.
pub(super) fn uniform_water(photo: &Photo, water: &[bool]) -> Option<String> {
    let mut seen = photo.display.iter().zip(water).filter(|(_, &w)| w);
    let (first, _) = seen.next()?;
    if seen.any(|(p, _)| p != first) {
        return None;
    }
    let clipped = photo
        .display
        .iter()
        .zip(&photo.clipped)
        .zip(water)
        .all(|((_, &c), &w)| !w || c);
    let value = first.map(|c| (c * 100.0).round());
    Some(if clipped {
        format!(
            "every water pixel is clipped (at the encoding's maximum, {}/{}/{} %): the photo is overexposed and shows no streak; lower the camera's exposure",
            value[0], value[1], value[2]
        )
    } else {
        format!(
            "every water pixel has the same value ({}/{}/{} % of full scale): the photo is blank and shows no streak; is it the right photo?",
            value[0], value[1], value[2]
        )
    })
}

/// Why no light was found: the photo is blank, it shows no streak, or no streak gave a light.
pub(super) fn nothing_found(
    uniform: Option<String>,
    segmentation: &Segmentation,
    skipped: &[Skipped],
) -> (Input, String) {
    if let Some(why) = uniform {
        return (Input::Photo, why);
    }
    if segmentation.streaks.is_empty() {
        let why = segmentation
            .require_streaks()
            .err()
            .map(|e| e.to_string())
            .unwrap_or_else(|| "no streak found".into());
        return (Input::Photo, why);
    }
    (
        Input::Scene,
        format!(
            "{} streak(s) found but no light could be fitted: {}",
            segmentation.streaks.len(),
            skipped
                .iter()
                .map(|s| match s {
                    Skipped::NoPlane { streak, message }
                    | Skipped::NoSolution { streak, message } => {
                        format!("streak {streak}: {message}")
                    }
                })
                .collect::<Vec<_>>()
                .join("; ")
        ),
    )
}

/// For each streak two or more of `lights` stand for (the joint fit split it, or one lamp's
/// direct image started each), those lights, unless every one of them is seen in the photo
/// itself (`seen`, by index): each lamp's direct image then pins its own light, and the photo
/// tells them apart to a fraction of a pixel (an orange lamp under a blue one: edges within
/// 0.03 %, radiances 0.6 %), where the reflections alone tell them apart only weakly.
fn lights_by_shared_streak(lights: &[FittedLight], seen: &[bool]) -> BTreeMap<usize, Vec<usize>> {
    let mut by_streak: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for (k, light) in lights.iter().enumerate() {
        for &streak in &light.streak_ids {
            by_streak.entry(streak).or_default().push(k);
        }
    }
    by_streak
        .retain(|_, ks| ks.len() > 1 && !ks.iter().all(|&k| seen.get(k).copied().unwrap_or(false)));
    by_streak
}

/// Whether two of `lights` stand for the same streak and the reflections alone must tell
/// them apart ([`lights_by_shared_streak`]).
pub(super) fn shares_a_streak(lights: &[FittedLight], seen: &[bool]) -> bool {
    !lights_by_shared_streak(lights, seen).is_empty()
}

/// One warning per set of lights that share streaks (overlapping reflections, split by the
/// joint fit; a light merged from two streaks and then split makes one warning naming both
/// streaks) and that the reflections alone must tell apart ([`lights_by_shared_streak`]):
/// the photo tells such lights apart only weakly, so their facing edges and
/// radiances can be off by several percent (on the bundled stacked sample from the
/// reflections alone, even with the refit over every pixel, 4-6 % rms over 20 seeds and up
/// to 11 % on one: BENCHMARKS.md, "From the reflections alone"). Their reported
/// uncertainties are as wide; the warning says why. Unless the fit already read every pixel
/// with at least [`THOROUGH`]'s samples (`thorough`), it also says how to fit such lights
/// more closely. Lights are named by [`light_name`] of their index.
pub(super) fn shared_streak_warnings(
    lights: &[FittedLight],
    seen: &[bool],
    thorough: bool,
) -> Vec<String> {
    let names: Vec<String> = (0..lights.len()).map(light_name).collect();
    let by_streak = lights_by_shared_streak(lights, seen);
    // Two streaks that one merged light spans make one warning, not one per streak.
    let mut by_lights: BTreeMap<Vec<&str>, Vec<usize>> = BTreeMap::new();
    for (streak, ks) in by_streak {
        let names = ks.iter().map(|&k| names[k].as_str()).collect();
        by_lights.entry(names).or_default().push(streak);
    }
    by_lights
        .into_iter()
        .map(|(names, streaks)| {
            let ids: Vec<String> = streaks.iter().map(|s| s.to_string()).collect();
            let (noun, verb) = if streaks.len() == 1 {
                ("streak", "holds")
            } else {
                ("streaks", "hold")
            };
            format!(
                "{noun} {} {verb} {} lights ({}), whose reflections overlap: the photo tells them \
                 apart only weakly where they meet, so their facing edges and radiances may be off \
                 by several percent (on the bundled stacked sample 8 % rms, up to about 25 %); \
                 their reported uncertainties are correspondingly wide{}",
                ids.join(", "),
                names.len(),
                names.join(", "),
                if thorough {
                    String::new()
                } else {
                    format!(
                        "; reading every pixel with {} samples ({}, {} {}) fits them about twice \
                         as closely, in about twice the time",
                        THOROUGH.samples,
                        Setting::AllPixels,
                        Setting::JointSamples,
                        THOROUGH.samples
                    )
                }
            )
        })
        .collect()
}
