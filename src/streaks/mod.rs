//! Steps 3-6 of method §5 (the paper's §3): from a photo and its water mask to streaks.
//!
//! [`extract_streaks`] runs superpixels ([`superpixels`]), seeds ([`seeds`]), growth
//! ([`growing`]) and edges ([`edges`]); [`pictures`] draws every stage and [`report`] writes
//! `streaks.json`.
//!
//! Streaks are numbered from left to right (by the centre of their bounding box), so that the
//! lights a later step fits from them come out in an order a person can match with the photo.
//!
//! Fragments are not merged by the extraction: two fragments of one light (a wave breaking a
//! streak) are told apart from two lights only by where their lights land in the scene, which
//! the fitter knows (method §5 step 5, [`crate::fitting::fragments::group`]);
//! [`Segmentation::merged`] then makes each group one streak (`merge`).

pub mod edges;
pub mod growing;
mod merge;
pub mod pictures;
pub mod report;
pub mod seeds;
pub mod superpixels;

pub use edges::{StreakEdges, StreakSide};
pub use growing::GrowParams;
pub use seeds::{SeedParams, SeedPoint};
pub use superpixels::{SlicParams, Superpixels};

use crate::photo_in::Photo;
use crate::{Error, Result};

/// All settings of the streak extraction.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StreakParams {
    /// Superpixels.
    pub slic: SlicParams,
    /// Seed points.
    pub seeds: SeedParams,
    /// Growth.
    pub grow: GrowParams,
}

/// An axis-aligned box of pixels, bounds included.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoundingBox {
    /// Leftmost column.
    pub x_min: u32,
    /// Topmost row.
    pub y_min: u32,
    /// Rightmost column.
    pub x_max: u32,
    /// Bottom row.
    pub y_max: u32,
}

impl BoundingBox {
    /// True when the two boxes share at least one pixel.
    pub fn overlaps(&self, other: &BoundingBox) -> bool {
        self.x_min <= other.x_max
            && other.x_min <= self.x_max
            && self.y_min <= other.y_max
            && other.y_min <= self.y_max
    }
}

/// One streak: the reflection of (part of) one light on the water.
#[derive(Clone, Debug)]
pub struct Streak {
    /// Number, from 0, left to right.
    pub id: usize,
    /// The superpixels it is made of.
    pub superpixels: Vec<u32>,
    /// Its pixels (the water pixels of its superpixels), as y * width + x, in raster order.
    pub pixels: Vec<u32>,
    /// The box around its pixels.
    pub bbox: BoundingBox,
    /// The brightest pixel (by luminance of the radiance) of its brightest superpixel (by mean
    /// luminance), as (column, row): where method §5 step 7 casts its rays.
    pub brightest: (u32, u32),
    /// Mean linear radiance (RGB) of its pixels.
    pub mean_colour: [f32; 3],
    /// Its edge pixels by side (indexed by [`StreakSide`]), in raster order.
    pub edges: StreakEdges,
    /// The streaks of the extraction it is made of, by their ids there: its own id alone
    /// unless fragments were merged ([`Segmentation::merged`]).
    pub fragments: Vec<usize>,
}

/// Everything the extraction found, stage by stage.
#[derive(Clone, Debug)]
pub struct Segmentation {
    /// Photo width.
    pub width: u32,
    /// Photo height.
    pub height: u32,
    /// The superpixels.
    pub superpixels: Superpixels,
    /// The blurred V plane the seeds were searched in.
    pub value: Vec<f32>,
    /// Seed points found on the rows, before the dropping rule.
    pub seed_points: Vec<SeedPoint>,
    /// Seed points kept.
    pub seeds: Vec<SeedPoint>,
    /// Seed superpixels, in the order they were found.
    pub seed_superpixels: Vec<u32>,
    /// The streaks, left to right.
    pub streaks: Vec<Streak>,
    /// The threshold t used, for messages.
    pub threshold: f32,
    /// The largest blurred V on the water, for messages.
    pub max_water_value: f32,
}

