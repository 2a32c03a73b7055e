//! The joint fit's options ([`JointOptions`]) and the limits on its samples.

use super::proposal::Reweight;
use super::Split;
use crate::fitting::rect::Rect;
use crate::optics::ReflectionModel;
use crate::progress::Reporter;
use crate::water_model::WaterModel;

/// How to refine.
#[derive(Clone, Copy, Debug)]
pub struct JointOptions<'a> {
    /// Lobe samples per pixel of the fitted region. The cost sums over thousands of pixels, so
    /// far fewer than the photo's own samples suffice.
    pub samples: u32,
    /// Seed of the footprints' random numbers.
    pub seed: u64,
    /// The water's reflection model.
    pub model: ReflectionModel,
    /// Pixels by which each streak is dilated to give the fitted region: the dark water around
    /// a streak is what pins its edges down.
    pub margin: u32,
    /// Coordinate-descent sweeps, at most (each shrinks the search windows; the descent
    /// stops once they are all at their smallest).
    pub sweeps: u32,
    /// Which pixels of the region are fitted ([`PixelShare`]): neighbouring pixels carry
    /// nearly the same information, and the footprints are most of the cost.
    pub pixels: PixelShare,
    /// Try explaining each light as two (overlapping streaks), keeping the split when it
    /// fits the photo far better.
    pub split: bool,
    /// Lights a fit before split, from the same start on the same photo: each is tried only
    /// the way that fit cut it (an overlap refit over more samples saves the other way's
    /// trial). Empty by default.
    pub known_splits: &'a [Split],
    /// End the fit as soon as it splits a light ([`JointOutcome::ended_at_split`]): the
    /// caller fits again from the same start with the split known (an overlap refit over
    /// more samples), so the split light's own samples, its boundary search and the descents
    /// after it would be thrown away. Off by default.
    ///
    /// [`JointOutcome::ended_at_split`]: super::JointOutcome::ended_at_split
    pub end_at_split: bool,
    /// The gloss whose lobe decides which pixels around the streaks are fitted (`None`: the
    /// model's). Fits under different glosses are comparable only over the same pixels, so a
    /// gloss search fixes it to the broadest lobe it will try.
    pub region_gloss: Option<f32>,
    /// The water model whose lobes (at the region gloss) decide which pixels are fitted
    /// (`None`: the fit's own). A search over the statistical model's slopes fixes it to the
    /// broadest lobe it will try, as a gloss search fixes [`region_gloss`](Self::region_gloss).
    pub region_water: Option<&'a dyn WaterModel>,
    /// Independent fits, each from its own samples, whose mean is the result (at least 1).
    /// From 2 on, their spread is added to the uncertainties (how far the samples move the
    /// fit); the mean's own error falls as one over the square root of
    /// the count.
    pub repeats: u32,
    /// Told as each repeat starts, when there are several (silent by default).
    pub progress: Reporter<'a>,
    /// Estimate the coefficients with the lobe Gaussian as a control variate (see the module
    /// doc): the same expectation, far less noise. Off only to measure what it brings.
    pub control_variate: bool,
    /// Fit the pixels outside the water that see a light's wall directly too (`direct`):
    /// where a light is in the photo, its direct image pins its edges to a fraction of a
    /// pixel. Off, only the water pixels are read.
    pub direct_view: bool,
    /// Take lights stacked in one column of one face, of one colour, for one light and drop
    /// the weaker (`stacked`): under a statistical water model the reflections alone cannot
    /// tell them apart. Off by default (the exact model tells stacked lamps apart).
    pub stacked_as_one: bool,
    /// Weight the water pixels by the glitter's noise (`glitter`): a first fit's residual
    /// gives each pixel's variance from its expectation and footprint, and the fit is
    /// descended again by weighted least squares. Where the start is already within a
    /// fraction of a footprint of the optimum (every light on its lamp's whole direct image,
    /// or [`resume`](Self::resume)d where a search fit put it), the residual at the start
    /// gives the weights and the fit descends once, weighted. Off by default (the exact
    /// model's residual is not glitter).
    pub glitter_weights: bool,
    /// Place each edge of a light whose radiance the photo shows (a pixel sees the lamp whole
    /// in a channel it did not clip) by the pixels that see the light directly alone, where
    /// its image pins the edge and at least 16 of them measure it: each step of the descent
    /// on such an edge minimises their cost, the radiance at each position solved over them
    /// too (`Problem::edge_profile`); the radiance kept is still solved over every
    /// pixel after each sweep. Under a statistical water model the water pixels are one draw
    /// of the glitter about the expected image, and they pulled the orange lamp's bottom edge
    /// 0.9 mm (six of its sigmas) off where its image puts it, in the paper's close geometry
    /// over a flat quad. A lamp that clips in every channel is left to every pixel: its image
    /// alone trades its radiance against the edges' partly covered pixels. Off by default
    /// (the exact model's water pixels place every edge with the image).
    pub edges_by_image: bool,
    /// Hold the region of interest of a light whose lamp the photo shows whole close around
    /// the lamp's image (`region::region_of_interest`). On by default, and in a gloss
    /// search's fits, which follow the final fit. Off under the statistical model, whose
    /// lobes are wide: there a sample landing outside the close region, never traced, still
    /// reaches into the light through its kernel (Table 1's radiance came out 8.6 % low
    /// instead of 7.5 %).
    pub close_regions: bool,
    /// Per fitted pixel, the scale of its row as a fit before over the same pixels measured
    /// it ([`super::JointOutcome::row_scales`]): the fit is weighted by it from the start,
    /// so that fits under different lobes compare their costs under one set of weights.
    /// Ignored when its length is not the fit's pixel count or with several repeats.
    pub row_scales: Option<&'a [f32]>,
    /// A statistical water whose samples may come from a trace under a broader lobe, made
    /// once for a whole search ([`Reweight`]): the fit's water model must be its target.
    /// `None` by default (every fit traces its own).
    pub reweight: Option<Reweight<'a>>,
    /// A test of the start: called once, after the trace, with the expected image of the
    /// water pixels at the start lights (their radiance solved in closed form, no edge moved
    /// yet); where it returns false the fit ends there
    /// ([`JointOutcome::stopped_at_start`](super::JointOutcome::stopped_at_start)). The
    /// automatic choice of the water model asks it whether the scene's waves could be the
    /// photo's at all before it spends the descent. `None` by default.
    pub start_gate: Option<StartGate<'a>>,
    /// Rectangles to hold lights at, one entry per start light as the fit takes them (after
    /// the starts are moved onto and split by the lamps' direct images): a light given one
    /// starts there with every edge held, the others are fitted. A search whose fits all
    /// start alike holds the lights a fit before it saw whole in the photo
    /// ([`JointOutcome::seen_whole`](super::JointOutcome::seen_whole)). Used only when its
    /// length is the start lights' count; empty by default.
    pub held: &'a [Option<Rect>],
    /// Rectangles to start lights at with their edges free, one entry per start light as the
    /// fit takes them (as for [`held`](Self::held), which wins where both give one): a fit
    /// that follows a search starts the lights a search fit saw whole where that fit put
    /// them, and their descent searches a fraction of a pixel's footprint around them
    /// (`Problem::descend_near`). Used only when its length is the start lights' count;
    /// empty by default.
    pub resume: &'a [Option<Rect>],
    /// The start lights are already where the direct view puts them
    /// ([`place_starts`](super::place_starts)): the fit takes them as they are. A search
    /// whose fits all start from the same lights places them once. Off by default.
    pub starts_placed: bool,
    /// Where each start light's lamp ends, one entry per start light as the fit takes them:
    /// its whole direct image's rectangle and a pixel's footprint there, as the fit would
    /// find it (`direct_start::enclosing_image`), given by a caller that found them already
    /// ([`start_estimate`](super::start_estimate)). Used only when its length is the start
    /// lights' count; empty by default.
    pub start_images: &'a [Option<(Rect, f32)>],
    /// Where every start light lies on a lamp's whole direct image, read one water pixel of
    /// each 2 x 2 block instead of the [`PixelShare::Checkerboard`] (the pixels that see a
    /// light directly stay a checkerboard), if that still reads at least
    /// [`THIN_MIN_WATER_PIXELS`] water pixels: the images pin every edge, and the water
    /// pixels are left the radiances, which half of a large streak's give as well to a few
    /// hundredths of a percent, in about two thirds of the time (docs/decisions.md). Only a
    /// checkerboard is thinned. Off by default. Fits whose costs are compared (a search)
    /// must read the same pixels: the slope search's fits all start alike, so they thin
    /// alike; the gloss search's read their own quarter.
    pub thin_seen_whole: bool,
}

