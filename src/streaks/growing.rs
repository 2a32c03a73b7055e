//! Step 5 of method §5 (the paper's §3.2.2): growing streaks from seed superpixels by the
//! correlation of their histograms (the paper's eq. 1).
//!
//! The histogram. The paper uses hue alone, which is undefined for the grey and white pixels of
//! most lights and of the dark water, so every dark superpixel would look alike. Ours has two
//! parts, concatenated:
//! - 12 hue bins, each pixel adding its chroma (max - min of R, G, B) times [`HUE_WEIGHT`]: a
//!   coloured light fills them, grey and dark pixels hardly touch them; the weight lets hue
//!   outvote brightness, so a yellow streak is not taken for a white one of equal brightness;
//! - 8 bins of the value V = max(R, G, B), each pixel adding 1: this is what tells a white
//!   light's streak from the dark water.
//!
//! Both parts are soft-binned (a pixel is shared linearly between the two nearest bin centres),
//! so a small change of colour moves mass gradually and neighbours along a streak's fall-off
//! still correlate.
//!
//! The correlation of two histograms is Pearson's over the bins; when either histogram is
//! constant it is undefined, and we call the pair dissimilar (OpenCV's compareHist returns 1
//! there, which merges every empty or flat superpixel; method §5 step 5).
//!
//! The growth. Breadth-first from a seed superpixel over adjacent water superpixels. Departure
//! from the paper: a candidate is compared with the streak superpixel it was reached from, not
//! with the seed. A streak is brightest in the middle and fades outwards, so a histogram that
//! sees brightness finds the seed unlike the streak's own flanks; a chain of neighbours follows
//! the fade. To keep the chain from running on into the dark water, a candidate's mean V must
//! also reach a floor.

use crate::{Error, Result};

/// Number of hue bins.
pub const HUE_BINS: usize = 12;
/// Number of value bins.
pub const VALUE_BINS: usize = 8;
/// Weight of a pixel's chroma in the hue bins against its 1 in the value bins.
pub const HUE_WEIGHT: f32 = 3.0;
/// Length of a histogram.
pub const BINS: usize = HUE_BINS + VALUE_BINS;

/// Settings of the growth.
#[derive(Clone, Debug, PartialEq)]
pub struct GrowParams {
    /// Two superpixels are similar when the correlation of their histograms is at least this.
    pub similarity: f32,
    /// A superpixel joins a streak only if its mean V (blurred, sRGB-encoded) is at least this.
    pub min_value: f32,
    /// A superpixel takes part only if at least this fraction of its pixels is water.
    pub min_water_fraction: f32,
}

impl Default for GrowParams {
    fn default() -> Self {
        GrowParams {
            similarity: 0.5,
            min_value: 0.15,
            min_water_fraction: 0.25,
        }
    }
}

impl GrowParams {
    /// Refuses settings that make no sense, naming the option.
    pub fn validate(&self) -> Result<()> {
        if !(self.similarity.is_finite() && (-1.0..=1.0).contains(&self.similarity)) {
            return Err(Error::Usage(format!(
                "the similarity threshold must be in [-1, 1], not {}",
                self.similarity
            )));
        }
        if !(self.min_value.is_finite() && (0.0..=1.0).contains(&self.min_value)) {
            return Err(Error::Usage(format!(
                "the growth floor on V must be in [0, 1], not {}",
                self.min_value
            )));
        }
        if !(self.min_water_fraction.is_finite()
            && self.min_water_fraction > 0.0
            && self.min_water_fraction <= 1.0)
        {
            return Err(Error::Usage(format!(
                "the minimum water fraction must be in (0, 1], not {}",
                self.min_water_fraction
            )));
        }
        Ok(())
    }
}

