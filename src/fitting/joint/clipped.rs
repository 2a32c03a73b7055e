//! The clipped pixels of an edge profile ([`super::profile`]) whose coefficient is the same
//! at every grid point: which of their channels count at every grid point's radiance, and
//! their sums there, gathered for the whole grid in one pass over them.
//!
//! A clipped channel is a lower bound (method §2): it adds `(r0 - L c)^2` while the model
//! `L c` stays below the photo's value (the residual `r0` with light k dark) and nothing once
//! the model is above, so it cannot join the normal equations' sums once for all radiances.
//! In the paper's setting most fitted pixels are clipped (a streak's core: 24 000 of Table
//! 1's 30 600), and counting each at every grid point was most of the descent's time. The
//! grid points where such a channel counts are those whose radiance lies on one side of
//! `r0 / c`: with the grid's radiances sorted, one run of them. Each channel adds its three
//! sums (`r0^2`, `r0 c`, `c^2`) at the run's ends as differences, and one pass along the
//! sorted radiances gives at every grid point the sums of the channels that count there: the
//! cost `sum r0^2 - 2 L sum r0 c + L^2 sum c^2`, and the least-squares radiance of those
//! channels (the profile's Newton step).

use rayon::prelude::*;

/// A clipped pixel of an edge profile: per channel, its residual `r0` and the other lights'
/// combined half-difference `rd` (see the note on the coefficients' noise in
/// [`super::cost`]) when light k is dark, and which channels the photo clipped (the others
/// are values).
#[derive(Clone, Copy)]
pub(super) struct ClippedPixel {
    pub(super) res: [f64; 3],
    pub(super) rest_dev: [f64; 3],
    pub(super) bound: [bool; 3],
}

impl ClippedPixel {
    /// Channel `ch`'s cost at light k's radiance `l`, coefficient `c` and half-difference
    /// `d`, less its cost with light k dark: as [`Problem::cost`](super::problem::Problem)
    /// counts it, `(r0 - l c)^2 - (l d + rd)^2`, for a clipped channel only while the model
    /// is below the photo (`r0 - l c >= 0`).
    #[cfg(test)]
    fn cost(&self, ch: usize, l: f64, c: f64, d: f64) -> f64 {
        let (r0, rd) = (self.res[ch], self.rest_dev[ch]);
        let r = r0 - l * c;
        let e = l * d + rd;
        let bound = self.bound[ch];
        let now = if bound && r < 0.0 { 0.0 } else { r * r - e * e };
        let dark = if bound && r0 < 0.0 {
            0.0
        } else {
            r0 * r0 - rd * rd
        };
        now - dark
    }
}

/// A clipped pixel whose coefficient `c` and half-difference `d` are the same at every grid
/// point.
pub(super) struct ClippedConstant {
    pub(super) pixel: ClippedPixel,
    pub(super) c: f64,
    pub(super) d: f64,
}

/// A clipped pixel whose coefficient and half-difference change over the grid: theirs at
/// every grid point.
pub(super) struct ClippedRow {
    pub(super) pixel: ClippedPixel,
    pub(super) c: Vec<f32>,
    pub(super) d: Vec<f32>,
}

/// The clipped pixels' channels that count at every grid point's radiance of light k (a
/// clipped channel while the model is below the photo, a value channel always), summed.
pub(super) struct Counted {
    /// Per grid point and channel, `[r0^2 - rd^2, r0 c + d rd, c^2 - d^2]` over the channels
    /// that count there: at light k's radiance `L` they add `s0 - 2 L s1 + L^2 s2`.
    pub(super) sums: Vec<[[f64; 3]; 3]>,
    /// What the same pixels add with light k dark.
    dark: f64,
}

impl Counted {
    /// The cost the clipped pixels add at grid point j with light k's radiance `l`, less what
    /// they add with light k dark (as [`Problem::cost`](super::problem::Problem) counts
    /// them): exact at the radiance they were counted at.
    pub(super) fn cost(&self, j: usize, l: [f64; 3]) -> f64 {
        let s = &self.sums[j];
        (0..3)
            .map(|ch| s[ch][0] - 2.0 * l[ch] * s[ch][1] + l[ch] * l[ch] * s[ch][2])
            .sum::<f64>()
            - self.dark
    }
}

