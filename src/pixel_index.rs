//! Where each pixel of a list lies in it, found by column and row: a dense grid over the
//! pixels' bounding box rather than a map, since a high-pass window or a correlation lag
//! reads hundreds of neighbours of each of up to a few hundred thousand pixels.

/// The positions in a list of pixels, by column and row.
pub struct PixelIndex {
    x0: i64,
    y0: i64,
    x1: i64,
    y1: i64,
    index: Vec<usize>,
}

impl PixelIndex {
    /// The index of `pixels` (pixel indices of a `width`-wide photo); of a pixel listed twice,
    /// its last position.
    pub fn new(pixels: impl Iterator<Item = u32> + Clone, width: u32) -> Self {
        let w = i64::from(width.max(1));
        let (mut x0, mut y0, mut x1, mut y1) = (i64::MAX, i64::MAX, i64::MIN, i64::MIN);
        for p in pixels.clone() {
            let (x, y) = (i64::from(p) % w, i64::from(p) / w);
            (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
        }
        if x0 > x1 {
            return PixelIndex {
                x0: 0,
                y0: 0,
                x1: -1,
                y1: -1,
                index: Vec::new(),
            };
        }
        let box_width = x1 - x0 + 1;
        let mut index = vec![usize::MAX; (box_width * (y1 - y0 + 1)) as usize];
        for (i, p) in pixels.enumerate() {
            let (x, y) = (i64::from(p) % w, i64::from(p) / w);
            index[((y - y0) * box_width + x - x0) as usize] = i;
        }
        PixelIndex {
            x0,
            y0,
            x1,
            y1,
            index,
        }
    }

    /// The position in the list of the pixel in column `x`, row `y`, if it is listed.
    pub fn at(&self, x: i64, y: i64) -> Option<usize> {
        if x < self.x0 || x > self.x1 || y < self.y0 || y > self.y1 {
            return None;
        }
        let j = self.index[((y - self.y0) * (self.x1 - self.x0 + 1) + x - self.x0) as usize];
        (j != usize::MAX).then_some(j)
    }
}

#[cfg(test)]
mod tests {
    use super::PixelIndex;

    /// Listed pixels are found at their positions (a repeated one at its last), others and
    /// anything outside the box are not, and an empty list finds nothing.
    #[test]
    fn pixels_are_found_where_they_are_listed() {
        let width = 10u32;
        let pixels = [23u32, 25, 47, 23, 31];
        let index = PixelIndex::new(pixels.iter().copied(), width);
        assert_eq!(index.at(3, 2), Some(3));
        assert_eq!(index.at(5, 2), Some(1));
        assert_eq!(index.at(7, 4), Some(2));
        assert_eq!(index.at(1, 3), Some(4));
        assert_eq!(index.at(4, 2), None);
        assert_eq!(index.at(0, 0), None);
        assert_eq!(index.at(-1, 3), None);
        assert_eq!(index.at(3, 9), None);
        let empty = PixelIndex::new(std::iter::empty(), width);
        assert_eq!(empty.at(0, 0), None);
    }
}
