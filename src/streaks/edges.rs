//! Step 6 of METHOD.md §5 (the paper's §3.2.3): the edge pixels of a streak.
//!
//! Pixel p of streak m is a left-edge pixel when none of the three pixels to its left in the
//! 3x3 around it belongs to m (pixels outside the image belong to no streak); likewise right,
//! top and bottom. A pixel can be on several sides at once (a corner, or a streak one pixel
//! wide).

/// The edge pixels of one streak by side, as indices y * width + x in raster order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct StreakEdges {
    /// Pixels with no streak pixel among their three left neighbours.
    pub left: Vec<u32>,
    /// Pixels with no streak pixel among their three right neighbours.
    pub right: Vec<u32>,
    /// Pixels with no streak pixel among their three upper neighbours.
    pub top: Vec<u32>,
    /// Pixels with no streak pixel among their three lower neighbours.
    pub bottom: Vec<u32>,
}

/// The edges of the streak `id`, given which streak every pixel belongs to (`owner`, with any
/// value other than `id` meaning "not in it") and the streak's pixels.
pub fn streak_edges(
    width: u32,
    height: u32,
    owner: &[u32],
    id: u32,
    pixels: &[u32],
) -> StreakEdges {
    let (w, h) = (width as i64, height as i64);
    let inside =
        |x: i64, y: i64| x >= 0 && y >= 0 && x < w && y < h && owner[(y * w + x) as usize] == id;
    let mut edges = StreakEdges::default();
    for &p in pixels {
        let (x, y) = (p as i64 % w, p as i64 / w);
        let none = |dx: i64, dy: i64, across: bool| {
            // `across`: the three pixels run along x (top/bottom) rather than along y.
            (-1..=1).all(|t| {
                if across {
                    !inside(x + t, y + dy)
                } else {
                    !inside(x + dx, y + t)
                }
            })
        };
        if none(-1, 0, false) {
            edges.left.push(p);
        }
        if none(1, 0, false) {
            edges.right.push(p);
        }
        if none(0, -1, true) {
            edges.top.push(p);
        }
        if none(0, 1, true) {
            edges.bottom.push(p);
        }
    }
    edges
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let e = streak_edges(w, h, &owner, 0, &pixels);
        assert_eq!(e.left, vec![6, 11]);
        assert_eq!(e.right, vec![8, 13]);
        assert_eq!(e.top, vec![6, 7, 8]);
        assert_eq!(e.bottom, vec![11, 12, 13]);

        // A staircase: (1,0), (0,1), (1,1). (1,0)'s left column holds (0,1) (below-left), so it
        // is not a left-edge pixel; (0,1) is.
        let (w, h) = (3u32, 2u32);
        let mut owner = vec![u32::MAX; 6];
        for p in [1u32, 3, 4] {
            owner[p as usize] = 7;
        }
        let e = streak_edges(w, h, &owner, 7, &[1, 3, 4]);
        assert_eq!(e.left, vec![3]);
        // (0,1)'s upper row holds (1,0) (above-right): only (1,0) is a top-edge pixel.
        assert_eq!(e.top, vec![1]);
        assert_eq!(e.bottom, vec![3, 4]);
        assert_eq!(e.right, vec![1, 4]);
    }
}