/// The clipped pixels (`constant` and `rows`) counted at light k's radiance `radiance[j]` at
/// every grid point j.
pub(super) fn counted(
    constant: &[ClippedConstant],
    rows: &[ClippedRow],
    radiance: &[[f64; 3]],
) -> Counted {
    let mut sums = vec![[[0f64; 3]; 3]; radiance.len()];
    let mut dark = 0f64;
    for ch in 0..3 {
        let channel: Vec<f64> = radiance.iter().map(|l| l[ch]).collect();
        dark += add_constant_sums(constant, ch, &channel, &mut sums);
    }
    for row in rows {
        for ch in 0..3 {
            let (r0, rd) = (row.pixel.res[ch], row.pixel.rest_dev[ch]);
            let bound = row.pixel.bound[ch];
            if !bound || r0 >= 0.0 {
                dark += r0 * r0 - rd * rd;
            }
            for (j, (s, l)) in sums.iter_mut().zip(radiance).enumerate() {
                let (c, d) = (row.c[j] as f64, row.d[j] as f64);
                if !bound || r0 - l[ch] * c >= 0.0 {
                    let s = &mut s[ch];
                    s[0] += r0 * r0 - rd * rd;
                    s[1] += r0 * c + d * rd;
                    s[2] += c * c - d * d;
                }
            }
        }
    }
    Counted { sums, dark }
}

/// Clipped pixels per parallel piece of [`add_constant_sums`].
const CHUNK: usize = 4096;

/// Adds to `sums[j][ch]` the `constant` pixels' sums in channel `ch` that count at every grid
/// point j, whose radiance in that channel is `radiance` (see the module doc); returns their
/// cost with light k dark.
fn add_constant_sums(
    constant: &[ClippedConstant],
    ch: usize,
    radiance: &[f64],
    sums: &mut [[[f64; 3]; 3]],
) -> f64 {
    let grid = radiance.len();
    let mut order: Vec<usize> = (0..grid).collect();
    order.sort_by(|&a, &b| radiance[a].total_cmp(&radiance[b]));
    let sorted: Vec<f64> = order.iter().map(|&j| radiance[j]).collect();
    // Fixed chunks summed in order: the same sums whatever the thread count.
    let parts: Vec<(Vec<[f64; 3]>, f64)> = constant
        .par_chunks(CHUNK)
        .map(|chunk| steps(chunk, ch, &sorted))
        .collect();
    let mut total = vec![[0f64; 3]; grid + 1];
    let mut dark = 0f64;
    for (part, part_dark) in parts {
        for (t, p) in total.iter_mut().zip(part) {
            for s in 0..3 {
                t[s] += p[s];
            }
        }
        dark += part_dark;
    }
    let mut running = [0f64; 3];
    for (m, &j) in order.iter().enumerate() {
        for s in 0..3 {
            running[s] += total[m][s];
        }
        for s in 0..3 {
            sums[j][ch][s] += running[s];
        }
    }
    dark
}