impl Segmentation {
    /// An error a person can act on when no streak was found; `Ok` otherwise.
    pub fn require_streaks(&self) -> Result<()> {
        if !self.streaks.is_empty() {
            return Ok(());
        }
        Err(Error::NothingFound(format!(
            "no streak found: the brightest water pixel has V = {:.3} (blurred, sRGB-encoded) \
             and a seed needs a row peak above t = {:.3}; if the photo does show reflections \
             of lights, lower the seed threshold or raise the exposure",
            self.max_water_value, self.threshold
        )))
    }
}

/// Relative luminance of linear Rec. 709 / sRGB radiance.
pub fn luminance(rgb: [f32; 3]) -> f32 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

/// Finds the streaks of `photo`; `water` marks, row by row, the pixels whose camera ray first
/// hits the water.
pub fn extract_streaks(
    photo: &Photo,
    water: &[bool],
    params: &StreakParams,
) -> Result<Segmentation> {
    params.seeds.validate()?;
    params.grow.validate()?;
    let (w, h) = (photo.width, photo.height);
    let n = photo.len();
    if water.len() != n {
        return Err(Error::Usage(format!(
            "the water mask has {} pixels but the photo has {w} x {h} = {n}",
            water.len()
        )));
    }
    if !water.iter().any(|&b| b) {
        return Err(Error::NothingFound(
            "the water covers no pixel of the photo: check the camera and the water node".into(),
        ));
    }
    let superpixels = superpixels::slic(w, h, &photo.display, &params.slic)?;
    let value = seeds::value_plane(w, h, &photo.display, params.seeds.blur_sigma);
    let members = superpixels.members();
    let adjacency = superpixels.adjacency();

    // Facts about every superpixel, from its water pixels only.
    let count = superpixels.count;
    let mut histograms = vec![[0.0f32; growing::BINS]; count];
    let mut mean_value = vec![0.0f32; count];
    let mut mean_luminance = vec![0.0f32; count];
    let mut takes_part = vec![false; count];
    let mut water_members: Vec<Vec<u32>> = Vec::with_capacity(count);
    for (s, list) in members.iter().enumerate() {
        let wet: Vec<u32> = list
            .iter()
            .copied()
            .filter(|&i| water[i as usize])
            .collect();
        takes_part[s] = !wet.is_empty()
            && wet.len() as f32 >= params.grow.min_water_fraction * list.len() as f32;
        for &i in &wet {
            growing::add_to_histogram(&mut histograms[s], photo.display[i as usize]);
        }
        if !wet.is_empty() {
            let k = wet.len() as f32;
            mean_value[s] = wet.iter().map(|&i| value[i as usize]).sum::<f32>() / k;
            mean_luminance[s] = wet
                .iter()
                .map(|&i| luminance(photo.radiance[i as usize]))
                .sum::<f32>()
                / k;
        }
        water_members.push(wet);
    }

    let seed_points = seeds::seed_points(w, h, &value, water, &params.seeds);
    let (seeds, seed_superpixels) = seeds::seed_superpixels(
        &seed_points,
        w,
        &superpixels.labels,
        &value,
        &mean_value,
        &takes_part,
        params.seeds.threshold,
    );
    let facts = growing::SuperpixelFacts {
        histograms: &histograms,
        mean_value: &mean_value,
        takes_part: &takes_part,
        adjacency: &adjacency,
    };
    let grown = growing::grow(&seed_superpixels, &facts, &params.grow);

    let mut streaks: Vec<Streak> = grown
        .into_iter()
        .map(|sps| assemble(photo, sps, &water_members, &mean_luminance))
        .collect();
    number(&mut streaks, w, h);
    for s in streaks.iter_mut() {
        s.fragments = vec![s.id];
    }
    let max_water_value = value
        .iter()
        .zip(water)
        .filter(|(_, &wet)| wet)
        .map(|(&v, _)| v)
        .fold(0.0f32, f32::max);
    Ok(Segmentation {
        width: w,
        height: h,
        superpixels,
        value,
        seed_points,
        seeds,
        seed_superpixels,
        streaks,
        threshold: params.seeds.threshold,
        max_water_value,
    })
}

