"""Figures for `granoscope analyze rev` (format granoscope-rev) and `analyze shearzone`
(format granoscope-shearzone).

rev: maps of REV / coarse-grained fields (seed 000 Figs 4-5, seed 004 Figs 4.16-4.17): on a slab
or 2D grid the whole map, on a 3D grid the section through the middle of the y axis (front view
x-z). `--field NAME` picks one field: a scalar (void_ratio, rotation_normal, p, ...), a vector or
tensor component (displacement_x, stress_zz) or a vector's magnitude (displacement); default:
a few standard ones.
shearzone: the map with the ridge points and the fitted band line, and the profile across the
band with the inflection points that bound it (seed 004 §4.2.3).
"""
import h5py
import numpy as np

import figutil
from figutil import plt

AXES = "xyz"


def make(input_path, out_dir, args):
    with h5py.File(input_path, "r") as f:
        if figutil.attr(f, "format", "") == "granoscope-shearzone":
            return _shearzone(f, out_dir)
        return _rev(f, out_dir, getattr(args, "field", None))


def _field(cells, name):
    """Values of a named field: scalar, vector/tensor component (_x, _zz) or vector magnitude."""
    if name in cells:
        v = cells[name][()]
        if v.ndim == 1:
            return v
        if v.ndim == 2:
            return np.linalg.norm(v, axis=1)
        raise KeyError("field %s is a tensor: give a component, e.g. %s_zz" % (name, name))
    base, _, comp = name.rpartition("_")
    if base in cells and comp and all(c in AXES for c in comp):
        v = cells[base][()]
        if v.ndim == 2 and len(comp) == 1:
            return v[:, AXES.index(comp)]
        if v.ndim == 3 and len(comp) == 2:
            return v[:, AXES.index(comp[0]), AXES.index(comp[1])]
    raise KeyError("no field %s (available: %s)" % (name, ", ".join(sorted(cells.keys()))))


def _section(f, values):
    """2D array (rows: second map axis) and its extent for the map or the mid-y section."""
    dims = f["grid/dims"][()]
    nx, ny, nz = (int(d) for d in dims)
    local = f["cells/local"][()]
    v = values.reshape(nz, ny, nx)
    mode = figutil.attr(f, "mode", "3d")
    if mode in ("slab", "2d"):
        img = v[0]
        u, w = local[:, 0].reshape(nz, ny, nx)[0], local[:, 1].reshape(nz, ny, nx)[0]
        labels = ("map x (m)", "map y (m)") if mode == "slab" else ("x (m)", "y (m)")
    else:
        j = ny // 2
        img = v[:, j, :]
        u, w = local[:, 0].reshape(nz, ny, nx)[:, j, :], local[:, 2].reshape(nz, ny, nx)[:, j, :]
        labels = ("x (m)", "z (m) (section at the middle of y)")
    step = float(f["grid"].attrs["step"])
    extent = (u.min() - step / 2, u.max() + step / 2, w.min() - step / 2, w.max() + step / 2)
    return img, extent, labels


