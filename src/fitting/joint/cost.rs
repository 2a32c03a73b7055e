//! The joint fit's cost and its radiances (method §5, last paragraph): the residual sum of
//! squares over the fitted pixels, less the coefficients' own noise, and the nonnegative
//! least squares of the radiances given the rectangles.
//!
//! The model is linear in the radiances: given the rectangles they are a nonnegative least
//! squares solve per channel ([`Problem::solve_radiance`]). A clipped pixel only counts when
//! the model is below it (it is a lower bound, method §2).
//!
//! # The noise of the coefficients, and why the fit must remove it
//!
//! The coefficients are Monte Carlo estimates, and least squares with a noisy regressor is
//! biased: sum c_hat^2 overestimates sum c^2 by the summed variance, which pulls the radiance
//! low and pushes the edges to compensate (the weakly seen edges move by a percent). Each
//! pixel's samples are two independent halves, A and B (the sign of a stored weight says
//! which); the coefficient is (A + B) / 2 and `d = (A - B) / 2`, its half-difference, has
//! E[d^2] = var(c_hat) whatever the stratification inside each half. More: for the modelled
//! pixel m = sum_k L_k c_k, E[(sum_k L_k d_k)^2] = var(m_hat) including the covariances of
//! lights that share samples (two pieces of one rectangle are strongly anti-correlated:
//! subtracting their variances one by one would reward splitting a light in two). So the fit
//! minimises sum (I - m_hat)^2 - (sum_k L_k d_k)^2, an unbiased estimate of the noise-free
//! cost up to a constant, and its normal equations carry `c_a c_b - d_a d_b`.

use super::problem::{Problem, State};
use super::ModelledPixel;
use crate::fitting::linalg::nnls_normal;
use crate::fitting::rect::Rect;

/// Row-summed over plain cost above which a residual counts as structured and a split is
/// tried (see [`Problem::structured`]).
pub(super) const SPLIT_STRUCTURE_RATIO: f64 = 3.0;

impl Problem {
    /// A state with these lights, their coefficients computed and radiances solved.
    pub(super) fn state(
        &self,
        set_of: Vec<usize>,
        pinned: Vec<[bool; 4]>,
        rects: Vec<Rect>,
        radiance: Vec<[f64; 3]>,
    ) -> State {
        let (coef, dev) = rects
            .iter()
            .zip(&set_of)
            .map(|(r, &set)| self.coefficients(set, r))
            .unzip();
        let mut st = State {
            set_of,
            pinned,
            rects,
            radiance,
            coef,
            dev,
        };
        self.solve_radiance(&mut st);
        st
    }

    /// The modelled pixel i, per channel: every light's radiance times its coefficient.
    pub(super) fn model(&self, st: &State, i: usize) -> [f64; 3] {
        let mut m = [0.0; 3];
        for (k, l) in st.radiance.iter().enumerate() {
            let c = st.coef[k][i] as f64;
            for ch in 0..3 {
                m[ch] += l[ch] * c;
            }
        }
        m
    }

    /// The expected image of the water pixels for `st`: each pixel's index into the photo
    /// with its modelled radiance, unweighted (`scales`: the rows' weights, where they were
    /// weighted). The direct view's pixels are left out: a light's sharp image there would
    /// match the photo whatever the water model.
    pub(super) fn water_image(&self, st: &State, scales: Option<&[f32]>) -> Vec<ModelledPixel> {
        (0..self.first_direct)
            .map(|i| {
                let s = scales.map_or(1.0, |s| s[i]);
                (self.pixel_ids[i], self.model(st, i).map(|c| c as f32 / s))
            })
            .collect()
    }

    /// Residual sum of squares (clipped pixels only where the model is below them), less the
    /// coefficients' own noise (see the module doc).
    pub(super) fn cost(&self, st: &State) -> f64 {
        self.residual_squares(st, true)
    }

    /// The residual variance per pixel and channel: the cost over its degrees of freedom
    /// (three channels a pixel, seven parameters a light), at least the smallest positive
    /// number.
    pub(super) fn residual_variance(&self, st: &State) -> f64 {
        let dof = (self.n() * 3).saturating_sub(7 * st.rects.len()).max(1) as f64;
        (self.cost(st) / dof).max(f64::MIN_POSITIVE)
    }

    /// The plain residual sum of squares, the coefficients' noise left in.
    pub(super) fn raw_cost(&self, st: &State) -> f64 {
        self.residual_squares(st, false)
    }

