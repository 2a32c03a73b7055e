//! Connectivity enforcement for SLIC.

/// EPFL's `EnforceLabelConnectivity` (4-connected): relabels 4-connected pieces in raster
/// order; a piece of at most a quarter of the mean superpixel size joins the piece that its
/// first pixel touches on the left or above (or, failing those, right or below). Returns the
/// new labels and their count.
pub(super) fn enforce_connectivity(
    labels: &[u32],
    w: usize,
    h: usize,
    mean_size: usize,
) -> (Vec<u32>, usize) {
    const NONE: u32 = u32::MAX;
    let n = w * h;
    let mut out = vec![NONE; n];
    let mut queue: Vec<(u32, u32)> = Vec::with_capacity(1024);
    let mut next: u32 = 0;
    let small = (mean_size / 4).max(1);
    for start in 0..n {
        if out[start] != NONE {
            continue;
        }
        let (sx, sy) = (start % w, start / w);
        // EPFL's order: left, up, right, down; the last labelled one wins (a piece flooded
        // earlier can reach round to the right of or below this pixel).
        let mut adjacent = NONE;
        for (ok, j) in [
            (sx > 0, start.wrapping_sub(1)),
            (sy > 0, start.wrapping_sub(w)),
            (sx + 1 < w, start + 1),
            (sy + 1 < h, start + w),
        ] {
            if ok && out[j] != NONE {
                adjacent = out[j];
            }
        }
        let old = labels[start];
        out[start] = next;
        queue.clear();
        queue.push((sx as u32, sy as u32));
        let mut head = 0;
        while head < queue.len() {
            let (x, y) = (queue[head].0 as usize, queue[head].1 as usize);
            head += 1;
            let i = y * w + x;
            if x > 0 && out[i - 1] == NONE && labels[i - 1] == old {
                out[i - 1] = next;
                queue.push((x as u32 - 1, y as u32));
            }
            if y > 0 && out[i - w] == NONE && labels[i - w] == old {
                out[i - w] = next;
                queue.push((x as u32, y as u32 - 1));
            }
            if x + 1 < w && out[i + 1] == NONE && labels[i + 1] == old {
                out[i + 1] = next;
                queue.push((x as u32 + 1, y as u32));
            }
            if y + 1 < h && out[i + w] == NONE && labels[i + w] == old {
                out[i + w] = next;
                queue.push((x as u32, y as u32 + 1));
            }
        }
        if queue.len() <= small && adjacent != NONE {
            for &(x, y) in &queue {
                out[y as usize * w + x as usize] = adjacent;
            }
        } else {
            next += 1;
        }
    }
    (out, next as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_pieces_join_a_neighbour() {
        // Label 1 is split in two; the one-pixel piece at the right joins its neighbour.
        let labels = vec![
            1, 1, 0, 1, //
            1, 1, 0, 0, //
            1, 1, 0, 0,
        ];
        let (out, count) = enforce_connectivity(&labels, 4, 3, 6);
        assert_eq!(count, 2);
        assert_eq!(out, vec![0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1]);
    }
}
