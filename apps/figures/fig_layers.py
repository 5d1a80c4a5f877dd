"""Coloured horizontal layers (seed 004 Figs 5.12-5.14), on request (`--type layers`): the
grains coloured by the horizontal band (10 bands, alternating colours) their centre lies in at a
reference frame (`--frame`, default the first), front view (x, z) at the reference frame and at
three later frames evenly spaced to the last. Grains that the reference frame does not hold are
grey. One PNG, `<run>_layers_<reference>.png`.
"""
import os

import h5py
import numpy as np
from matplotlib.collections import EllipseCollection

import figutil
from figutil import plt
from fig_positions import load_frame

BANDS = 10


def _ids(path, i):
    with h5py.File(path, "r", swmr=True) as f:
        end = f["frames/end"][:]
        b = 0 if i == 0 else int(end[i - 1][0])
        return f["particles/id"][b:int(end[i][0])]


def reference_frame(path, args):
    """(frames in the trajectory, the reference frame: --frame, default the first)."""
    with h5py.File(path, "r", swmr=True) as f:
        n = len(f["frames/end"])
    if n == 0:
        raise ValueError("trajectory holds no frame")
    ref = args.frame if args.frame >= 0 else 0
    if ref >= n:
        raise ValueError(f"no such frame ({ref} of {n})")
    return n, ref


def make(path, out_dir, args):
    n, ref = reference_frame(path, args)
    _, t0, pos0, _ = load_frame(path, ref)
    if len(pos0) == 0:
        raise ValueError(f"frame {ref} has no particles")
    z0 = pos0[:, 2]
    lo, hi = z0.min(), z0.max()
    edges = np.linspace(lo, hi, BANDS + 1)
    band = {int(k): int(min(BANDS - 1, np.searchsorted(edges, z, side="right") - 1))
            for k, z in zip(_ids(path, ref), z0)}
    frames = sorted(set([ref] + [int(round(ref + (n - 1 - ref) * s)) for s in (1 / 3, 2 / 3, 1)]))
    fig, axes = plt.subplots(1, len(frames), figsize=(4 * len(frames), 6), squeeze=False)
    colours = np.array([[0.85, 0.35, 0.1], [0.15, 0.35, 0.75]])
    for ax, k in zip(axes[0], frames):
        i, t, pos, rad = load_frame(path, k)
        ids = _ids(path, i)
        b = np.array([band.get(int(j), -1) for j in ids])
        rgb = np.where(b[:, None] >= 0, colours[np.maximum(b, 0) % 2], 0.7)
        coll = EllipseCollection(2 * rad, 2 * rad, np.zeros(len(rad)), units="xy",
                                 offsets=pos[:, [0, 2]], transOffset=ax.transData,
                                 facecolors=rgb, edgecolors="none")
        ax.add_collection(coll)
        if len(rad):
            a = (pos[:, [0, 2]] - rad[:, None]).min(axis=0)
            c = (pos[:, [0, 2]] + rad[:, None]).max(axis=0)
            ax.set_xlim(a[0], c[0])
            ax.set_ylim(min(a[1], lo), max(c[1], hi))
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_title("layers: frame %d, t = %.4g s" % (i, t))
    axes[0][0].set_ylabel("z (m)")
    fig.suptitle("layers of frame %d (t = %.4g s), %d bands" % (ref, t0, BANDS))
    stem = os.path.splitext(os.path.basename(path))[0]
    return [figutil.save(fig, out_dir, f"{stem}_layers_{ref:06d}.png")]
