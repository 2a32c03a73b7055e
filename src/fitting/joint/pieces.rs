//! An edge profile's normal-equation sums ([`super::profile`]) gathered as polynomials over
//! runs of the grid rather than point by point.
//!
//! Over a narrow window most pixels' coefficients are smooth in the edge's position: linear
//! between the few kernel edges inside the window ([`super::ramps::EdgeRamps::for_each_piece`])
//! plus the control variate's Gaussian, which over a window far narrower than its deviation
//! is a cubic to within the f32 rounding of its table. A pixel's `c^2 - d^2`, `c^2` and
//! `c r + d r'` are then polynomials in the grid position, added once per run (as differences
//! at the run's ends) instead of once per grid point; the runs are summed and the
//! polynomials evaluated at every grid point once per chunk of pixels.

/// Coefficients of `c^2 - d^2` (7), `c^2` (7) and, per channel, `c r + d r'` (4 each).
const TERMS: usize = 26;

/// A window of `grid` points `lo + j step`, as the variable `x = (j - m) / m`, `m = (grid -
/// 1) / 2`, which runs from -1 to 1: the polynomials in it stay well conditioned.
#[derive(Clone, Copy)]
pub(super) struct Window {
    /// The edge's position at `x = 0`.
    pub(super) centre: f64,
    /// Half the window's length: `t = centre + half x`.
    pub(super) half: f64,
    /// `m`.
    middle: f64,
}

impl Window {
    /// The window of `grid` (at least 2) points from `lo` by `step`.
    pub(super) fn new(lo: f32, step: f32, grid: usize) -> Self {
        let middle = (grid - 1) as f64 / 2.0;
        let half = middle * step as f64;
        Window {
            centre: lo as f64 + half,
            half,
            middle,
        }
    }

    /// Grid point j's x.
    fn x(&self, j: usize) -> f64 {
        (j as f64 - self.middle) / self.middle
    }

    /// The cubic in x through `values` at `x = -1, -1/3, 1/3, 1` (see [`CUBIC_NODES`]), as
    /// coefficients of `1, x, x^2, x^3`.
    pub(super) fn cubic(values: [f64; 4]) -> [f64; 4] {
        let [y0, y1, y2, y3] = values;
        // Even and odd parts at x = 1 and x = 1/3.
        let (e1, e3) = (0.5 * (y3 + y0), 0.5 * (y2 + y1));
        let (o1, o3) = (0.5 * (y3 - y0), 0.5 * (y2 - y1));
        [
            (9.0 * e3 - e1) / 8.0,
            (27.0 * o3 - o1) / 8.0,
            9.0 * (e1 - e3) / 8.0,
            (9.0 * o1 - 27.0 * o3) / 8.0,
        ]
    }
}

/// Where [`Window::cubic`] takes its values.
pub(super) const CUBIC_NODES: [f64; 4] = [-1.0, -1.0 / 3.0, 1.0 / 3.0, 1.0];

/// The runs' polynomials, as differences at their first and one-past-last grid points.
pub(super) struct PieceSums {
    diff: Vec<[f64; TERMS]>,
    /// Whether any run was added since the last [`Self::add_to`].
    any: bool,
}

impl PieceSums {
    pub(super) fn new(grid: usize) -> Self {
        PieceSums {
            diff: vec![[0.0; TERMS]; grid + 1],
            any: false,
        }
    }

    /// Adds a pixel over the grid points `j0..j1`, where its coefficient is the cubic `c` and
    /// its half-difference the line `d` (in x), and the rest of its residual is `res` (the
    /// others' half-differences `rest_dev`): `c^2 - d^2`, `c^2` and `c res + d rest_dev`.
    pub(super) fn add(
        &mut self,
        j0: usize,
        j1: usize,
        c: [f64; 4],
        d: [f64; 2],
        res: [f64; 3],
        rest_dev: [f64; 3],
    ) {
        if j0 >= j1 {
            return;
        }
        let mut terms = [0f64; TERMS];
        for (p, cp) in c.iter().enumerate() {
            for (q, cq) in c.iter().enumerate() {
                terms[p + q] += cp * cq;
                terms[7 + p + q] += cp * cq;
            }
        }
        terms[0] -= d[0] * d[0];
        terms[1] -= 2.0 * d[0] * d[1];
        terms[2] -= d[1] * d[1];
        for ch in 0..3 {
            let at = 14 + 4 * ch;
            for (p, cp) in c.iter().enumerate() {
                terms[at + p] += cp * res[ch];
            }
            terms[at] += d[0] * rest_dev[ch];
            terms[at + 1] += d[1] * rest_dev[ch];
        }
        for (d, t) in self.diff[j0].iter_mut().zip(&terms) {
            *d += t;
        }
        for (d, t) in self.diff[j1].iter_mut().zip(&terms) {
            *d -= t;
        }
        self.any = true;
    }