/// A test of a joint fit's start image ([`JointOptions::start_gate`]): the water pixels'
/// indices into the photo with their modelled radiance in; whether to go on, out.
#[derive(Clone, Copy)]
pub struct StartGate<'a>(pub &'a (dyn Fn(&[ModelledPixel]) -> bool + Sync));

/// A fitted pixel's index `y * width + x` into the photo and its modelled radiance.
pub type ModelledPixel = (u32, [f32; 3]);

impl std::fmt::Debug for StartGate<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("StartGate")
    }
}

impl JointOptions<'_> {
    /// Defaults for a model and seed.
    pub fn new(model: ReflectionModel, seed: u64) -> Self {
        JointOptions {
            samples: DEFAULT_JOINT_SAMPLES,
            seed,
            model,
            margin: 6,
            sweeps: 14,
            pixels: PixelShare::Checkerboard,
            split: true,
            known_splits: &[],
            end_at_split: false,
            region_gloss: None,
            region_water: None,
            repeats: 1,
            progress: Reporter::default(),
            control_variate: true,
            direct_view: true,
            stacked_as_one: false,
            glitter_weights: false,
            edges_by_image: false,
            close_regions: true,
            row_scales: None,
            reweight: None,
            start_gate: None,
            held: &[],
            resume: &[],
            starts_placed: false,
            start_images: &[],
            thin_seen_whole: false,
        }
    }

    /// The pixels a fit reads ([`Self::pixels`], thinned by [`Self::thin_seen_whole`] when
    /// every start light is `seen_whole`).
    pub fn share_for(&self, seen_whole: bool) -> PixelShare {
        if self.thin_seen_whole && seen_whole && self.pixels == PixelShare::Checkerboard {
            PixelShare::WaterBlocks(2)
        } else {
            self.pixels
        }
    }
}

