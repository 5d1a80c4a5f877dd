"""Figures for `granoscope analyze strain` (format granoscope-strain) and `analyze voidcells`
(format granoscope-voidcells).

strain: maps of the per-particle volumetric and equivalent shear strain (2D, or a 3D section
projected on x-y), and their histograms.
voidcells: maps of the alignment alpha (seed 002 eq 18, Fig. 8) and of the normalised vorticity
w (eq 20, Fig. 9: grey scale accentuating direction) on the void-cell polygons, and the
relative-velocity arrows of eq 21 (Fig. 10).
"""
import h5py
import numpy as np
from matplotlib.collections import PolyCollection

import figutil
from figutil import plt


def make(input_path, out_dir, args):
    with h5py.File(input_path, "r") as f:
        fmt = figutil.attr(f, "format", "")
        if fmt == "granoscope-voidcells":
            return _voidcells(f, out_dir)
        if fmt == "granoscope-strain":
            return _strain(f, out_dir)
    raise ValueError("not a strain or voidcells file (format %s)" % fmt)


def _shape(f, name, *shape):
    """Dataset `name` with the given shape (None: any length); a ValueError otherwise, so a
    malformed file is one error line rather than a traceback from numpy or matplotlib."""
    if name not in f:
        raise KeyError("%s missing" % name)
    d = f[name]
    if len(d.shape) != len(shape) or any(w is not None and w != n for w, n in zip(shape, d.shape)):
        raise ValueError("dataset %s has shape %s, expected %s"
                         % (name, d.shape, tuple("N" if w is None else w for w in shape)))
    return d[()]


def _strain(f, out_dir):
    pos = _shape(f, "particles/position", None, 3)
    n = len(pos)
    for name in ("particles/valid", "particles/volumetric_strain",
                 "particles/equivalent_shear_strain"):
        _shape(f, name, n)
    if "simplices/alpha" in f:  # checked before any figure is written
        tri = _shape(f, "simplices/vertices", None, 3)
        if tri.size and (tri.min() < 0 or tri.max() >= n):
            raise ValueError("simplices/vertices index a particle out of range")
        for name in ("simplices/sliver", "simplices/alpha", "simplices/w"):
            _shape(f, name, len(tri))
    valid = f["particles/valid"][()].astype(bool)
    vol = f["particles/volumetric_strain"][()]
    shear = f["particles/equivalent_shear_strain"][()]
    written = []
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for ax, val, name, cmap in ((axes[0], vol, "volumetric strain", "RdBu_r"),
                                (axes[1], shear, "equivalent shear strain", "viridis")):
        v = val[valid]
        lim = np.nanpercentile(np.abs(v), 98) if v.size else 1.0
        lim = lim if lim > 0 else 1.0
        kw = dict(vmin=-lim, vmax=lim) if cmap == "RdBu_r" else dict(vmin=0, vmax=lim)
        sc = ax.scatter(pos[valid, 0], pos[valid, 1], c=v, s=4, cmap=cmap, **kw)
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.set_title(name)
        fig.colorbar(sc, ax=ax, shrink=0.8)
    written.append(figutil.save(fig, out_dir, "strain_maps.png"))
    if "simplices/alpha" in f:  # 2D: triangle (Bagi eq 4) variant of Figs 8-9
        tri = f["simplices/vertices"][()]
        sliver = f["simplices/sliver"][()].astype(bool)
        polys = [pos[t, :2] for t in tri[~sliver]]
        written += _alpha_w_maps(polys, f["simplices/alpha"][()][~sliver],
                                 f["simplices/w"][()][~sliver], out_dir, "strain_triangles")
    fig, ax = plt.subplots(figsize=(5, 4))
    ax.hist(shear[valid], bins=60, color="0.3")
    ax.set_xlabel("equivalent shear strain")
    ax.set_ylabel("particles")
    written.append(figutil.save(fig, out_dir, "strain_shear_histogram.png"))
    return written


def _polygons(f):
    off = _shape(f, "cells/offsets", None)
    poly = _shape(f, "cells/polygon", None, 2)
    if len(off) < 1 or off[0] != 0 or off[-1] != len(poly) or (off[1:] < off[:-1]).any():
        raise ValueError("cells/offsets do not partition cells/polygon")
    return [poly[off[i]:off[i + 1]] for i in range(len(off) - 1)]


def _voidcells(f, out_dir):
    polys = _polygons(f)
    for name in ("cells/alpha", "cells/w"):
        _shape(f, name, len(polys))
    n = len(_shape(f, "particles/position", None, 2))
    _shape(f, "particles/active", n)
    _shape(f, "particles/relative_velocity", n, 2)
    alpha = f["cells/alpha"][()]
    w = f["cells/w"][()]
    pos = f["particles/position"][()]
    active = f["particles/active"][()].astype(bool)
    vrel = f["particles/relative_velocity"][()]
    written = _alpha_w_maps(polys, alpha, w, out_dir, "voidcells")

    # Fig. 10: relative velocities (eq 21).
    fig, ax = plt.subplots(figsize=(6, 6))
    ax.add_collection(PolyCollection(polys, facecolors="none", edgecolors="0.8", linewidths=0.2))
    ax.quiver(pos[active, 0], pos[active, 1], vrel[active, 0], vrel[active, 1], angles="xy",
              width=0.002)
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_title("relative velocity (eq 21)")
    written.append(figutil.save(fig, out_dir, "voidcells_relative_velocity.png"))
    return written


def _alpha_w_maps(polys, alpha, w, out_dir, prefix):
    written = []
    # Fig. 8: alignment alpha, white for alpha <= 0.
    fig, ax = plt.subplots(figsize=(6, 6))
    pc = PolyCollection(polys, array=np.clip(alpha, 0, 1), cmap="Greys", edgecolors="0.6",
                        linewidths=0.2)
    pc.set_clim(0, 1)
    ax.add_collection(pc)
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_title("alignment alpha (eq 18); mean %.2f, %.0f%% <= 0"
                 % (float(np.mean(alpha)) if alpha.size else 0.0,
                    100.0 * float(np.mean(alpha <= 0)) if alpha.size else 0.0))
    fig.colorbar(pc, ax=ax, shrink=0.8)
    written.append(figutil.save(fig, out_dir, prefix + "_alpha.png"))

    # Fig. 9: vorticity w, grey scale that accentuates direction and de-emphasises magnitude.
    fig, ax = plt.subplots(figsize=(6, 6))
    scale = float(np.median(np.abs(w))) if w.size else 1.0
    shade = np.tanh(w / scale) if scale > 0 else np.zeros_like(w)
    pc = PolyCollection(polys, array=shade, cmap="gray", edgecolors="0.6", linewidths=0.2)
    pc.set_clim(-1, 1)
    ax.add_collection(pc)
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_title("vorticity w (eq 20): tanh(w / median|w|); black clockwise")
    fig.colorbar(pc, ax=ax, shrink=0.8)
    written.append(figutil.save(fig, out_dir, prefix + "_w.png"))
    return written
