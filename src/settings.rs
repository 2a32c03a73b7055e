//! The settings a message may name, in the library's own terms.
//!
//! The library never speaks of command-line flags. A message that tells the user which
//! setting to change names it by [`Setting`], shown as the library's field (for example
//! `` `LoadOptions::water` ``); a front end maps each to its own spelling (the command line
//! turns that into `--water`) with [`reword`].

use std::fmt;

/// A setting of the library that messages refer to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Setting {
    /// Which camera of the scene took the photo.
    Camera,
    /// Which mesh node is the water.
    Water,
    /// The water's gloss exponent `e`, overriding its material's.
    Gloss,
    /// Estimating the gloss from the photo ([`crate::pipeline::GlossFit::Estimate`]).
    GlossEstimate,
    /// The water's index of refraction.
    Ior,
    /// Light intensity units per unit of radiance.
    NitsScale,
    /// The photo's exposure (its linear values are divided by it).
    Exposure,
    /// Lobe samples per traced pixel of the paper's estimate.
    Samples,
    /// The paper's estimate alone ([`crate::pipeline::Method::Paper`]).
    PaperMethod,
    /// Lobe samples per pixel of the joint fit.
    JointSamples,
    /// The joint fit reads every pixel of its region, not a checkerboard half.
    AllPixels,
    /// Independent joint fits averaged.
    Repeats,
    /// Writing the scene unchanged when no light is found.
    AllowEmpty,
    /// Camera rays per pixel of a render.
    RenderSamples,
}

impl Setting {
    /// Every setting.
    pub const ALL: [Setting; 14] = [
        Setting::Camera,
        Setting::Water,
        Setting::Gloss,
        Setting::GlossEstimate,
        Setting::Ior,
        Setting::NitsScale,
        Setting::Exposure,
        Setting::Samples,
        Setting::PaperMethod,
        Setting::JointSamples,
        Setting::AllPixels,
        Setting::Repeats,
        Setting::AllowEmpty,
        Setting::RenderSamples,
    ];

    /// The library's name of the setting: the field or variant that holds it.
    pub fn name(self) -> &'static str {
        match self {
            Setting::Camera => "LoadOptions::camera",
            Setting::Water => "LoadOptions::water",
            Setting::Gloss => "LoadOptions::gloss",
            Setting::GlossEstimate => "GlossFit::Estimate",
            Setting::Ior => "LoadOptions::ior",
            Setting::NitsScale => "LoadOptions::nits_scale",
            Setting::Exposure => "exposure",
            Setting::Samples => "FitSettings::samples",
            Setting::PaperMethod => "Method::Paper",
            Setting::JointSamples => "Reading::samples",
            Setting::AllPixels => "Reading::all_pixels",
            Setting::Repeats => "JointSettings::repeats",
            Setting::AllowEmpty => "ConvertOptions::allow_empty",
            Setting::RenderSamples => "RenderOptions::samples_per_pixel",
        }
    }
}

/// Shown as the library's name in backticks, the form [`reword`] recognises.
impl fmt::Display for Setting {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "`{}`", self.name())
    }
}

/// `text` with every setting it names (as [`Setting`]'s `Display` writes them) spelled by
/// `spell` instead: how a front end shows library messages in its own terms.
pub fn reword(text: &str, spell: impl Fn(Setting) -> String) -> String {
    let mut out = text.to_owned();
    for setting in Setting::ALL {
        let mention = setting.to_string();
        if out.contains(&mention) {
            out = out.replace(&mention, &spell(setting));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_setting_has_its_own_name() {
        let mut names: Vec<&str> = Setting::ALL.iter().map(|s| s.name()).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), Setting::ALL.len());
    }

    #[test]
    fn reword_replaces_each_mention_and_nothing_else() {
        let text = format!(
            "no water: choose one with {}; {} and {} are fine, LoadOptions::water bare is not a mention",
            Setting::Water,
            Setting::JointSamples,
            Setting::AllPixels
        );
        let spelled = reword(&text, |s| match s {
            Setting::Water => "--water".into(),
            Setting::JointSamples => "--joint-samples".into(),
            other => format!("<{}>", other.name()),
        });
        assert_eq!(
            spelled,
            "no water: choose one with --water; --joint-samples and <Reading::all_pixels> are fine, \
             LoadOptions::water bare is not a mention"
        );
    }
}