    fn residual_squares(&self, st: &State, remove_noise: bool) -> f64 {
        (0..self.n())
            .map(|i| {
                let m = self.model(st, i);
                (0..3)
                    .map(|c| {
                        match squared_residual(self.obs[i][c], m[c], self.clipped_channels[i][c]) {
                            None => 0.0,
                            Some(squared) if remove_noise => {
                                let d: f64 = st
                                    .radiance
                                    .iter()
                                    .enumerate()
                                    .map(|(k, l)| l[c] * st.dev[k][i] as f64)
                                    .sum();
                                squared - d * d
                            }
                            Some(squared) => squared,
                        }
                    })
                    .sum::<f64>()
            })
            .sum()
    }

    /// Whether the residual is structured along rows: for noise independent from pixel to
    /// pixel the row-summed cost is about the plain one, a light missing from the model
    /// makes it many times larger (Table 1's fit: 1.05; two stacked lights fitted as one:
    /// 15).
    pub(super) fn structured(&self, st: &State) -> bool {
        self.row_cost(st) > SPLIT_STRUCTURE_RATIO * self.raw_cost(st)
    }

    /// The residual summed over each image row, squared and summed: a misfit that persists
    /// along rows (one light where there are two) grows with the row's pixel count squared,
    /// the noise only with the count, so the comparison is not at the noise's mercy.
    pub(super) fn row_cost(&self, st: &State) -> f64 {
        let mut rows: std::collections::BTreeMap<u32, [f64; 3]> = Default::default();
        for i in 0..self.n() {
            if self.clipped[i] {
                continue;
            }
            let m = self.model(st, i);
            let row = rows.entry(self.pixel_ids[i] / self.width).or_default();
            for c in 0..3 {
                row[c] += self.obs[i][c] as f64 - m[c];
            }
        }
        rows.values().flatten().map(|r| r * r).sum()
    }

    /// Re-solves every radiance given the rectangles: per channel, nonnegative least squares
    /// over the pixels, a clipped channel included only while the model stays below it.
    pub(super) fn solve_radiance(&self, st: &mut State) {
        let k = st.rects.len();
        let mut include: Vec<[bool; 3]> = self
            .clipped_channels
            .iter()
            .map(|c| c.map(|c| !c))
            .collect();
        for _round in 0..3 {
            for ch in 0..3 {
                let mut ata = vec![0.0; k * k];
                let mut atb = vec![0.0; k];
                let mut raw_diag = vec![0.0; k];
                for i in (0..self.n()).filter(|&i| include[i][ch]) {
                    for a in 0..k {
                        let ca = st.coef[a][i] as f64;
                        if ca == 0.0 {
                            continue;
                        }
                        atb[a] += ca * self.obs[i][ch] as f64;
                        let da = st.dev[a][i] as f64;
                        for b in 0..k {
                            ata[a * k + b] += ca * st.coef[b][i] as f64 - da * st.dev[b][i] as f64;
                        }
                        raw_diag[a] += ca * ca;
                    }
                }
                for a in 0..k {
                    // As in the edge profile: never trust less than half the raw term.
                    ata[a * k + a] = ata[a * k + a].max(0.5 * raw_diag[a]);
                }
                let x = nnls_normal(&ata, &atb, k);
                for (l, xa) in st.radiance.iter_mut().zip(&x) {
                    l[ch] = *xa;
                }
            }
            let mut changed = false;
            for i in (0..self.n()).filter(|&i| self.clipped[i]) {
                let m = self.model(st, i);
                for c in 0..3 {
                    let counts = !self.clipped_channels[i][c] || m[c] < self.obs[i][c] as f64;
                    if counts != include[i][c] {
                        include[i][c] = counts;
                        changed = true;
                    }
                }
            }
            if !changed {
                break;
            }
        }
    }

    /// At pixel i, the other lights' model and their combined half-difference, per channel.
    pub(super) fn others(&self, st: &State, k: usize, i: usize) -> ([f64; 3], [f64; 3]) {
        let (mut rest, mut rest_dev) = ([0f64; 3], [0f64; 3]);
        for (kk, l) in st.radiance.iter().enumerate() {
            if kk != k {
                let (c, d) = (st.coef[kk][i] as f64, st.dev[kk][i] as f64);
                for ch in 0..3 {
                    rest[ch] += l[ch] * c;
                    rest_dev[ch] += l[ch] * d;
                }
            }
        }
        (rest, rest_dev)
    }
}

/// A channel's squared residual, the photo's value `obs` against the `model`, or `None` for a
/// channel the photo clipped (`clipped`: a lower bound) that the model does not fall below.
pub(super) fn squared_residual(obs: f32, model: f64, clipped: bool) -> Option<f64> {
    let r = obs as f64 - model;
    (!(clipped && r < 0.0)).then_some(r * r)
}
