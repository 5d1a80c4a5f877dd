"""Rotation map (seed 004 Figs 4.16, 4.47-4.50; the silo's rotations of §5.3), on request
(`--type rotation`): every grain coloured by its rotation about the +y axis (the out-of-plane
axis of the front view) since a reference frame (`--frame`, default the first), in rad, at three
frames evenly spaced from the reference to the last. Positive is clockwise in this view (x to the
right, z up, looking along +y), drawn red as in the thesis; counterclockwise blue. Grains the
reference frame does not hold are grey. The colour scale is symmetric, ±the |rotation| of the grains
drawn at the 98th percentile (a few free rattlers spin far more than the grains of a shear zone:
they saturate). One PNG, `<run>_rotation_<reference>.png`.
"""
import os

import h5py
import numpy as np
from matplotlib.collections import EllipseCollection

import figutil
from figutil import plt
from fig_layers import reference_frame
from fig_positions import load_frame


def _ids_rotation(path, i):
    with h5py.File(path, "r", swmr=True) as f:
        if "particles/rotation" not in f:
            raise ValueError("trajectory has no particles/rotation")
        end = f["frames/end"][:]
        b = 0 if i == 0 else int(end[i - 1][0])
        e = int(end[i][0])
        return f["particles/id"][b:e], f["particles/rotation"][b:e, 1]


def make(path, out_dir, args):
    n, ref = reference_frame(path, args)
    t0 = load_frame(path, ref)[1]
    ids0, rot0 = _ids_rotation(path, ref)
    start = {int(k): float(r) for k, r in zip(ids0, rot0)}
    frames = sorted(set([int(round(ref + (n - 1 - ref) * s)) for s in (1 / 3, 2 / 3, 1)]))
    panels = []
    for k in frames:
        i, t, pos, rad = load_frame(path, k)
        ids, rot = _ids_rotation(path, i)
        w = np.array([r - start[int(j)] if int(j) in start else np.nan
                      for j, r in zip(ids, rot)])
        panels.append((i, t, pos, rad, w))
    drawn = np.concatenate([np.abs(p[4][np.isfinite(p[4])]) for p in panels])
    top = float(np.percentile(drawn, 98)) if drawn.size else 0.0
    top = top if top > 0 else 1.0
    fig, axes = plt.subplots(1, len(panels), figsize=(4 * len(panels) + 1, 6), squeeze=False)
    cmap = plt.get_cmap("coolwarm").copy()
    cmap.set_bad((0.7, 0.7, 0.7))
    coll = None
    for ax, (i, t, pos, rad, w) in zip(axes[0], panels):
        coll = EllipseCollection(2 * rad, 2 * rad, np.zeros(len(rad)), units="xy",
                                 offsets=pos[:, [0, 2]], transOffset=ax.transData,
                                 cmap=cmap, edgecolors="none")
        coll.set_array(np.ma.masked_invalid(w))
        coll.set_clim(-top, top)
        ax.add_collection(coll)
        if len(rad):
            a = (pos[:, [0, 2]] - rad[:, None]).min(axis=0)
            c = (pos[:, [0, 2]] + rad[:, None]).max(axis=0)
            ax.set_xlim(a[0], c[0])
            ax.set_ylim(a[1], c[1])
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_title("rotation: frame %d, t = %.4g s" % (i, t))
    axes[0][0].set_ylabel("z (m)")
    fig.colorbar(coll, ax=axes[0].tolist(),
                 label="rotation about +y since the reference (rad; + clockwise here)")
    fig.suptitle("grain rotations since frame %d (t = %.4g s)" % (ref, t0))
    stem = os.path.splitext(os.path.basename(path))[0]
    return [figutil.save(fig, out_dir, f"{stem}_rotation_{ref:06d}.png")]
