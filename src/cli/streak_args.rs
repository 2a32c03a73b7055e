//! The settings of the streak extraction, shared by `segment` and `fit`.

use streaklight::streaks::StreakParams;

/// Streak-extraction options (method §5 steps 3-5); the defaults work on the samples.
#[derive(clap::Args)]
pub struct StreakArgs {
    /// Number of superpixels K, 1 or more (default: one per 400 pixels, e.g. 1200 for a
    /// 800 x 600 photo; fewer, larger superpixels merge narrow streaks with the water).
    #[arg(long, value_name = "K", value_parser = super::values::count_usize)]
    pub superpixels: Option<usize>,
    /// SLIC compactness m, > 0 (typical 5-40: higher gives rounder superpixels that follow
    /// the streaks' edges less).
    #[arg(long, value_name = "M", default_value_t = 10.0, value_parser = super::values::positive_f32)]
    pub compactness: f32,
    /// Seed search: every k-th row, 1 or more (typical 4-16; smaller finds shorter streaks
    /// and takes longer).
    #[arg(long, value_name = "K", default_value_t = 8, value_parser = super::values::count_usize)]
    pub seed_row_step: usize,
    /// Seed threshold t on the value V = max(R, G, B), sRGB-encoded, from 0 up to, not
    /// including, 1 (typical 0.2-0.6; lower finds dimmer lights, and more false streaks).
    #[arg(long, value_name = "T", default_value_t = 0.35, value_parser = super::values::unit_threshold)]
    pub seed_threshold: f32,
    /// Gaussian blur sigma before the seed search, in pixels, 0 to 50 (typical 0.5-3).
    #[arg(long, value_name = "PIXELS", default_value_t = 1.5, value_parser = super::values::blur_sigma)]
    pub blur: f32,
    /// Histogram correlation at or above which two superpixels are one streak, -1 to 1
    /// (typical 0.3-0.8; higher splits streaks more).
    #[arg(long, value_name = "R", default_value_t = 0.5, value_parser = super::values::correlation)]
    pub similarity: f32,
    /// Mean V (sRGB-encoded, 0 to 1) below which a superpixel never joins a streak (typical
    /// 0.05-0.3).
    #[arg(long, value_name = "V", default_value_t = 0.15, value_parser = super::values::unit_interval)]
    pub min_value: f32,
}

impl StreakArgs {
    /// The library's parameters, checked.
    pub fn params(&self) -> streaklight::Result<StreakParams> {
        let mut params = StreakParams::default();
        params.slic.superpixels = self.superpixels;
        params.slic.compactness = self.compactness;
        params.seeds.row_step = self.seed_row_step;
        params.seeds.threshold = self.seed_threshold;
        params.seeds.blur_sigma = self.blur;
        params.grow.similarity = self.similarity;
        params.grow.min_value = self.min_value;
        params.seeds.validate()?;
        params.grow.validate()?;
        Ok(params)
    }
}