/// Which pixels of its region a joint fit reads, of the water and of the pixels that see a
/// light directly.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PixelShare {
    /// Every pixel.
    All,
    /// Every second pixel, on a checkerboard: the fit's default on a photo of up to
    /// [`LARGE_PHOTO_PIXELS`].
    Checkerboard,
    /// One water pixel of each `b` x `b` block (column and row multiples of `b`) and, of the
    /// pixels that see a light directly, those on every `b`-th diagonal (`x + y` a multiple
    /// of `b`; a checkerboard for `b` = 2): the fit's default on a photo of more than
    /// [`LARGE_PHOTO_PIXELS`], `b` growing with its size ([`PixelShare::water_blocks`]).
    /// There a glint covers several pixels, so neighbouring water pixels tell little more
    /// than one of them, while a direct image's edge is pinned by every row or column it
    /// crosses, which the diagonals read, one pixel in `b` of each, and a block grid does
    /// not.
    WaterBlocks(u32),
    /// Every fourth pixel, one of each 2 x 2 block (even column, even row), of the water and of
    /// the direct view: enough for a search that compares the costs of fits over the same
    /// pixels, where the minimum lies matters and not how well each fit pins its lights.
    Quarter,
}

/// The most pixels of a photo whose joint fit reads a checkerboard of its water pixels by
/// default; a larger photo's fit reads one of each block of them
/// ([`PixelShare::WaterBlocks`]), a block large enough that the pixels it could read stay
/// under this many. A 1920 x 1080 photo has 2.07 million.
pub const LARGE_PHOTO_PIXELS: u64 = 1_000_000;

impl PixelShare {
    /// The default share of the water of a photo of `pixels` pixels: a checkerboard up to
    /// [`LARGE_PHOTO_PIXELS`], else one of each `b` x `b` block with `b` the least for which
    /// `b^2` such photos hold the photo (2 up to 4 million pixels, 4 from 9 to 16 million).
    pub fn water_blocks(pixels: u64) -> PixelShare {
        if pixels <= LARGE_PHOTO_PIXELS {
            return PixelShare::Checkerboard;
        }
        let mut b = 2u32;
        while u64::from(b) * u64::from(b) * LARGE_PHOTO_PIXELS < pixels {
            b += 1;
        }
        PixelShare::WaterBlocks(b)
    }

