//! What a fit is asked to do, shaped so that no two settings can contradict each other: the
//! method carries its own settings (the paper's estimate has no joint-fit settings; estimating
//! the gloss is part of the joint fit's), and each value is held in one place.

use super::water_choice::WaterChoice;
use crate::fitting::gloss::GlossSearch;
use crate::fitting::joint::{PixelShare, DEFAULT_JOINT_SAMPLES};
use crate::fitting::{DEFAULT_SAMPLES, DEFAULT_START_SAMPLES, QUICK_START_SAMPLES};
use crate::optics::Shadowing;
use crate::settings::Setting;
use crate::streaks::StreakParams;
use crate::{Error, Result};

/// Everything [`super::fit`] needs besides the scene and the photo.
#[derive(Clone, Debug)]
pub struct FitSettings {
    /// Lobe samples per traced pixel of the paper's estimate (method §5 steps 7-9); `None`:
    /// [`DEFAULT_SAMPLES`], or [`DEFAULT_START_SAMPLES`] where the estimate starts the exact
    /// model's joint fit ([`Self::paper_samples`], [`Self::quick_start_samples`]). The
    /// edge solutions average over tens of pixels, so a few hundred suffice.
    pub samples: Option<u32>,
    /// Seed of every random number of the fit: the same inputs and seed give the same lights.
    pub seed: u64,
    /// Shadowing term of the reflection model (method §4).
    pub shadowing: Shadowing,
    /// Settings of the streak extraction (method §5 steps 3-6).
    pub streaks: StreakParams,
    /// How the lights are fitted.
    pub method: Method,
    /// Which model of the water the fit inverts (method §10).
    pub water: WaterChoice,
    /// Whether a night's smooth background (a dim sky, lit facades, their reflections) is
    /// measured away from the lights and taken off the photo before they are fitted
    /// ([`crate::background`]); a black night is left as it is either way.
    pub background: bool,
}

impl Default for FitSettings {
    /// The defaults of `streaklight fit`: the paper's estimate's samples by its use, seed 1,
    /// the paper's G = 1, the default streak extraction, the joint method with the scene's
    /// gloss, the water model chosen from the photo, the night's background taken off.
    fn default() -> Self {
        FitSettings {
            samples: None,
            seed: 1,
            shadowing: Shadowing::None,
            streaks: StreakParams::default(),
            method: Method::default(),
            water: WaterChoice::default(),
            background: true,
        }
    }
}

/// How the lights are fitted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// The paper's per-streak estimate alone, with streaklight's corrections (method §5).
    Paper,
    /// The paper's estimate, then every light refined together against every water pixel
    /// from which it can be seen (render and compare), a light split in two where the
    /// residual shows overlapping streaks, with per-parameter uncertainties.
    Joint(JointSettings),
}

impl Default for Method {
    /// The joint fit with its defaults.
    fn default() -> Self {
        Method::Joint(JointSettings::default())
    }
}

impl Method {
    /// "joint" or "paper".
    pub fn name(&self) -> &'static str {
        match self {
            Method::Joint(_) => "joint",
            Method::Paper => "paper",
        }
    }
}

/// What a joint fit reads: its samples per pixel and which pixels of its region.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Reading {
    /// Lobe samples per pixel, rounded by the fit to `8 b^2` (8, 32, 72, 128, ...;
    /// [`crate::fitting::joint::effective_samples`]). The time grows with them and the fit's
    /// own noise falls.
    pub samples: u32,
    /// Every pixel of the fitted region instead of a checkerboard half (one water pixel of
    /// each block on a photo of more than a megapixel, [`PixelShare::water_blocks`]):
    /// about twice the time (four times or more), less of both the samples' and the photo's
    /// noise.
    pub all_pixels: bool,
}

impl Reading {
    /// The joint fit's share of the pixels of a photo of `photo_pixels` pixels.
    pub fn share(&self, photo_pixels: u64) -> PixelShare {
        if self.all_pixels {
            PixelShare::All
        } else {
            PixelShare::water_blocks(photo_pixels)
        }
    }
}

/// The reading lights that share a streak are fitted again with by default.
pub const THOROUGH: Reading = Reading {
    samples: 128,
    all_pixels: true,
};

