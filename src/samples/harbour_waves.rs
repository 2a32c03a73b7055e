//! Harbour chop for the harbour samples: waves of 0.15 to 3 m with a main direction, so
//! that the slopes along the main direction are larger than across it.
//!
//! A realisation is a sum of sinusoids ([`RippleField`]) drawn from a seed: wavelengths
//! stratified over the spectrum's distribution, directions spread evenly over
//! [-spread, spread] about the main direction (stratified, then shuffled against the
//! wavelengths), random phases. Every component carries the same slope variance, so the
//! slope variances along and across the main direction depend only on the set of
//! directions: the spread is solved for on each realisation's directions, which makes both
//! variances exactly the spectrum's in every realisation, while the waves themselves differ.

use std::f64::consts::{FRAC_PI_2, TAU};

use crate::random::Rng;

use super::water_surface::{Ripple, RippleField};

/// A directional wave spectrum.
#[derive(Clone, Debug)]
pub struct WaveSpectrum {
    /// Shortest wavelength (m).
    pub min_wavelength: f64,
    /// Longest wavelength (m).
    pub max_wavelength: f64,
    /// Slope variance per unit of log wavelength grows as wavelength^`long_wave_weight`
    /// (0: every octave carries the same slope variance).
    pub long_wave_weight: f64,
    /// Root-mean-square slope along the main direction.
    pub rms_slope_along: f64,
    /// Root-mean-square slope across it (smaller than along).
    pub rms_slope_across: f64,
    /// Unit horizontal direction (x, z) the waves travel along.
    pub main_direction: [f64; 2],
    /// Number of sinusoids.
    pub count: usize,
}

/// The harbour samples' spectrum: waves of 0.15 to 3 m travelling towards the camera
/// (+z), rms slopes 0.06 along the view and 0.04 across it (0.072 in all). The components
/// are spread evenly over wavelength, so an octave carries slope variance in proportion to
/// its wavelengths: the waves a 0.1 m grid resolves well (above 0.5 m) carry 88 % of it.
pub fn harbour_spectrum() -> WaveSpectrum {
    WaveSpectrum {
        min_wavelength: 0.15,
        max_wavelength: 3.0,
        long_wave_weight: 1.0,
        rms_slope_along: 0.06,
        rms_slope_across: 0.04,
        main_direction: [0.0, 1.0],
        count: 96,
    }
}

impl WaveSpectrum {
    /// The wavelength at quantile `u` in [0, 1] of the spectrum's distribution of
    /// components over wavelength.
    fn wavelength(&self, u: f64) -> f64 {
        let (a, b, p) = (
            self.min_wavelength,
            self.max_wavelength,
            self.long_wave_weight,
        );
        if p.abs() < 1e-9 {
            a * (b / a).powf(u)
        } else {
            (a.powf(p) + u * (b.powf(p) - a.powf(p))).powf(1.0 / p)
        }
    }

    /// A realisation drawn from `seed`.
    pub fn realise(&self, seed: u64) -> RippleField {
        let n = self.count.max(1);
        let mut rng = Rng::new(seed, 0x4841_5242);
        let wavelengths: Vec<f64> = (0..n)
            .map(|i| self.wavelength((i as f64 + rng.next_f64()) / n as f64))
            .collect();
        // Stratified positions in [-1, 1], shuffled against the wavelengths.
        let mut positions: Vec<f64> = (0..n)
            .map(|i| 2.0 * (i as f64 + rng.next_f64()) / n as f64 - 1.0)
            .collect();
        for i in (1..n).rev() {
            let j = (rng.next_u32() as usize) % (i + 1);
            positions.swap(i, j);
        }
        let (along, across) = (self.rms_slope_along.powi(2), self.rms_slope_across.powi(2));
        let spread = solve_spread(&positions, across / (along + across));
        let per_component = (along + across) / n as f64;
        let [mx, mz] = self.main_direction;
        let ripples = wavelengths
            .iter()
            .zip(&positions)
            .map(|(&wavelength, &q)| {
                let k = TAU / wavelength;
                let (s, c) = (spread * q).sin_cos();
                // The main direction turned by the angle, towards (-mz, mx).
                let dir = [c * mx - s * mz, c * mz + s * mx];
                Ripple {
                    k: [k * dir[0], k * dir[1]],
                    amplitude: (2.0 * per_component).sqrt() / k,
                    phase: rng.next_f64() * TAU,
                }
            })
            .collect();
        RippleField::from_ripples(ripples)
    }
}

