"""Particle positions coloured by radius, front view (x horizontal, z up, looking along +y)."""
import os

import h5py
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import EllipseCollection

import figutil


def load_frame(path, frame):
    with h5py.File(path, "r", swmr=True) as f:
        end = f["frames/end"][:]
        if end.ndim != 2 or end.shape[1] != 3:
            raise ValueError(f"frames/end has shape {end.shape}, expected (frames, 3)")
        n = len(end)
        if n == 0:
            raise ValueError("trajectory holds no frame")
        i = frame if frame >= 0 else n + frame
        if not 0 <= i < n:
            raise ValueError(f"no such frame ({frame} of {n})")
        b = 0 if i == 0 else int(end[i - 1][0])
        e = int(end[i][0])
        pos = f["particles/position"][b:e]
        rad = f["particles/radius"][b:e]
        if not 0 <= b <= e or pos.shape != (e - b, 3) or rad.shape != (e - b,):
            raise ValueError(f"frame {i}: particle rows {b}..{e} do not match "
                             f"particles/position {f['particles/position'].shape} "
                             f"and particles/radius {f['particles/radius'].shape}")
        if len(f["frames/time"]) <= i:
            raise ValueError(f"frames/time is shorter than frames/end ({len(f['frames/time'])})")
        t = float(f["frames/time"][i])
    return i, t, pos, rad


def make(path, out_dir, args):
    i, t, pos, rad = load_frame(path, args.frame)
    if len(rad) == 0:
        raise ValueError(f"frame {i} has no particles")
    order = np.argsort(-pos[:, 1])  # far particles first, near ones drawn on top
    fig, ax = plt.subplots(figsize=(6, 6))
    coll = EllipseCollection(2 * rad[order], 2 * rad[order], np.zeros(len(order)), units="xy",
                             offsets=pos[order][:, [0, 2]], transOffset=ax.transData,
                             cmap="viridis", edgecolors="k", linewidths=0.2)
    coll.set_array(rad[order] * 1e3)
    ax.add_collection(coll)
    lo = (pos[:, [0, 2]] - rad[:, None]).min(axis=0)
    hi = (pos[:, [0, 2]] + rad[:, None]).max(axis=0)
    pad = 0.02 * (hi - lo).max()
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    ax.set_title(f"frame {i}, t = {t:.6g} s, {len(rad)} particles (front view)")
    fig.colorbar(coll, ax=ax, label="radius (mm)", shrink=0.8)
    stem = os.path.splitext(os.path.basename(path))[0]
    return [figutil.save(fig, out_dir, f"{stem}_positions_front_{i:06d}.png")]