/// Numbers streaks left to right (by the centre of their bounding box) and finds their edges.
fn number(streaks: &mut [Streak], w: u32, h: u32) {
    streaks.sort_by_key(|s| (s.bbox.x_min + s.bbox.x_max, s.bbox.y_min + s.bbox.y_max));
    let mut owner = vec![u32::MAX; w as usize * h as usize];
    for (id, s) in streaks.iter_mut().enumerate() {
        s.id = id;
        for &p in &s.pixels {
            owner[p as usize] = id as u32;
        }
    }
    for s in streaks.iter_mut() {
        let id = s.id as u32;
        s.edges = edges::streak_edges(w, h, &s.pixels, |x, y| owner[(y * w + x) as usize] == id);
    }
}

/// Of two pixels (indices into `radiance`), the one of greater luminance; `a` on a tie.
pub fn brighter(radiance: &[[f32; 3]], a: u32, b: u32) -> u32 {
    let lum = |p: u32| radiance.get(p as usize).map_or(0.0, |&c| luminance(c));
    if lum(a) >= lum(b) {
        a
    } else {
        b
    }
}

/// The box around `pixels` and their mean linear radiance.
fn box_and_mean(photo: &Photo, pixels: &[u32]) -> (BoundingBox, [f32; 3]) {
    let w = photo.width;
    let mut bbox = BoundingBox {
        x_min: u32::MAX,
        y_min: u32::MAX,
        x_max: 0,
        y_max: 0,
    };
    let mut sum = [0.0f64; 3];
    for &p in pixels {
        let (x, y) = (p % w, p / w);
        bbox.x_min = bbox.x_min.min(x);
        bbox.x_max = bbox.x_max.max(x);
        bbox.y_min = bbox.y_min.min(y);
        bbox.y_max = bbox.y_max.max(y);
        for (c, s) in sum.iter_mut().enumerate() {
            *s += photo.radiance[p as usize][c] as f64;
        }
    }
    let k = pixels.len().max(1) as f64;
    (bbox, sum.map(|s| (s / k) as f32))
}

/// Builds a streak (without id and edges) from its superpixels.
fn assemble(
    photo: &Photo,
    superpixels: Vec<u32>,
    water_members: &[Vec<u32>],
    mean_luminance: &[f32],
) -> Streak {
    let w = photo.width;
    let mut pixels: Vec<u32> = superpixels
        .iter()
        .flat_map(|&s| water_members[s as usize].iter().copied())
        .collect();
    pixels.sort_unstable();
    let (bbox, mean_colour) = box_and_mean(photo, &pixels);
    // Ties go to the first superpixel and the first pixel in raster order.
    let brightest_sp = superpixels
        .iter()
        .copied()
        .fold(None::<u32>, |best, s| match best {
            Some(b) if mean_luminance[b as usize] >= mean_luminance[s as usize] => Some(b),
            _ => Some(s),
        });
    let brightest_pixel = brightest_sp
        .and_then(|s| {
            water_members[s as usize]
                .iter()
                .copied()
                .fold(None::<u32>, |best, p| match best {
                    Some(b)
                        if luminance(photo.radiance[b as usize])
                            >= luminance(photo.radiance[p as usize]) =>
                    {
                        Some(b)
                    }
                    _ => Some(p),
                })
        })
        .unwrap_or(0);
    Streak {
        id: 0,
        superpixels,
        pixels,
        bbox,
        brightest: (brightest_pixel % w, brightest_pixel / w),
        mean_colour,
        edges: StreakEdges::default(),
        fragments: Vec::new(),
    }
}