/// The settings of the joint fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointSettings {
    /// What the fit reads.
    pub reading: Reading,
    /// When the fit ends with lights that share a streak (it split an overlapping streak),
    /// fit again from the paper's estimate with this reading (`None`: keep the first fit).
    /// The photo tells such lights apart only weakly; reading every pixel with more samples
    /// halves their scatter on the bundled stacked samples, in about twice the time.
    pub overlap_refit: Option<Reading>,
    /// Independent fits, each from its own samples, whose mean is the result (at least 1):
    /// N times slower, about sqrt(N) times less of the samples' noise, with the fits' spread
    /// added to the uncertainties.
    pub repeats: u32,
    /// The water's gloss: the scene's, or estimated from the photo.
    pub gloss: GlossFit,
    /// Fit the pixels that see a light directly (above the water) too: where a light is in
    /// the photo, its direct image pins its edges ([`JointOptions::direct_view`]).
    ///
    /// [`JointOptions::direct_view`]: crate::fitting::joint::JointOptions::direct_view
    pub direct_view: bool,
}

impl Default for JointSettings {
    /// [`DEFAULT_JOINT_SAMPLES`] samples over a checkerboard half of the pixels, lights that
    /// share a streak fitted again with [`THOROUGH`], one repeat, the scene's gloss.
    fn default() -> Self {
        JointSettings {
            reading: Reading {
                samples: DEFAULT_JOINT_SAMPLES,
                all_pixels: false,
            },
            overlap_refit: Some(THOROUGH),
            repeats: 1,
            gloss: GlossFit::Given,
            direct_view: true,
        }
    }
}

impl JointSettings {
    /// Estimating the gloss with the default search (its fits read
    /// [`SEARCH_SAMPLES`](crate::fitting::gloss::SEARCH_SAMPLES) samples); the final fit at
    /// the estimate reads [`DEFAULT_JOINT_SAMPLES`] over a checkerboard, as a fit of a given
    /// gloss does, without a refit of lights that share a streak.
    pub fn estimating_gloss() -> Self {
        JointSettings {
            reading: Reading {
                samples: DEFAULT_JOINT_SAMPLES,
                all_pixels: false,
            },
            overlap_refit: None,
            repeats: 1,
            gloss: GlossFit::Estimate(GlossSearch::default()),
            direct_view: true,
        }
    }
}

impl JointSettings {
    /// These settings with what the fit reads chosen by the user: `samples` (when given)
    /// and every pixel (when `all_pixels`). A choice made stands for every light: when either
    /// is given, lights that share a streak are not fitted again with another reading.
    pub fn reading_chosen(mut self, samples: Option<u32>, all_pixels: bool) -> Self {
        if samples.is_some() || all_pixels {
            self.overlap_refit = None;
        }
        if let Some(samples) = samples {
            self.reading.samples = samples;
        }
        self.reading.all_pixels |= all_pixels;
        self
    }
}

/// Where the joint fit's gloss comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GlossFit {
    /// The scene's (its material's, or the loader's override).
    Given,
    /// Estimated from the photo together with the lights, starting from the scene's
    /// ([`crate::fitting::gloss`]): about 2-3 times the time of a fit.
    Estimate(GlossSearch),
}

impl FitSettings {
    /// The paper's estimate's samples per traced pixel under the water model `statistical`
    /// or the exact one: the ones asked for, else [`DEFAULT_START_SAMPLES`] where the
    /// estimate starts the exact model's joint fit and [`DEFAULT_SAMPLES`] where it is the
    /// result (the paper's method) or starts the statistical model's slope search (out of
    /// frame its fits descend from the start, and its noise moved their lights by tens of
    /// percent: docs/decisions.md), unless [`Self::quick_start_samples`]' first try is
    /// kept.
    pub fn paper_samples(&self, statistical: bool) -> u32 {
        self.samples.unwrap_or(match self.method {
            Method::Joint(_) if !statistical => DEFAULT_START_SAMPLES,
            _ => DEFAULT_SAMPLES,
        })
    }

