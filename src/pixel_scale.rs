//! Lengths in pixels measured on the samples' photos (600 rows through a vertical field of
//! view of 60 degrees: 10 rows per degree), carried to a photo of another resolution. A glint
//! covers the same angle at any resolution, and so does the correlation of the glitter the
//! statistical model leaves in the residual, so on a finer photo each spans more pixels.

/// The samples' rows per degree of the camera's vertical field of view, at which the lengths
/// given to [`scaled_pixels`] were measured.
pub const SAMPLE_ROWS_PER_DEGREE: f64 = 10.0;

/// A length of `base` pixels on the samples, on a photo of `rows` rows through a vertical
/// field of view of `yfov` radians: grown in proportion to the rows per degree, never below
/// `base` (a coarser photo keeps it), and `base` for a degenerate field of view.
pub fn scaled_pixels(base: i64, rows: u32, yfov: f32) -> i64 {
    let per_degree = rows as f64 / (yfov as f64).to_degrees();
    if !per_degree.is_finite() {
        return base;
    }
    let scaled = (base as f64 * per_degree / SAMPLE_ROWS_PER_DEGREE).round();
    base.max(scaled.min(1000.0) as i64)
}

#[cfg(test)]
mod tests {
    use super::scaled_pixels;

    /// 3 pixels of the samples' 600 rows over 60 degrees: 3 there, 5.4 (5) at 1080 rows, 15
    /// at 3000; a coarser photo or a wider view keeps 3, and a degenerate field of view does
    /// not break it.
    #[test]
    fn lengths_grow_with_the_rows_per_degree() {
        let sixty = 60f32.to_radians();
        assert_eq!(scaled_pixels(3, 600, sixty), 3);
        assert_eq!(scaled_pixels(3, 1080, sixty), 5);
        assert_eq!(scaled_pixels(3, 3000, sixty), 15);
        assert_eq!(scaled_pixels(8, 3000, sixty), 40);
        assert_eq!(scaled_pixels(3, 2000, 2.0 * sixty), 5);
        assert_eq!(scaled_pixels(3, 300, sixty), 3);
        assert_eq!(scaled_pixels(3, 600, 0.0), 3);
    }
}
