//! Step 6 of method §5 (the paper's §3.2.3): the edge pixels of a streak.
//!
//! Pixel p of a streak is a left-edge pixel when none of the three pixels to its left in the
//! 3x3 around it belongs to the streak (pixels outside the image belong to no streak);
//! likewise right, bottom and top. A pixel can be on several sides at once (a corner, or a
//! streak one pixel wide). [`streak_edges`] is the one implementation of this rule: the
//! extraction and the fitter's [`crate::fitting::StreakObservation::from_pixels`] both call it.

use std::ops::{Index, IndexMut};

/// A side of a streak in the image: towards column 0 or the last column, the last row or row
/// 0.
///
/// This is not a side of the light: a reflection flips the vertical order, so a streak's top
/// shows the light's bottom edge ([`crate::fitting::EdgeSide::streak_side`] gives the paper's
/// mapping). The two types share one order, Left, Right, Bottom, Top, so that an array of four
/// reads the same whichever of them indexes it; an array of four indexed by `StreakSide`
/// (`array[StreakSide::Top]`) is one value per side in that order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum StreakSide {
    /// Towards column 0.
    Left = 0,
    /// Towards the last column.
    Right = 1,
    /// Towards the last row.
    Bottom = 2,
    /// Towards row 0.
    Top = 3,
}

impl StreakSide {
    /// All four, in the order of arrays indexed by side.
    pub const ALL: [StreakSide; 4] = [
        StreakSide::Left,
        StreakSide::Right,
        StreakSide::Bottom,
        StreakSide::Top,
    ];

    /// "left", "right", "bottom" or "top".
    pub fn name(self) -> &'static str {
        match self {
            StreakSide::Left => "left",
            StreakSide::Right => "right",
            StreakSide::Bottom => "bottom",
            StreakSide::Top => "top",
        }
    }

    /// The three neighbour offsets (dx, dy) on this side of a pixel in its 3 x 3 (y grows
    /// downwards, towards the last row).
    pub fn outward_neighbours(self) -> [(i32, i32); 3] {
        match self {
            StreakSide::Left => [(-1, -1), (-1, 0), (-1, 1)],
            StreakSide::Right => [(1, -1), (1, 0), (1, 1)],
            StreakSide::Bottom => [(-1, 1), (0, 1), (1, 1)],
            StreakSide::Top => [(-1, -1), (0, -1), (1, -1)],
        }
    }
}

impl<T> Index<StreakSide> for [T; 4] {
    type Output = T;
    fn index(&self, side: StreakSide) -> &T {
        &self[side as usize]
    }
}

impl<T> IndexMut<StreakSide> for [T; 4] {
    fn index_mut(&mut self, side: StreakSide) -> &mut T {
        &mut self[side as usize]
    }
}

/// The edge pixels of one streak, indexed by [`StreakSide`]: per side, the pixels with no
/// streak pixel among their three neighbours on that side, as indices y * width + x in the
/// order the streak's pixels were given.
pub type StreakEdges = [Vec<u32>; 4];

/// The edges of the streak made of `pixels` (indices y * width + x), given which pixels of the
/// image belong to it: `is_member(x, y)`, asked only for pixels inside the image (outside
/// belongs to no streak). Each side lists its pixels in the order of `pixels`.
pub fn streak_edges(
    width: u32,
    height: u32,
    pixels: &[u32],
    is_member: impl Fn(u32, u32) -> bool,
) -> StreakEdges {
    let (w, h) = (width as i64, height as i64);
    let inside =
        |x: i64, y: i64| x >= 0 && y >= 0 && x < w && y < h && is_member(x as u32, y as u32);
    let mut edges = StreakEdges::default();
    for &p in pixels {
        let (x, y) = (p as i64 % w, p as i64 / w);
        for side in StreakSide::ALL {
            let none = side
                .outward_neighbours()
                .iter()
                .all(|&(dx, dy)| !inside(x + dx as i64, y + dy as i64));
            if none {
                edges[side].push(p);
            }
        }
    }
    edges
}

#[cfg(test)]
mod tests {
    use super::StreakSide::{Bottom, Left, Right, Top};
    use super::*;

    /// The edges of the pixels `owner` gives `id`.
    fn edges_of(w: u32, h: u32, owner: &[u32], id: u32, pixels: &[u32]) -> StreakEdges {
        streak_edges(w, h, pixels, |x, y| owner[(y * w + x) as usize] == id)
    }

    #[test]
    fn edges_of_a_rectangle_and_a_staircase() {
        // A 3x2 rectangle at x 1..=3, y 1..=2 in a 5x4 image.
        let (w, h) = (5u32, 4u32);
        let mut owner = vec![u32::MAX; 20];
        let mut pixels = Vec::new();
        for y in 1..=2u32 {
            for x in 1..=3u32 {
                owner[(y * w + x) as usize] = 0;
                pixels.push(y * w + x);
            }
        }
        let e = edges_of(w, h, &owner, 0, &pixels);
        assert_eq!(e[Left], vec![6, 11]);
        assert_eq!(e[Right], vec![8, 13]);
        assert_eq!(e[Top], vec![6, 7, 8]);
        assert_eq!(e[Bottom], vec![11, 12, 13]);

        // A staircase: (1,0), (0,1), (1,1). (1,0)'s left column holds (0,1) (below-left), so it
        // is not a left-edge pixel; (0,1) is.
        let (w, h) = (3u32, 2u32);
        let mut owner = vec![u32::MAX; 6];
        for p in [1u32, 3, 4] {
            owner[p as usize] = 7;
        }
        let e = edges_of(w, h, &owner, 7, &[1, 3, 4]);
        assert_eq!(e[Left], vec![3]);
        // (0,1)'s upper row holds (1,0) (above-right): only (1,0) is a top-edge pixel.
        assert_eq!(e[Top], vec![1]);
        assert_eq!(e[Bottom], vec![3, 4]);
        assert_eq!(e[Right], vec![1, 4]);
    }

    #[test]
    fn sides_index_in_one_order() {
        let names = StreakSide::ALL.map(StreakSide::name);
        assert_eq!(names, ["left", "right", "bottom", "top"]);
        let mut a = [0; 4];
        for (k, side) in StreakSide::ALL.into_iter().enumerate() {
            a[side] = k;
        }
        assert_eq!(a, [0, 1, 2, 3]);
    }
}