    /// The samples per traced pixel of a first, cheaper paper's estimate that starts a joint
    /// fit under the water model `statistical` or the exact one: kept when every light it
    /// starts lies on a lamp's whole direct image, which then pins it
    /// ([`crate::fitting::joint::start_estimate`]). For the joint method unless `--samples`
    /// was given: [`QUICK_START_SAMPLES`] under the exact model, [`DEFAULT_START_SAMPLES`]
    /// under the statistical one, whose slope search read other variances from the fewer
    /// (docs/decisions.md).
    pub fn quick_start_samples(&self, statistical: bool) -> Option<u32> {
        match self.method {
            Method::Joint(_) if self.samples.is_none() => Some(if statistical {
                DEFAULT_START_SAMPLES
            } else {
                QUICK_START_SAMPLES
            }),
            _ => None,
        }
    }

    /// Refuses values out of range, naming the setting.
    pub fn validate(&self) -> Result<()> {
        if self.samples == Some(0) {
            return Err(Error::setting(Setting::Samples, "must be at least 1"));
        }
        if let Method::Joint(joint) = &self.method {
            for reading in std::iter::once(&joint.reading).chain(&joint.overlap_refit) {
                if reading.samples == 0 {
                    return Err(Error::setting(Setting::JointSamples, "must be at least 1"));
                }
            }
            if joint.repeats == 0 {
                return Err(Error::setting(Setting::Repeats, "must be at least 1"));
            }
        }
        self.streaks.seeds.validate()?;
        self.streaks.grow.validate()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A photo up to a megapixel reads a checkerboard, a larger one one water pixel of each
    /// block, and `all_pixels` every pixel at any size.
    #[test]
    fn the_share_follows_the_photo_size() {
        let default = JointSettings::default().reading;
        assert_eq!(default.share(600 * 600), PixelShare::Checkerboard);
        assert_eq!(default.share(1000 * 1000), PixelShare::Checkerboard);
        assert_eq!(default.share(1000 * 1000 + 1), PixelShare::WaterBlocks(2));
        assert_eq!(default.share(1920 * 1080), PixelShare::WaterBlocks(2));
        assert_eq!(default.share(4000 * 3000), PixelShare::WaterBlocks(4));
        for size in [600 * 600, 1920 * 1080] {
            assert_eq!(THOROUGH.share(size), PixelShare::All);
        }
    }

    /// The paper's estimate reads 128 samples where it only starts the exact model's joint
    /// fit (which tries 32 first), 512 where it is the result or the statistical model's
    /// start (which tries 128 first), and what was asked for wherever it was asked.
    #[test]
    fn the_paper_estimates_samples_follow_its_use() {
        let joint = FitSettings::default();
        assert_eq!(joint.paper_samples(false), 128);
        assert_eq!(joint.paper_samples(true), 512);
        assert_eq!(joint.quick_start_samples(false), Some(32));
        assert_eq!(joint.quick_start_samples(true), Some(128));
        let paper = FitSettings {
            method: Method::Paper,
            ..FitSettings::default()
        };
        assert_eq!(paper.paper_samples(false), 512);
        assert_eq!(paper.paper_samples(true), 512);
        assert_eq!(paper.quick_start_samples(false), None);
        assert_eq!(paper.quick_start_samples(true), None);
        for method in [Method::Paper, Method::default()] {
            let asked = FitSettings {
                samples: Some(64),
                method,
                ..FitSettings::default()
            };
            assert_eq!(asked.paper_samples(false), 64);
            assert_eq!(asked.paper_samples(true), 64);
            assert_eq!(asked.quick_start_samples(false), None);
            assert_eq!(asked.quick_start_samples(true), None);
        }
    }

    #[test]
    fn zero_samples_are_refused_by_name() {
        let no_samples = FitSettings {
            samples: Some(0),
            ..FitSettings::default()
        };
        let e = no_samples.validate().unwrap_err();
        assert!(matches!(
            e,
            Error::Setting {
                setting: Setting::Samples,
                ..
            }
        ));
        let joint = JointSettings {
            overlap_refit: Some(Reading {
                samples: 0,
                all_pixels: true,
            }),
            ..JointSettings::default()
        };
        let e = FitSettings {
            method: Method::Joint(joint),
            ..FitSettings::default()
        }
        .validate()
        .unwrap_err();
        assert_eq!(e.to_string(), "`Reading::samples` must be at least 1");
        assert!(FitSettings::default().validate().is_ok());
        assert!(FitSettings {
            method: Method::Paper,
            ..FitSettings::default()
        }
        .validate()
        .is_ok());
    }
}