/// The `pixels`' sums in channel `ch` as steps along the grid's radiances `sorted` (at
/// `steps[m]`, what the sums gain from sorted position m on; one past the end unused), and
/// their cost with light k dark.
fn steps(pixels: &[ClippedConstant], ch: usize, sorted: &[f64]) -> (Vec<[f64; 3]>, f64) {
    let grid = sorted.len();
    let mut steps = vec![[0f64; 3]; grid + 1];
    let mut dark = 0f64;
    for &ClippedConstant { pixel, c, d } in pixels {
        let (r0, rd) = (pixel.res[ch], pixel.rest_dev[ch]);
        if c == 0.0 && d == 0.0 {
            // The cost is the same with and without light k.
            continue;
        }
        // (r0 - L c)^2 - (L d + rd)^2, a quadratic in L.
        let sums = [r0 * r0 - rd * rd, r0 * c + d * rd, c * c - d * d];
        let run = if pixel.bound[ch] {
            if r0 >= 0.0 {
                dark += sums[0];
            }
            // Counted where r0 - L c >= 0: L up to r0 / c for a positive c, from it on for a
            // negative one (a coefficient less its control variate can be), at every L or
            // none for a zero one.
            if c > 0.0 {
                let t = r0 / c;
                0..sorted.partition_point(|&l| l <= t)
            } else if c < 0.0 {
                let t = r0 / c;
                sorted.partition_point(|&l| l < t)..grid
            } else if r0 >= 0.0 {
                0..grid
            } else {
                0..0
            }
        } else {
            dark += sums[0];
            0..grid
        };
        for s in 0..3 {
            steps[run.start][s] += sums[s];
            steps[run.end][s] -= sums[s];
        }
    }
    (steps, dark)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Per grid point j, the cost the clipped pixels (`constant` and `rows`) add when light k's
    /// radiance is `radiance[j]`, less what they add with light k dark ([`ClippedPixel::cost`]).
    fn one_sided_costs(
        constant: &[ClippedConstant],
        rows: &[ClippedRow],
        radiance: &[[f64; 3]],
    ) -> Vec<f64> {
        let counted = counted(constant, rows, radiance);
        radiance
            .iter()
            .enumerate()
            .map(|(j, &l)| counted.cost(j, l))
            .collect()
    }

    #[test]
    fn gathered_costs_are_the_pixels_counted_one_by_one() {
        // Pixels with positive, negative and zero coefficients, residuals of both signs,
        // channels clipped and not; grid radiances unsorted, repeated and crossing many of
        // the pixels' thresholds r0 / c; more pixels than one parallel piece takes. Gathered,
        // their costs must be the pixels' own (`ClippedPixel::cost`, the cost's own rule)
        // summed at every grid point.
        let mut rng = crate::random::Rng::new(7, 0);
        let constant: Vec<ClippedConstant> = (0..2 * CHUNK + 500)
            .map(|n| {
                let c = match n % 7 {
                    0 => 0.0,
                    1 => -0.05 * rng.next_f64(),
                    _ => rng.next_f64(),
                };
                let d = if n % 5 == 0 {
                    0.0
                } else {
                    0.1 * (rng.next_f64() - 0.5)
                };
                let pixel = ClippedPixel {
                    res: [0; 3].map(|_| 4.0 * rng.next_f64() - 1.0),
                    rest_dev: [0; 3].map(|_| 0.2 * (rng.next_f64() - 0.5)),
                    bound: [0; 3].map(|_| rng.next_f64() < 0.7),
                };
                ClippedConstant { pixel, c, d }
            })
            .collect();
        let mut radiance: Vec<[f64; 3]> = (0..65)
            .map(|_| [0; 3].map(|_| 6.0 * rng.next_f64()))
            .collect();
        radiance[10] = radiance[40];
        radiance[20] = [0.0; 3];
        let got = one_sided_costs(&constant, &[], &radiance);
        let want: Vec<f64> = radiance
            .iter()
            .map(|l| {
                constant
                    .iter()
                    .flat_map(|p| (0..3).map(move |ch| p.pixel.cost(ch, l[ch], p.c, p.d)))
                    .sum()
            })
            .collect();
        let scale = want.iter().fold(0f64, |m, c| m.max(c.abs()));
        assert!(scale > 1.0, "the test's costs are not all zero: {scale}");
        for (j, (g, w)) in got.iter().zip(&want).enumerate() {
            assert!(
                (g - w).abs() <= 1e-12 * scale,
                "grid point {j}: {g} against {w}"
            );
        }
        // All equal radiances give all equal costs, bit for bit (an unconstrained edge's
        // flat profile keeps its current position).
        let flat = one_sided_costs(&constant, &[], &vec![radiance[3]; 65]);
        assert!(flat.iter().all(|&c| c == flat[0]), "{flat:?}");
        // The same pixels as rows, their coefficient and half-difference changing over the
        // grid: again each pixel's own cost at every grid point.
        let rows: Vec<ClippedRow> = constant[..300]
            .iter()
            .map(|p| ClippedRow {
                pixel: p.pixel,
                c: (0..65)
                    .map(|j| (p.c * (0.5 + j as f64 / 64.0)) as f32)
                    .collect(),
                d: (0..65)
                    .map(|j| (p.d * (1.5 - j as f64 / 64.0)) as f32)
                    .collect(),
            })
            .collect();
        let got = one_sided_costs(&[], &rows, &radiance);
        for (j, (g, l)) in got.iter().zip(&radiance).enumerate() {
            let want: f64 = rows
                .iter()
                .flat_map(|r| {
                    let (c, d) = (r.c[j] as f64, r.d[j] as f64);
                    (0..3).map(move |ch| r.pixel.cost(ch, l[ch], c, d))
                })
                .sum();
            assert!(
                (g - want).abs() <= 1e-12 * scale,
                "row grid point {j}: {g} against {want}"
            );
        }
    }

    #[test]
    fn a_clipped_channel_counts_only_below_the_photo() {
        // r0 = 2, c = 1, no noise: (2 - L)^2 - 4 for L up to 2, then the model is above the
        // photo and the channel adds nothing (-4 against the dark light); a value channel
        // keeps its square.
        let pixel = ClippedPixel {
            res: [2.0; 3],
            rest_dev: [0.0; 3],
            bound: [true, false, true],
        };
        let constant = [ClippedConstant {
            pixel,
            c: 1.0,
            d: 0.0,
        }];
        let radiance = [[1.0, 1.0, 0.0], [3.0, 3.0, 0.0]];
        let got = one_sided_costs(&constant, &[], &radiance);
        assert_eq!(got, vec![(1.0 - 4.0) + (1.0 - 4.0), -4.0 + (1.0 - 4.0)]);
    }
}
