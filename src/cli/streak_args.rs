//! The settings of the streak extraction, shared by `segment` and `fit`.

use streaklight::streaks::StreakParams;

/// Streak-extraction options (method §5 steps 3-5); the defaults work on the samples.
#[derive(clap::Args)]
pub struct StreakArgs {
    /// Number of superpixels K (default: one per 400 pixels).
    #[arg(long)]
    pub superpixels: Option<usize>,
    /// SLIC compactness m.
    #[arg(long, default_value_t = 10.0)]
    pub compactness: f32,
    /// Seed search: every k-th row.
    #[arg(long, default_value_t = 8)]
    pub seed_row_step: usize,
    /// Seed threshold t on the value V (sRGB-encoded, 0 to 1).
    #[arg(long, default_value_t = 0.35)]
    pub seed_threshold: f32,
    /// Gaussian blur sigma in pixels before the seed search.
    #[arg(long, default_value_t = 1.5)]
    pub blur: f32,
    /// Histogram correlation at or above which two superpixels are one streak (-1 to 1).
    #[arg(long, default_value_t = 0.5)]
    pub similarity: f32,
    /// Mean V below which a superpixel never joins a streak.
    #[arg(long, default_value_t = 0.15)]
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