def _rev(f, out_dir, field):
    cells = f["cells"]
    method = figutil.attr(f, "method", "box")
    if field:
        names = [field]
    elif method == "gaussian":
        names = ["density", "void_ratio", "p"]
    else:
        names = ["void_ratio", "rotation_normal" if "rotation_normal" in cells else "rotation",
                 "p", "coordination"]
        if "displacement" in cells:
            names.append("displacement")
    written = []
    for name in names:
        vals = _field(cells, name)
        img, extent, labels = _section(f, vals)
        fig, ax = plt.subplots(figsize=(6, 6))
        finite = img[np.isfinite(img)]
        if name.startswith("rotation") and finite.size:
            lim = float(np.nanpercentile(np.abs(finite), 99)) or 1.0
            kw = dict(cmap="RdBu_r", vmin=-lim if np.nanmin(finite) < 0 else 0, vmax=lim)
        else:
            kw = dict(cmap="viridis")
            if finite.size:
                kw.update(vmin=float(np.nanpercentile(finite, 1)),
                          vmax=float(np.nanpercentile(finite, 99)))
                if kw["vmin"] == kw["vmax"]:
                    kw["vmax"] = kw["vmin"] + (abs(kw["vmin"]) or 1.0) * 1e-9
        im = ax.imshow(img, origin="lower", extent=extent, interpolation="nearest", **kw)
        ax.set_xlabel(labels[0])
        ax.set_ylabel(labels[1])
        title = "%s (%s, L = %.3g m, s = %.3g m)" % (name, method, float(f.attrs["cell"]),
                                                   float(f.attrs["step"]))
        if method == "gaussian":
            title = "%s (gaussian, w = %.3g m)" % (name, float(f.attrs["width"]))
        ax.set_title(title)
        fig.colorbar(im, ax=ax, shrink=0.8)
        written.append(figutil.save(fig, out_dir, "rev_%s.png" % name))
    return written


def _shearzone(f, out_dir):
    val = f["map/value"][()]
    u0, v0, step = (float(f["map"].attrs[k]) for k in ("u0", "v0", "step"))
    nv, nu = val.shape
    extent = (u0 - step / 2, u0 + (nu - 0.5) * step, v0 - step / 2, v0 + (nv - 0.5) * step)
    ridge = f["ridge/points"][()]
    inl = f["ridge/inlier"][()].astype(bool) if ridge.size else np.zeros(0, bool)
    p, d = f["line/point"][()], f["line/direction"][()]
    fig, axes = plt.subplots(1, 2, figsize=(11, 6), gridspec_kw=dict(width_ratios=[1, 1.2]))
    ax = axes[0]
    im = ax.imshow(val, origin="lower", extent=extent, cmap="magma", interpolation="nearest")
    if ridge.size:
        ax.plot(ridge[inl, 0], ridge[inl, 1], "c.", ms=4, label="ridge (used)")
        ax.plot(ridge[~inl, 0], ridge[~inl, 1], "x", color="0.6", ms=4, label="ridge (outlier)")
    t = np.linspace(-2, 2, 3) * np.hypot(extent[1] - extent[0], extent[3] - extent[2])
    ax.plot(p[0] + t * d[0], p[1] + t * d[1], "w--", lw=1.5, label="band axis")
    n = np.array([-d[1], d[0]])
    for key in ("lower_m", "upper_m"):
        off = float(f.attrs[key])
        if np.isfinite(off):
            ax.plot(p[0] + off * n[0] + t * d[0], p[1] + off * n[1] + t * d[1], "w:", lw=1)
    ax.set_xlim(extent[0], extent[1])
    ax.set_ylim(extent[2], extent[3])
    ax.set_xlabel("map x (m)")
    ax.set_ylabel("map y (m)")
    ax.set_title("%s map; inclination %.1f deg" % (figutil.attr(f, "field", ""),
                                                  float(f.attrs["inclination_deg"])))
    ax.legend(loc="lower right", fontsize=7)
    fig.colorbar(im, ax=ax, shrink=0.7)
    ax = axes[1]
    dist, prof = f["profile/distance"][()], f["profile/value"][()]
    d50 = float(f.attrs["d50"])
    ax.plot(dist / d50, prof, "k.-")
    for key in ("lower_m", "upper_m"):
        off = float(f.attrs[key])
        if np.isfinite(off):
            ax.axvline(off / d50, color="r", ls="--")
    ax.set_xlabel("distance across the band (d50)")
    ax.set_ylabel("mean %s along the band" % figutil.attr(f, "field", ""))
    ax.set_title("thickness %.2f mm = %.2f d50 (inflection points)"
                 % (float(f.attrs["thickness_mm"]), float(f.attrs["thickness_d50"])))
    return [figutil.save(fig, out_dir, "shearzone.png")]