/// Adds one sRGB-encoded colour to a histogram.
pub fn add_to_histogram(hist: &mut [f32; BINS], rgb: [f32; 3]) {
    let [r, g, b] = rgb.map(|c| c.clamp(0.0, 1.0));
    let max = r.max(g).max(b);
    let min = r.min(g).min(b);
    let chroma = max - min;
    if chroma > 0.0 {
        // Hue in [0, 6), the standard hexcone formula.
        let h = if max == r {
            ((g - b) / chroma).rem_euclid(6.0)
        } else if max == g {
            (b - r) / chroma + 2.0
        } else {
            (r - g) / chroma + 4.0
        };
        // Bin centres at (j + 0.5) * 6 / HUE_BINS, shared circularly.
        let pos = h / 6.0 * HUE_BINS as f32 - 0.5;
        let lo = pos.floor();
        let frac = pos - lo;
        let j0 = (lo as i64).rem_euclid(HUE_BINS as i64) as usize;
        let j1 = (j0 + 1) % HUE_BINS;
        hist[j0] += HUE_WEIGHT * chroma * (1.0 - frac);
        hist[j1] += HUE_WEIGHT * chroma * frac;
    }
    let pos = (max * VALUE_BINS as f32 - 0.5).clamp(0.0, (VALUE_BINS - 1) as f32);
    let lo = pos.floor();
    let frac = pos - lo;
    let j0 = lo as usize;
    let j1 = (j0 + 1).min(VALUE_BINS - 1);
    hist[HUE_BINS + j0] += 1.0 - frac;
    hist[HUE_BINS + j1] += frac;
}

/// The paper's eq. 1, Pearson's correlation of the bins; `None` when either histogram is
/// constant (the correlation is undefined there, and the caller treats it as dissimilar).
pub fn correlation(a: &[f32], b: &[f32]) -> Option<f32> {
    let n = a.len().min(b.len()) as f64;
    if n == 0.0 {
        return None;
    }
    let mean_a = a.iter().map(|&v| v as f64).sum::<f64>() / n;
    let mean_b = b.iter().map(|&v| v as f64).sum::<f64>() / n;
    let (mut sab, mut saa, mut sbb) = (0.0f64, 0.0f64, 0.0f64);
    for (&x, &y) in a.iter().zip(b) {
        let (dx, dy) = (x as f64 - mean_a, y as f64 - mean_b);
        sab += dx * dy;
        saa += dx * dx;
        sbb += dy * dy;
    }
    // Relative to the histograms' own scale, so that a histogram of many equal pixels that is
    // constant up to rounding counts as constant too.
    let scale_a = a.iter().map(|&v| (v as f64).abs()).fold(0.0, f64::max);
    let scale_b = b.iter().map(|&v| (v as f64).abs()).fold(0.0, f64::max);
    if saa <= (1e-9 * scale_a).powi(2) * n || sbb <= (1e-9 * scale_b).powi(2) * n {
        return None;
    }
    Some((sab / (saa * sbb).sqrt()) as f32)
}

/// True when two histograms are similar enough to be in one streak.
pub fn similar(a: &[f32], b: &[f32], threshold: f32) -> bool {
    correlation(a, b).is_some_and(|c| c >= threshold)
}

/// What the growth needs to know about every superpixel.
pub struct SuperpixelFacts<'a> {
    /// Histogram of each superpixel's water pixels.
    pub histograms: &'a [[f32; BINS]],
    /// Mean blurred V of each superpixel's water pixels.
    pub mean_value: &'a [f32],
    /// Whether each superpixel is a water superpixel.
    pub takes_part: &'a [bool],
    /// Adjacent superpixels of each.
    pub adjacency: &'a [Vec<u32>],
}