    /// Adds the runs' sums at every grid point of `window` to `a` (`c^2 - d^2`), `a_raw`
    /// (`c^2`) and `b` (`c res + d rest_dev`).
    pub(super) fn add_to(
        &self,
        window: &Window,
        a: &mut [f64],
        a_raw: &mut [f64],
        b: &mut [[f64; 3]],
    ) {
        if !self.any {
            return;
        }
        let mut run = [0f64; TERMS];
        for (j, ((a, a_raw), b)) in a.iter_mut().zip(a_raw.iter_mut()).zip(b).enumerate() {
            for (r, d) in run.iter_mut().zip(&self.diff[j]) {
                *r += d;
            }
            let x = window.x(j);
            let poly = |coefficients: &[f64]| coefficients.iter().rev().fold(0.0, |s, c| s * x + c);
            *a += poly(&run[0..7]);
            *a_raw += poly(&run[7..14]);
            for (ch, b) in b.iter_mut().enumerate() {
                *b += poly(&run[14 + 4 * ch..18 + 4 * ch]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Rng;

    #[test]
    fn the_cubic_through_four_points_is_the_cubic() {
        let f = |x: f64| 0.3 - 1.7 * x + 0.25 * x * x + 2.5 * x * x * x;
        let c = Window::cubic(CUBIC_NODES.map(f));
        let want = [0.3, -1.7, 0.25, 2.5];
        for (got, want) in c.iter().zip(want) {
            assert!((got - want).abs() < 1e-12, "{c:?}");
        }
    }

    #[test]
    fn runs_sum_to_the_pointwise_sums() {
        // Random runs of random cubics and lines against the sums made grid point by grid
        // point.
        let mut rng = Rng::new(11, 0);
        let grid = 65;
        let window = Window::new(-2.0, 0.01, grid);
        let mut sums = PieceSums::new(grid);
        let (mut a, mut a_raw, mut b) = (vec![0f64; grid], vec![0f64; grid], vec![[0f64; 3]; grid]);
        let mut want = (vec![0f64; grid], vec![0f64; grid], vec![[0f64; 3]; grid]);
        let mut r = || rng.next_f32() as f64 - 0.5;
        for _ in 0..50 {
            let j0 = (r() + 0.5) * grid as f64;
            let j1 = j0 + (r() + 0.5) * grid as f64;
            let (j0, j1) = (j0 as usize, (j1 as usize).min(grid));
            let c = [r(), r(), r(), r()];
            let d = [r(), r()];
            let res = [r(), r(), r()];
            let rest_dev = [r(), r(), r()];
            sums.add(j0, j1, c, d, res, rest_dev);
            for j in j0..j1 {
                let x = window.x(j);
                let cv = c[0] + x * (c[1] + x * (c[2] + x * c[3]));
                let dv = d[0] + x * d[1];
                want.0[j] += cv * cv - dv * dv;
                want.1[j] += cv * cv;
                for ch in 0..3 {
                    want.2[j][ch] += cv * res[ch] + dv * rest_dev[ch];
                }
            }
        }
        sums.add_to(&window, &mut a, &mut a_raw, &mut b);
        for j in 0..grid {
            assert!(
                (a[j] - want.0[j]).abs() < 1e-9,
                "{j}: {} {}",
                a[j],
                want.0[j]
            );
            assert!((a_raw[j] - want.1[j]).abs() < 1e-9);
            for (got, want) in b[j].iter().zip(want.2[j]) {
                assert!((got - want).abs() < 1e-9);
            }
        }
    }
}