    /// Whether the water pixel in column `x`, row `y` is read.
    pub fn reads(self, x: u32, y: u32) -> bool {
        match self {
            PixelShare::All => true,
            PixelShare::Checkerboard => (x + y).is_multiple_of(2),
            PixelShare::WaterBlocks(b) => {
                let b = b.max(1);
                x.is_multiple_of(b) && y.is_multiple_of(b)
            }
            PixelShare::Quarter => x.is_multiple_of(2) && y.is_multiple_of(2),
        }
    }

    /// Whether two water pixels this share reads can lie `dx` columns and `dy` rows apart:
    /// the pixels read form a lattice through the origin, so a lag between two of them is
    /// itself on it.
    pub fn lag_between_read(self, dx: i64, dy: i64) -> bool {
        match self {
            PixelShare::All => true,
            PixelShare::Checkerboard => (dx + dy).rem_euclid(2) == 0,
            PixelShare::WaterBlocks(b) => {
                let b = i64::from(b.max(1));
                dx.rem_euclid(b) == 0 && dy.rem_euclid(b) == 0
            }
            PixelShare::Quarter => dx.rem_euclid(2) == 0 && dy.rem_euclid(2) == 0,
        }
    }

    /// Whether the pixel in column `x`, row `y` is read where it sees a light's wall directly.
    pub fn reads_direct(self, x: u32, y: u32) -> bool {
        match self {
            PixelShare::WaterBlocks(b) => (x + y).is_multiple_of(b.max(1)),
            share => share.reads(x, y),
        }
    }

    /// The share's name in the report: "all", "checkerboard", "one water pixel of each
    /// B x B block" or "quarter".
    pub fn name(self) -> String {
        match self {
            PixelShare::All => "all".into(),
            PixelShare::Checkerboard => "checkerboard".into(),
            PixelShare::WaterBlocks(b) => format!("one water pixel of each {b} x {b} block"),
            PixelShare::Quarter => "quarter".into(),
        }
    }
}

/// The fewest water pixels a fit thinned by [`JointOptions::thin_seen_whole`] reads; with
/// fewer it keeps the checkerboard. Half of Table 1's streak (15800 pixels) gives its
/// radiance to 0.06 % rms over seeds (0.02 % from the checkerboard); half of a far 1.5 x
/// 1.2 m light's gave its red 1.0 % high (0.3 % from the checkerboard), and the harbour
/// pair's reflections (5100 pixels thinned) are kept whole.
pub const THIN_MIN_WATER_PIXELS: usize = 10_000;

/// Default lobe samples per pixel of the joint fit.
pub const DEFAULT_JOINT_SAMPLES: u32 = 72;

/// The most lobe samples per pixel the joint fit takes: a pixel's stored samples are indexed
/// in 16 bits (`samples::PlaneSamples::by_v`), and `effective_samples` of this is 32768.
pub const MAX_JOINT_SAMPLES: u32 = 32_768;

#[cfg(test)]
mod tests {
    use super::PixelShare;