/// Grows one streak from every seed superpixel not yet taken, in order; returns each streak's
/// superpixels in the order they joined. No superpixel is in two streaks.
pub fn grow(seeds: &[u32], facts: &SuperpixelFacts, params: &GrowParams) -> Vec<Vec<u32>> {
    let count = facts.takes_part.len();
    let mut taken = vec![false; count];
    let mut streaks = Vec::new();
    for &seed in seeds {
        let seed = seed as usize;
        if taken[seed] || !facts.takes_part[seed] {
            continue;
        }
        taken[seed] = true;
        let mut members = vec![seed as u32];
        let mut head = 0;
        while head < members.len() {
            let from = members[head] as usize;
            head += 1;
            for &c in &facts.adjacency[from] {
                let c = c as usize;
                if taken[c]
                    || !facts.takes_part[c]
                    || facts.mean_value[c] < params.min_value
                    || !similar(
                        &facts.histograms[from],
                        &facts.histograms[c],
                        params.similarity,
                    )
                {
                    continue;
                }
                taken[c] = true;
                members.push(c as u32);
            }
        }
        streaks.push(members);
    }
    streaks
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hist_of(colours: &[[f32; 3]]) -> [f32; BINS] {
        let mut h = [0.0; BINS];
        for &c in colours {
            add_to_histogram(&mut h, c);
        }
        h
    }

    #[test]
    fn correlation_matches_pearson_and_refuses_constants() {
        let a = [1.0, 2.0, 3.0, 4.0];
        let b = [2.0, 4.0, 6.0, 8.0];
        let c = [4.0, 3.0, 2.0, 1.0];
        assert!((correlation(&a, &b).unwrap() - 1.0).abs() < 1e-6);
        assert!((correlation(&a, &c).unwrap() + 1.0).abs() < 1e-6);
        // Hand computation: a = (1,0,0), b = (1,1,0): means 1/3 and 2/3,
        // sab = 1/3, saa = 2/3, sbb = 2/3: r = 0.5.
        assert!((correlation(&[1.0, 0.0, 0.0], &[1.0, 1.0, 0.0]).unwrap() - 0.5).abs() < 1e-6);
        assert_eq!(correlation(&[0.0; 4], &a), None);
        assert_eq!(correlation(&a, &[3.0; 4]), None);
        assert!(!similar(&[0.0; 4], &[0.0; 4], -1.0));
    }

    #[test]
    fn white_is_told_from_dark_water_and_yellow_from_white() {
        let white = hist_of(&[[1.0, 1.0, 1.0], [0.95, 0.95, 0.95], [0.9, 0.92, 0.9]]);
        let white2 = hist_of(&[[0.97, 0.97, 0.97], [0.93, 0.93, 0.94]]);
        let dark = hist_of(&[[0.04, 0.05, 0.06], [0.06, 0.05, 0.04], [0.05, 0.05, 0.05]]);
        let dark2 = hist_of(&[[0.03, 0.06, 0.05], [0.07, 0.05, 0.05]]);
        let yellow = hist_of(&[[1.0, 1.0, 0.0], [0.95, 0.93, 0.05]]);
        // A hue-only histogram would call white and dark alike (both nearly empty of hue).
        assert!(similar(&white, &white2, 0.5));
        assert!(similar(&dark, &dark2, 0.5));
        assert!(!similar(&white, &dark, 0.5));
        assert!(!similar(&yellow, &dark, 0.5));
        assert!(!similar(&yellow, &white, 0.5));
    }

    #[test]
    fn growth_follows_similar_neighbours_and_never_shares() {
        // A chain 0-1-2-3 and 4 alone; 2 is dark, so 3 is not reached from 0.
        let bright = {
            let mut h = [0.0; BINS];
            add_to_histogram(&mut h, [0.9, 0.9, 0.9]);
            h
        };
        let darkh = {
            let mut h = [0.0; BINS];
            add_to_histogram(&mut h, [0.05, 0.05, 0.05]);
            h
        };
        let histograms = [bright, bright, darkh, bright, bright];
        let mean_value = [0.9, 0.9, 0.05, 0.9, 0.9];
        let takes_part = [true; 5];
        let adjacency = vec![vec![1], vec![0, 2], vec![1, 3], vec![2], vec![]];
        let facts = SuperpixelFacts {
            histograms: &histograms,
            mean_value: &mean_value,
            takes_part: &takes_part,
            adjacency: &adjacency,
        };
        let streaks = grow(&[0, 1, 3, 4], &facts, &GrowParams::default());
        assert_eq!(streaks, vec![vec![0, 1], vec![3], vec![4]]);
    }
}
