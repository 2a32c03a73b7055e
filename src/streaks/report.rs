//! `streaks.json`: one entry per streak, for people and for other tools. Its JSON Schema is
//! `schema/streaks.schema.json`.

use std::path::Path;

use serde::Serialize;

use super::{BoundingBox, Segmentation, StreakParams, StreakSide};
use crate::output_file::write_atomically;
use crate::{Error, Result};

/// The whole report.
#[derive(Serialize)]
pub struct Report {
    /// Version of this format.
    pub format_version: u32,
    /// Photo size.
    pub photo: PhotoSize,
    /// Settings used.
    pub settings: Settings,
    /// Number of superpixels.
    pub superpixel_count: usize,
    /// Number of seed points kept.
    pub seed_count: usize,
    /// Number of seed superpixels.
    pub seed_superpixel_count: usize,
    /// One entry per streak, left to right: per light, fragments of one light merged.
    pub streaks: Vec<StreakEntry>,
    /// The streaks as the extraction found them, before fragments were merged (the same as
    /// `streaks` when none were), numbered as `fragments` and the fit's `streak_ids` give
    /// them.
    pub fragments: Vec<StreakEntry>,
}

/// Width and height in pixels.
#[derive(Serialize)]
pub struct PhotoSize {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
}

/// The settings of the extraction, as used.
#[derive(Serialize)]
pub struct Settings {
    /// SLIC K.
    pub superpixels: usize,
    /// SLIC compactness.
    pub compactness: f32,
    /// Seed row step k.
    pub seed_row_step: usize,
    /// Seed threshold t.
    pub seed_threshold: f32,
    /// Blur sigma in pixels.
    pub blur_sigma: f32,
    /// Row mean filter width.
    pub row_filter: usize,
    /// Histogram correlation threshold.
    pub similarity: f32,
    /// Growth floor on mean V.
    pub min_value: f32,
}

/// One streak.
#[derive(Serialize)]
pub struct StreakEntry {
    /// Number, from 0, left to right.
    pub id: usize,
    /// Number of pixels.
    pub pixel_count: usize,
    /// Number of superpixels.
    pub superpixel_count: usize,
    /// Bounding box, bounds included.
    pub bbox: Bbox,
    /// Brightest pixel of the brightest superpixel.
    pub brightest: Pixel,
    /// Mean linear radiance.
    pub mean_colour: [f32; 3],
    /// Edge pixel counts per side.
    pub edge_pixel_counts: EdgeCounts,
    /// The ids (in the report's `fragments`) of the streaks of the extraction it is made of.
    pub fragments: Vec<usize>,
}

/// A bounding box in pixels.
#[derive(Serialize)]
pub struct Bbox {
    /// Leftmost column.
    pub x_min: u32,
    /// Topmost row.
    pub y_min: u32,
    /// Rightmost column.
    pub x_max: u32,
    /// Bottom row.
    pub y_max: u32,
}

impl From<BoundingBox> for Bbox {
    fn from(b: BoundingBox) -> Self {
        Bbox {
            x_min: b.x_min,
            y_min: b.y_min,
            x_max: b.x_max,
            y_max: b.y_max,
        }
    }
}

/// A pixel position.
#[derive(Serialize)]
pub struct Pixel {
    /// Column.
    pub x: u32,
    /// Row.
    pub y: u32,
}

/// Edge pixel counts per side.
#[derive(Serialize)]
pub struct EdgeCounts {
    /// Left.
    pub left: usize,
    /// Right.
    pub right: usize,
    /// Top.
    pub top: usize,
    /// Bottom.
    pub bottom: usize,
}

/// The entries of `seg`'s streaks.
fn entries(seg: &Segmentation) -> Vec<StreakEntry> {
    seg.streaks
        .iter()
        .map(|s| StreakEntry {
            id: s.id,
            pixel_count: s.pixels.len(),
            superpixel_count: s.superpixels.len(),
            bbox: s.bbox.into(),
            brightest: Pixel {
                x: s.brightest.0,
                y: s.brightest.1,
            },
            mean_colour: s.mean_colour,
            edge_pixel_counts: EdgeCounts {
                left: s.edges[StreakSide::Left].len(),
                right: s.edges[StreakSide::Right].len(),
                top: s.edges[StreakSide::Top].len(),
                bottom: s.edges[StreakSide::Bottom].len(),
            },
            fragments: s.fragments.clone(),
        })
        .collect()
}

/// Builds the report of a segmentation; `pieces` is the extraction `seg` was merged from
/// ([`Segmentation::merged`]), `None` when `seg` is the extraction itself.
pub fn report(seg: &Segmentation, pieces: Option<&Segmentation>, params: &StreakParams) -> Report {
    let n = seg.width as usize * seg.height as usize;
    Report {
        format_version: 2,
        photo: PhotoSize {
            width: seg.width,
            height: seg.height,
        },
        settings: Settings {
            superpixels: params.slic.superpixel_count(n),
            compactness: params.slic.compactness,
            seed_row_step: params.seeds.row_step,
            seed_threshold: params.seeds.threshold,
            blur_sigma: params.seeds.blur_sigma,
            row_filter: params.seeds.row_filter,
            similarity: params.grow.similarity,
            min_value: params.grow.min_value,
        },
        superpixel_count: seg.superpixels.count,
        seed_count: seg.seeds.len(),
        seed_superpixel_count: seg.seed_superpixels.len(),
        streaks: entries(seg),
        fragments: entries(pieces.unwrap_or(seg)),
    }
}

/// Writes `streaks.json` to `path` (`pieces` as for [`report`]).
pub fn write_report(
    path: &Path,
    seg: &Segmentation,
    pieces: Option<&Segmentation>,
    params: &StreakParams,
) -> Result<()> {
    let mut bytes = serde_json::to_vec_pretty(&report(seg, pieces, params))
        .map_err(|e| Error::output(path, format!("cannot write JSON: {e}")))?;
    bytes.push(b'\n');
    write_atomically(path, &bytes)
}