    /// Over a 100 x 100 block the shares read 10000, 5000 and 2500 pixels, each share's
    /// pixels among the denser one's, and in every 2 x 2 block the quarter reads one.
    #[test]
    fn each_share_reads_its_part_of_the_pixels() {
        let read = |share: PixelShare| {
            (0..100u32)
                .flat_map(|y| (0..100u32).map(move |x| (x, y)))
                .filter(|&(x, y)| share.reads(x, y))
                .collect::<Vec<_>>()
        };
        let (all, half, quarter) = (
            read(PixelShare::All),
            read(PixelShare::Checkerboard),
            read(PixelShare::Quarter),
        );
        assert_eq!((all.len(), half.len(), quarter.len()), (10000, 5000, 2500));
        assert!(quarter
            .iter()
            .all(|&(x, y)| PixelShare::Checkerboard.reads(x, y)));
        for by in 0..50u32 {
            for bx in 0..50u32 {
                let inside = quarter
                    .iter()
                    .filter(|&&(x, y)| x / 2 == bx && y / 2 == by)
                    .count();
                assert_eq!(inside, 1, "block ({bx}, {by})");
            }
        }
        // The default share of a large photo reads one water pixel of each block and the
        // checkerboard's direct ones.
        let large = PixelShare::WaterBlocks(2);
        for (x, y) in (0..100u32).flat_map(|y| (0..100u32).map(move |x| (x, y))) {
            assert_eq!(large.reads(x, y), PixelShare::Quarter.reads(x, y));
            assert_eq!(
                large.reads_direct(x, y),
                PixelShare::Checkerboard.reads(x, y)
            );
            for share in [
                PixelShare::All,
                PixelShare::Checkerboard,
                PixelShare::Quarter,
            ] {
                assert_eq!(share.reads_direct(x, y), share.reads(x, y));
            }
        }
        // The lags between two pixels read are the lags the share allows.
        for share in [
            PixelShare::All,
            PixelShare::Checkerboard,
            PixelShare::Quarter,
            PixelShare::WaterBlocks(3),
        ] {
            let pixels = read(share);
            for (dx, dy) in (-6i64..=6).flat_map(|dy| (-6i64..=6).map(move |dx| (dx, dy))) {
                let (x, y) = (pixels[0].0 as i64 + 12, pixels[0].1 as i64 + 12);
                let (from, to) = ((x as u32, y as u32), ((x + dx) as u32, (y + dy) as u32));
                let both = share.reads(from.0, from.1) && share.reads(to.0, to.1);
                if share.reads(from.0, from.1) {
                    assert_eq!(share.lag_between_read(dx, dy), both, "{share:?} {dx} {dy}");
                }
            }
        }
        let blocks = read(PixelShare::WaterBlocks(4));
        assert_eq!(blocks.len(), 625);
        assert!(blocks.iter().all(|&(x, y)| x % 4 == 0 && y % 4 == 0));
        // Its direct view reads a quarter of the pixels, 25 of each row and of each column.
        let direct: Vec<(u32, u32)> = (0..100u32)
            .flat_map(|y| (0..100u32).map(move |x| (x, y)))
            .filter(|&(x, y)| PixelShare::WaterBlocks(4).reads_direct(x, y))
            .collect();
        assert_eq!(direct.len(), 2500);
        for line in 0..100u32 {
            assert_eq!(direct.iter().filter(|p| p.1 == line).count(), 25);
            assert_eq!(direct.iter().filter(|p| p.0 == line).count(), 25);
        }
    }

    /// The block's side is the least `b` with `b^2` megapixels holding the photo.
    #[test]
    fn the_water_blocks_grow_with_the_photo() {
        let share = PixelShare::water_blocks;
        assert_eq!(share(600 * 600), PixelShare::Checkerboard);
        assert_eq!(share(1_000_000), PixelShare::Checkerboard);
        assert_eq!(share(1_000_001), PixelShare::WaterBlocks(2));
        assert_eq!(share(1920 * 1080), PixelShare::WaterBlocks(2));
        assert_eq!(share(4_000_000), PixelShare::WaterBlocks(2));
        assert_eq!(share(4_000_001), PixelShare::WaterBlocks(3));
        assert_eq!(share(4000 * 3000), PixelShare::WaterBlocks(4));
        assert_eq!(share(8192 * 5464), PixelShare::WaterBlocks(7));
    }

    /// Only a checkerboard is thinned, only when asked, and only when every light is seen
    /// whole: a larger photo's blocks, every pixel and the search's quarter stay as they are.
    #[test]
    fn a_checkerboard_is_thinned_where_every_lamp_pins_its_light() {
        let options = |pixels, thin_seen_whole| super::JointOptions {
            pixels,
            thin_seen_whole,
            ..super::JointOptions::new(crate::optics::ReflectionModel::new(500.0, 1.33), 1)
        };
        let board = PixelShare::Checkerboard;
        assert_eq!(
            options(board, true).share_for(true),
            PixelShare::WaterBlocks(2)
        );
        assert_eq!(options(board, true).share_for(false), board);
        assert_eq!(options(board, false).share_for(true), board);
        for other in [
            PixelShare::All,
            PixelShare::Quarter,
            PixelShare::WaterBlocks(2),
            PixelShare::WaterBlocks(4),
        ] {
            assert_eq!(options(other, true).share_for(true), other);
        }
        assert!(
            !super::JointOptions::new(crate::optics::ReflectionModel::new(500.0, 1.33), 1)
                .thin_seen_whole
        );
    }
}