/// The spread S in [0, pi/2] for which the mean of sin^2(S q) over `positions` is `target`
/// (the share of the slope variance across the main direction), by bisection: the mean
/// grows with S there. A target beyond reach gives the nearest end.
fn solve_spread(positions: &[f64], target: f64) -> f64 {
    let share = |s: f64| {
        positions.iter().map(|q| (s * q).sin().powi(2)).sum::<f64>() / positions.len() as f64
    };
    let (mut lo, mut hi) = (0.0, FRAC_PI_2);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if share(mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The analytic slope variances of a realisation (the sum over its sinusoids of
    /// a^2 (k . u)^2 / 2) against the area-weighted variances measured numerically over a
    /// patch of the field itself, along and across the main direction and along a diagonal.
    /// The patch is 1 km square, sampled at 400 000 uniformly random points: the sampling
    /// error of each variance is about 0.2 % (sqrt(2 / 400 000)), and the cross terms
    /// between sinusoids average out over the patch to well under 1 %. A missing factor of
    /// 1/2, a projection on the wrong axis or along and across swapped would be off by a
    /// factor of 1.4 or more.
    #[test]
    fn analytic_slope_variances_match_the_sampled_field() {
        let spectrum = harbour_spectrum();
        let field = spectrum.realise(5);
        let axes = [[0.0, 1.0], [1.0, 0.0], [0.6, 0.8]];
        let mut rng = Rng::new(17, 3);
        let points = 400_000;
        let mut sums = [[0.0f64; 3]; 3];
        for _ in 0..points {
            let (x, z) = (1000.0 * rng.next_f64(), 1000.0 * rng.next_f64());
            let (_, gx, gz) = field.sample(x, z, 0.0, 0.0);
            for (a, axis) in axes.iter().enumerate() {
                let u = gx * axis[0] + gz * axis[1];
                let v = -gx * axis[1] + gz * axis[0];
                sums[a][0] += u * u;
                sums[a][1] += v * v;
                sums[a][2] += u * v;
            }
        }
        for (a, axis) in axes.iter().enumerate() {
            let exact = field.slope_variances(*axis);
            let measured = sums[a].map(|s| s / points as f64);
            let total = exact.along + exact.across;
            eprintln!("axis {axis:?}: analytic {exact:?}, sampled {measured:?}");
            assert!((measured[0] / exact.along - 1.0).abs() < 0.01);
            assert!((measured[1] / exact.across - 1.0).abs() < 0.01);
            assert!((measured[2] - exact.covariance).abs() < 0.01 * total);
        }
    }

    /// Every realisation has the spectrum's slope variances exactly: 0.06^2 along the main
    /// direction, 0.04^2 across, no covariance (the directions are spread evenly both
    /// ways), while the waves of two seeds differ.
    #[test]
    fn realisations_share_the_spectrum_statistics() {
        let spectrum = harbour_spectrum();
        let (a, b) = (spectrum.realise(1), spectrum.realise(2));
        for field in [&a, &b] {
            let v = field.slope_variances(spectrum.main_direction);
            assert!((v.along - 0.0036).abs() < 1e-12, "{v:?}");
            assert!((v.across - 0.0016).abs() < 1e-9, "{v:?}");
            assert!(v.covariance.abs() < 2e-4, "{v:?}");
            for r in field.ripples() {
                let wavelength = TAU / r.k[0].hypot(r.k[1]);
                assert!((0.15..=3.0).contains(&wavelength), "{wavelength}");
            }
        }
        let height = |f: &RippleField| f.sample(1.0, 2.0, 0.0, 0.0).0;
        assert!((height(&a) - height(&b)).abs() > 1e-4);
    }
}
