//! Connectivity enforcement for SLIC, on runs of equal labels rather than pixel by pixel.
//!
//! EPFL floods every piece from its first pixel in raster order, one pixel at a time. The same
//! result comes from the runs of each row: runs of one label that overlap in consecutive rows
//! are one piece (union-find), the smallest run index of a piece is the run holding its first
//! pixel, so visiting pieces in that order is EPFL's order, and whether a neighbour of that
//! first pixel "is labelled already" when EPFL reaches it becomes "its piece comes earlier".

use rayon::prelude::*;

/// EPFL's `EnforceLabelConnectivity` (4-connected): relabels 4-connected pieces in raster
/// order; a piece of at most a quarter of the mean superpixel size joins the piece that its
/// first pixel touches on the left or above (or, failing those, right or below). Relabels in
/// place and returns the number of labels.
pub(super) fn enforce_connectivity(
    labels: &mut [u32],
    w: usize,
    h: usize,
    mean_size: usize,
) -> usize {
    const NONE: u32 = u32::MAX;
    let small = (mean_size / 4).max(1);

    // The first column of every run, row by row, each row closed by an entry `w`: the runs of
    // row y are `first[y]..first[y + 1] - 1`, run r covers `start[r]..start[r + 1]`, and its
    // label is that of its first pixel. Counted first, so that the rows are written in
    // place, in parallel.
    let slots_in = |row: &[u32]| 2 + row.windows(2).filter(|p| p[0] != p[1]).count();
    let slots: Vec<usize> = labels.par_chunks(w).map(slots_in).collect();
    let mut first = Vec::with_capacity(h + 1);
    first.push(0usize);
    for c in &slots {
        first.push(first[first.len() - 1] + c);
    }
    let mut start = vec![0u32; first[h]];
    let mut rest: &mut [u32] = &mut start;
    let mut rows = Vec::with_capacity(h);
    for &c in &slots {
        let (row, others) = rest.split_at_mut(c);
        rows.push(row);
        rest = others;
    }
    rows.into_par_iter()
        .zip(labels.par_chunks(w))
        .for_each(|(starts, row)| {
            // Labels change every few pixels, at random, along ragged boundaries: rather than
            // a branch mispredicted that often, every column is written as the start of the
            // next run and kept only where the label changes (the last write lands on the
            // closing entry).
            let mut r = 1;
            for x in 1..row.len() {
                starts[r] = x as u32;
                r += (row[x] != row[x - 1]) as usize;
            }
            starts[0] = 0;
            starts[r] = w as u32;
        });
    let runs_of = |y: usize| first[y]..first[y + 1] - 1;
    let label = |y: usize, r: usize| labels[y * w + start[r] as usize];

    // Union-find whose root is always the smallest index of the set, so `parent[i] <= i`.
    let mut parent: Vec<u32> = (0..first[h] as u32).collect();
    fn find(parent: &mut [u32], mut i: u32) -> u32 {
        while parent[i as usize] != i {
            let p = parent[i as usize];
            parent[i as usize] = parent[p as usize];
            i = p;
        }
        i
    }
    for y in 1..h {
        let (above, here) = (runs_of(y - 1), runs_of(y));
        let (mut i, mut j) = (above.start, here.start);
        while i < above.end && j < here.end {
            let (up_end, here_end) = (start[i + 1], start[j + 1]);
            // 4-connected: the column ranges share a column.
            if start[i] < here_end && start[j] < up_end && label(y - 1, i) == label(y, j) {
                let (a, b) = (find(&mut parent, i as u32), find(&mut parent, j as u32));
                if a < b {
                    parent[b as usize] = a;
                } else {
                    parent[a as usize] = b;
                }
            }
            if up_end <= here_end {
                i += 1;
            } else {
                j += 1;
            }
        }
    }
    // Every run's piece, named by its first run: parents come first, so one pass resolves
    // them in place. Then the size of every piece, at its first run.
    let mut piece = parent;
    for r in 0..piece.len() {
        piece[r] = piece[piece[r] as usize];
    }
    let mut size_then_label = vec![0u32; first[h]];
    for y in 0..h {
        for r in runs_of(y) {
            size_then_label[piece[r] as usize] += start[r + 1] - start[r];
        }
    }

    let mut next: u32 = 0;
    for y in 0..h {
        // The runs above and below that hold the column of the current run's first pixel;
        // they only move right along the row.
        let (mut up, mut down) = (first[y.saturating_sub(1)], first[(y + 1).min(h - 1)]);
        for r in runs_of(y) {
            if piece[r] as usize != r {
                continue;
            }
            let x = start[r];
            // EPFL looks left, up, right and down from the piece's first pixel, and the last of
            // them already labelled wins. Left and up come earlier in raster order, so they
            // always are; right and down are when their piece started earlier. A piece's
            // entry holds its new label once it has been visited.
            let mut adjacent = NONE;
            let mut look = |q: usize| {
                if (piece[q] as usize) < r {
                    adjacent = size_then_label[piece[q] as usize];
                }
            };
            if x > 0 {
                look(r - 1);
            }
            if y > 0 {
                while start[up + 1] <= x {
                    up += 1;
                }
                look(up);
            }
            if (x as usize) + 1 < w && start[r + 1] == x + 1 {
                look(r + 1);
            }
            if y + 1 < h {
                while start[down + 1] <= x {
                    down += 1;
                }
                look(down);
            }
            size_then_label[r] = if size_then_label[r] as usize <= small && adjacent != NONE {
                adjacent
            } else {
                next += 1;
                next - 1
            };
        }
    }

    labels
        .par_chunks_mut(w)
        .with_min_len(16)
        .enumerate()
        .for_each(|(y, row)| {
            for r in runs_of(y) {
                let new = size_then_label[piece[r] as usize];
                for v in &mut row[start[r] as usize..start[r + 1] as usize] {
                    *v = new;
                }
            }
        });
    next as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    /// EPFL's flood fill as it was written here before the run version: the reference.
    fn flood_fill(labels: &[u32], w: usize, h: usize, mean_size: usize) -> (Vec<u32>, usize) {
        const NONE: u32 = u32::MAX;
        let n = w * h;
        let mut out = vec![NONE; n];
        let mut queue: Vec<usize> = Vec::new();
        let mut next: u32 = 0;
        let small = (mean_size / 4).max(1);
        for start in 0..n {
            if out[start] != NONE {
                continue;
            }
            let (sx, sy) = (start % w, start / w);
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
            queue.push(start);
            let mut head = 0;
            while head < queue.len() {
                let i = queue[head];
                head += 1;
                let (x, y) = (i % w, i / w);
                for (ok, j) in [
                    (x > 0, i.wrapping_sub(1)),
                    (y > 0, i.wrapping_sub(w)),
                    (x + 1 < w, i + 1),
                    (y + 1 < h, i + w),
                ] {
                    if ok && out[j] == NONE && labels[j] == old {
                        out[j] = next;
                        queue.push(j);
                    }
                }
            }
            if queue.len() <= small && adjacent != NONE {
                for &i in &queue {
                    out[i] = adjacent;
                }
            } else {
                next += 1;
            }
        }
        (out, next as usize)
    }

    #[test]
    fn small_pieces_join_a_neighbour() {
        // Label 1 is split in two; the one-pixel piece at the right joins its neighbour.
        let labels = vec![
            1, 1, 0, 1, //
            1, 1, 0, 0, //
            1, 1, 0, 0,
        ];
        let mut out = labels.clone();
        let count = enforce_connectivity(&mut out, 4, 3, 6);
        assert_eq!(count, 2);
        assert_eq!(out, vec![0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1]);
    }

    #[test]
    fn runs_give_the_flood_fill_result() {
        // Blocks (like superpixels) with a sprinkling of other labels, and pure noise, in a few
        // sizes including one row, one column and a single pixel; spirals and U shapes come
        // out of the noise, where a piece reaches round to the right of or below a later one.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut random = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for &(w, h) in &[(1, 1), (1, 9), (9, 1), (7, 5), (40, 30), (97, 61)] {
            for block in [1usize, 3, 8] {
                for noise in [0u64, 10, 100] {
                    for values in [2u64, 3, 1000] {
                        let labels: Vec<u32> = (0..w * h)
                            .map(|i| {
                                let (x, y) = (i % w, i / w);
                                let base = ((y / block) * w + x / block) as u64;
                                if random() % 100 < noise {
                                    (random() % values) as u32
                                } else {
                                    (base % values) as u32
                                }
                            })
                            .collect();
                        for mean_size in [1, 4, 16, 64] {
                            let mut runs = labels.clone();
                            let count = enforce_connectivity(&mut runs, w, h, mean_size);
                            assert_eq!(
                                (runs, count),
                                flood_fill(&labels, w, h, mean_size),
                                "{w}x{h}, block {block}, noise {noise}, {values} values, mean size {mean_size}"
                            );
                        }
                    }
                }
            }
        }
    }
}
