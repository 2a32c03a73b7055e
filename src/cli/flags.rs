//! The command line's spelling of the library's settings: library messages name settings in
//! the library's terms ([`streaklight::settings`]), and the command line shows its flags.

use streaklight::settings::{reword, Setting};

/// The flag that sets `setting`.
pub fn flag(setting: Setting) -> String {
    match setting {
        Setting::Camera => "--camera",
        Setting::Water => "--water",
        Setting::Gloss => "--gloss",
        Setting::GlossEstimate => "--gloss auto",
        Setting::Ior => "--ior",
        Setting::NitsScale => "--nits-scale",
        Setting::Exposure => "--exposure",
        Setting::Samples => "--samples",
        Setting::PaperMethod => "--method paper",
        Setting::JointSamples => "--joint-samples",
        Setting::AllPixels => "--all-pixels",
        Setting::Repeats => "--repeats",
        Setting::AllowEmpty => "--allow-empty",
        Setting::RenderSamples => "--spp",
    }
    .into()
}

/// A library message with its settings spelled as flags.
pub fn in_flags(text: &str) -> String {
    streaklight::names::for_terminal(&reword(text, flag))
}
