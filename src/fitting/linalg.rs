//! Small dense linear algebra for the joint fit (method §5, last paragraph): the nonnegative
//! least squares of the radiances given the rectangles, and the inverse behind the
//! uncertainties' covariance. The systems are small (one unknown per light for a channel's
//! radiances, at most seven per light for the covariance), so plain elimination is all they
//! need.

/// Solves the nonnegative least squares `min |b - A x|^2, x >= 0` for a small dense system
/// given by its normal equations (`ata` row-major n x n, `atb`), by dropping the most negative
/// variable until none is negative (exact for the few, mostly separated lights here).
pub(super) fn nnls_normal(ata: &[f64], atb: &[f64], n: usize) -> Vec<f64> {
    let mut active: Vec<bool> = vec![true; n];
    loop {
        let idx: Vec<usize> = (0..n).filter(|&i| active[i]).collect();
        let m = idx.len();
        let mut x = vec![0.0; n];
        if m == 0 {
            return x;
        }
        let mut a = vec![0.0; m * m];
        let mut b = vec![0.0; m];
        for (r, &i) in idx.iter().enumerate() {
            b[r] = atb[i];
            for (c, &j) in idx.iter().enumerate() {
                a[r * m + c] = ata[i * n + j];
            }
            // A light whose rectangle receives no sample has a zero row: keep it solvable.
            a[r * m + r] += 1e-12 * (1.0 + ata[i * n + i]);
        }
        let sol = solve(&mut a, &mut b, m);
        for (r, &i) in idx.iter().enumerate() {
            x[i] = sol[r];
        }
        let worst = idx
            .iter()
            .copied()
            .filter(|&i| x[i] < 0.0)
            .min_by(|&a, &b| x[a].total_cmp(&x[b]));
        match worst {
            Some(i) => active[i] = false,
            None => return x,
        }
    }
}

/// Gaussian elimination with partial pivoting (small dense systems).
pub(super) fn solve(a: &mut [f64], b: &mut [f64], n: usize) -> Vec<f64> {
    for col in 0..n {
        let piv = (col..n)
            .max_by(|&i, &j| a[i * n + col].abs().total_cmp(&a[j * n + col].abs()))
            .unwrap_or(col);
        if piv != col {
            for c in 0..n {
                a.swap(col * n + c, piv * n + c);
            }
            b.swap(col, piv);
        }
        let d = a[col * n + col];
        if d.abs() < 1e-300 {
            continue;
        }
        for r in col + 1..n {
            let f = a[r * n + col] / d;
            if f != 0.0 {
                for c in col..n {
                    a[r * n + c] -= f * a[col * n + c];
                }
                b[r] -= f * b[col];
            }
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let mut s = b[r];
        for c in r + 1..n {
            s -= a[r * n + c] * x[c];
        }
        let d = a[r * n + r];
        x[r] = if d.abs() < 1e-300 { 0.0 } else { s / d };
    }
    x
}

/// Inverse of a small symmetric positive matrix (for the radiance covariance); `None` when
/// singular.
pub(super) fn invert(m: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut inv = vec![0.0; n * n];
    for j in 0..n {
        let mut a = m.to_vec();
        let mut e = vec![0.0; n];
        e[j] = 1.0;
        let col = solve(&mut a, &mut e, n);
        for i in 0..n {
            if !col[i].is_finite() {
                return None;
            }
            inv[i * n + j] = col[i];
        }
    }
    Some(inv)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solve_and_invert_give_hand_computed_values() {
        // [2 1; 1 3] x = [3; 5]: x = (4/5, 7/5).
        let x = solve(&mut [2.0, 1.0, 1.0, 3.0], &mut [3.0, 5.0], 2);
        assert!(
            (x[0] - 0.8).abs() < 1e-12 && (x[1] - 1.4).abs() < 1e-12,
            "{x:?}"
        );
        // Its inverse is [3 -1; -1 2] / 5.
        let inv = invert(&[2.0, 1.0, 1.0, 3.0], 2).expect("invertible");
        for (got, want) in inv.iter().zip([0.6, -0.2, -0.2, 0.4]) {
            assert!((got - want).abs() < 1e-12, "{inv:?}");
        }
    }

    #[test]
    fn nnls_drops_the_variable_that_would_go_negative() {
        // Unconstrained: [2 1; 1 3] x = [3; 5] has x >= 0, kept.
        let x = nnls_normal(&[2.0, 1.0, 1.0, 3.0], &[3.0, 5.0], 2);
        assert!(
            (x[0] - 0.8).abs() < 1e-9 && (x[1] - 1.4).abs() < 1e-9,
            "{x:?}"
        );
        // [2 1; 1 3] x = [-1; 3] gives x0 < 0: it is held at 0, and x1 = 3 / 3.
        let x = nnls_normal(&[2.0, 1.0, 1.0, 3.0], &[-1.0, 3.0], 2);
        assert_eq!(x[0], 0.0);
        assert!((x[1] - 1.0).abs() < 1e-9, "{x:?}");
    }
}
