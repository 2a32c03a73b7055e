#!/usr/bin/env python3
"""scikit-image's SLIC on an image, for the cross-check and the benchmark of streaklight's SLIC.

    slic_reference.py label IMAGE K COMPACTNESS OUT.png [COUNT]
        write the label map (16-bit PNG); with COUNT, choose n_segments so that the map has
        the fewest labels not below COUNT (at most 10 % more): scikit-image gives fewer labels
        than K on noisy images, quality measures compare fairly only at equal counts, and
        its count moves in jumps; giving it a few more labels than ours favours it.
    slic_reference.py time  IMAGE K COMPACTNESS REPEATS   print the median time in ms

Settings as streaklight's: n_segments=K, the given compactness, 10 iterations, no smoothing
(sigma=0), CIELAB, connectivity enforced, labels from 0. Needs: scikit-image numpy.
"""
import sys
import time

try:
    import numpy as np
    import imageio.v3 as iio
    from skimage.segmentation import slic
except ImportError as e:  # pragma: no cover
    sys.exit(f"slic_reference.py needs scikit-image and numpy (pip install scikit-image numpy): {e}")


def run(image, k, compactness):
    return slic(image, n_segments=k, compactness=compactness, max_num_iter=10, sigma=0,
                convert2lab=True, enforce_connectivity=True, start_label=0, channel_axis=-1)


def main():
    if len(sys.argv) not in (6, 7) or sys.argv[1] not in ("label", "time"):
        sys.exit(__doc__)
    mode, path, k, compactness = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4])
    image = iio.imread(path)[..., :3]
    if mode == "label":
        labels = run(image, k, compactness)
        if len(sys.argv) == 7:
            # scikit-image's count moves in jumps with n_segments (its grid): try the
            # proportional guess, then nearby values, and keep the closest count.
            target = int(sys.argv[6])
            found = {}
            guess = k
            for _ in range(6):
                guess = max(1, round(guess * target / (labels.max() + 1)))
                labels = run(image, guess, compactness)
                found[guess] = labels
            centre = min(found, key=lambda g: abs(found[g].max() + 1 - target))
            for cand in range(max(1, centre - 30), centre + 31, 2):
                found[cand] = run(image, cand, compactness)
            above = [g for g in found if found[g].max() + 1 >= target]
            if not above:
                sys.exit(f"no n_segments gave at least {target} labels")
            k = min(above, key=lambda g: found[g].max())
            labels = found[k]
            if labels.max() + 1 > 1.1 * target:
                sys.exit(f"could not come within 10 % above {target} labels (best: {labels.max() + 1})")
            print(f"n_segments={k} gives {labels.max() + 1} labels", file=sys.stderr)
        if labels.max() >= 65536:
            sys.exit("too many labels for a 16-bit PNG")
        iio.imwrite(sys.argv[5], labels.astype(np.uint16))
    else:
        repeats = int(sys.argv[5])
        run(image, k, compactness)  # warm-up
        times = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            run(image, k, compactness)
            times.append((time.perf_counter() - t0) * 1000.0)
        times.sort()
        print(f"{times[len(times) // 2]:.1f}")


if __name__ == "__main__":
    main()
