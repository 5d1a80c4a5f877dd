"""Figures for `granoscope analyze rose` (format granoscope-rose) and `analyze fabric`
(format granoscope-fabric).

rose: polar diagrams of the contact-normal density and of the mean normal and tangential
contact force per direction (seed 004 Figs 4.11c, 4.24, 5.27), and with --3d the density on
the equal-area bins in a Hammer projection.
fabric: the Kanatani density E(n) = (1 + D_ij n_i n_j) / (4 pi) (seed 003 eq 18) in the view
plane and in the three coordinate planes, and the clump orientation fabric when present.
"""
import h5py
import numpy as np

import figutil
from figutil import plt


def make(input_path, out_dir, args):
    with h5py.File(input_path, "r") as f:
        if figutil.attr(f, "format", "") == "granoscope-fabric":
            return _fabric(f, out_dir)
        return _rose(f, out_dir)


def _closed(a, r):
    return np.append(a, a[0] + 2 * np.pi), np.append(r, r[0])


def _rose(f, out_dir):
    g = f["rose2d"]
    ang = np.radians(g["angle_deg"][()])
    width = np.radians(float(g.attrs["bin_deg"]))
    panels = (("density", "contact normals (1/rad)", "0.4"),
              ("mean_fn", "mean normal force (N)", "tab:red"),
              ("mean_fs", "mean tangential force (N)", "tab:blue"))
    fig, axes = plt.subplots(1, 3, figsize=(14, 5), subplot_kw=dict(projection="polar"))
    for ax, (name, title, color) in zip(axes, panels):
        r = np.nan_to_num(g[name][()])
        ax.bar(ang, r, width=width, bottom=0.0, color=color, alpha=0.6, edgecolor="k",
               linewidth=0.3)
        ax.plot(*_closed(ang, r), color="k", lw=0.8)
        ax.set_title(title, pad=15)
    fig.suptitle("%d contacts, %g deg bins; angle from the plane's first axis"
                 % (int(g.attrs["contacts"]), float(g.attrs["bin_deg"])))
    written = [figutil.save(fig, out_dir, "rose.png")]
    if "rose3d" in f:
        r3 = f["rose3d"]
        d = r3["direction"][()]
        lon = np.arctan2(d[:, 1], d[:, 0])
        lat = np.arcsin(np.clip(d[:, 2], -1, 1))
        fig = plt.figure(figsize=(9, 5))
        ax = fig.add_subplot(111, projection="hammer")
        sc = ax.scatter(lon, lat, c=r3["density"][()], s=25, cmap="viridis")
        ax.grid(True)
        ax.set_title("contact-normal density (1/sr) on %d x %d equal-area bins"
                     % (int(r3.attrs["n_theta"]), int(r3.attrs["n_phi"])))
        fig.colorbar(sc, ax=ax, shrink=0.7)
        written.append(figutil.save(fig, out_dir, "rose_3d.png"))
    return written


def _fabric(f, out_dir):
    D = f["D"][()]
    dim = int(f.attrs["dim"])
    view = f["view_axes"][()]
    planes = [("view plane", view[0], view[1])]
    if dim == 3:
        e = np.eye(3)
        planes += [("x-y", e[0], e[1]), ("x-z", e[0], e[2]), ("y-z", e[1], e[2])]
    th = np.linspace(0, 2 * np.pi, 361)
    fig, axes = plt.subplots(1, len(planes), figsize=(4.5 * len(planes), 4.5),
                             subplot_kw=dict(projection="polar"))
    axes = np.atleast_1d(axes)
    norm = 4 * np.pi if dim == 3 else 2 * np.pi
    for ax, (name, a, b) in zip(axes, planes):
        n = np.outer(np.cos(th), a) + np.outer(np.sin(th), b)
        e = (1 + np.einsum("ki,ij,kj->k", n, D, n)) / norm
        ax.plot(th, e, "k")
        ax.plot(th, np.full_like(th, 1 / norm), ":", color="0.5")
        if "orientation" in f and int(f["orientation"].attrs["bodies"]) > 0:
            Do = f["orientation/D"][()]
            ax.plot(th, (1 + np.einsum("ki,ij,kj->k", n, Do, n)) / norm, "tab:orange")
        ax.set_title(name, pad=12)
    fig.suptitle("Kanatani E(n) (black; dotted: isotropic; orange: clump axes): omega = %.3f, "
                 "|D| = %.3f" % (float(f.attrs["omega"]), float(f.attrs["D_norm"])))
    return [figutil.save(fig, out_dir, "fabric.png")]
