"""Figures for `granoscope analyze hhd` (format granoscope-hhd), after seed 000 Figs 7-11.

2D (a frame, a projected slab or a 2D CSV): the four fields xi, grad u, curl v and h side by side,
each drawn with a line-integral-convolution texture (Cabral & Leedom 1993, seed 000 ref 45)
coloured by the field's magnitude; vortex centres on the curl v panel and sources/sinks on the
grad u panel as circles whose diameter grows with the extremum's magnitude (green: right-handed
vortices / sources, red: left-handed vortices / sinks, as in Figs 8-9). Ghost nodes are not drawn.
3D: the vortex tubes (line width growing with |v| of the Coulomb potential they follow) and the
vortex centres (Fig. 11). Only the significant extrema (/extrema/significant, `--significance`)
and their tubes are drawn; the HDF5 file and the CSV keep every one.
"""
import h5py
import numpy as np
from matplotlib.tri import Triangulation

import figutil
from figutil import plt

RIGHT, LEFT, SOURCE, SINK = 0, 1, 2, 3


def make(input_path, out_dir, args):
    with h5py.File(input_path, "r") as f:
        if figutil.attr(f, "format", "") != "granoscope-hhd":
            raise ValueError("not an HHD file (format %s)" % figutil.attr(f, "format", ""))
        for name in ("nodes/position", "simplices/vertices", "simplices/xi", "extrema/kind"):
            if name not in f:
                raise KeyError("%s missing" % name)
        dim = int(figutil.attr(f, "dim", 3))
        data = {k: f[k][()] for k in ("nodes/position", "nodes/ghost", "nodes/v",
                                      "simplices/vertices", "simplices/xi", "simplices/grad_u",
                                      "simplices/curl_v", "simplices/harmonic", "extrema/node",
                                      "extrema/kind", "extrema/magnitude", "tubes/offsets",
                                      "tubes/nodes", "tubes/extremum")}
        # Files from before the significance threshold: every extremum counts.
        data["nodes/v_coulomb"] = f["nodes/v_coulomb"][()] if "nodes/v_coulomb" in f \
            else data["nodes/v"]
        data["extrema/significant"] = f["extrema/significant"][()].astype(bool) \
            if "extrema/significant" in f else np.ones(len(data["extrema/kind"]), bool)
    if dim == 2:
        return [_four_fields(data, out_dir)]
    return [_tubes_3d(data, out_dir)]


# ---- line integral convolution ------------------------------------------------------------

def lic(vx, vy, length=20, seed=0):
    """LIC of the grid field (vx, vy) (rows = y): a white-noise texture averaged along the
    streamline through each pixel, `length` unit steps forward and backward (nearest-pixel
    sampling, normalised direction). Pixels with a zero vector keep their noise."""
    ny, nx = vx.shape
    noise = np.random.default_rng(seed).random((ny, nx))
    mag = np.hypot(vx, vy)
    with np.errstate(invalid="ignore", divide="ignore"):
        ux = np.where(mag > 0, vx / mag, 0.0)
        uy = np.where(mag > 0, vy / mag, 0.0)
    acc = noise.copy()
    cnt = np.ones_like(noise)
    iy0, ix0 = np.mgrid[0:ny, 0:nx].astype(float)
    for sign in (1.0, -1.0):
        x, y = ix0 + 0.5, iy0 + 0.5
        alive = np.ones((ny, nx), bool)
        for _ in range(length):
            i = np.clip(y.astype(int), 0, ny - 1)
            j = np.clip(x.astype(int), 0, nx - 1)
            x = x + sign * ux[i, j]
            y = y + sign * uy[i, j]
            alive &= (x >= 0) & (x < nx) & (y >= 0) & (y < ny)
            i = np.clip(y.astype(int), 0, ny - 1)
            j = np.clip(x.astype(int), 0, nx - 1)
            acc += np.where(alive, noise[i, j], 0.0)
            cnt += alive
    return acc / cnt


def _grid_fields(pos, tri, fields, region, npx=320):
    """Samples per-triangle constant fields on a pixel grid over `region` (x0, x1, y0, y1);
    pixels outside the mesh are NaN."""
    x0, x1, y0, y1 = region
    w, h = x1 - x0, y1 - y0
    nx = npx if w >= h else max(8, int(npx * w / h))
    ny = npx if h > w else max(8, int(npx * h / w))
    gx = x0 + (np.arange(nx) + 0.5) * w / nx
    gy = y0 + (np.arange(ny) + 0.5) * h / ny
    X, Y = np.meshgrid(gx, gy)
    t = Triangulation(pos[:, 0], pos[:, 1], tri)
    which = t.get_trifinder()(X, Y)
    out = []
    for f in fields:
        g = np.full((ny, nx, 2), np.nan)
        ok = which >= 0
        g[ok] = f[which[ok], :2]
        out.append(g)
    return out, (nx, ny)


def _four_fields(d, out_dir):
    pos = d["nodes/position"]
    ghost = d["nodes/ghost"].astype(bool)
    tri = d["simplices/vertices"]
    true = pos[~ghost]
    region = (true[:, 0].min(), true[:, 0].max(), true[:, 1].min(), true[:, 1].max())
    names = [("simplices/xi", "displacement field xi (Fig. 7)"),
             ("simplices/grad_u", "curl-free part grad u (Fig. 9)"),
             ("simplices/curl_v", "divergence-free part curl v (Fig. 8)"),
             ("simplices/harmonic", "harmonic part h (Fig. 10)")]
    grids, _ = _grid_fields(pos, tri, [d[n] for n, _ in names], region)
    fig, axes = plt.subplots(1, 4, figsize=(18, 5.2))
    sig = d["extrema/significant"]  # only the significant extrema are drawn
    kind = d["extrema/kind"][sig]
    node = d["extrema/node"][sig]
    mag = d["extrema/magnitude"][sig]
    for ax, g, (_, title), k in zip(axes, grids, names, range(4)):
        vx, vy = np.nan_to_num(g[..., 0]), np.nan_to_num(g[..., 1])
        m = np.hypot(vx, vy)
        outside = np.isnan(g[..., 0])
        tex = lic(vx, vy)
        tex = np.clip(0.5 + (tex - tex.mean()) / (4.0 * tex.std() + 1e-300), 0.0, 1.0)
        top = np.nanpercentile(m[~outside], 99) if (~outside).any() else 1.0
        top = top if top > 0 else 1.0
        rgb = plt.get_cmap("viridis")(np.clip(m / top, 0, 1))[..., :3]
        rgb = rgb * (0.25 + 0.75 * tex[..., None])
        rgb[outside] = 1.0
        ax.imshow(rgb, origin="lower", extent=region, interpolation="nearest")
        sm = plt.cm.ScalarMappable(cmap="viridis", norm=plt.Normalize(0, top))
        fig.colorbar(sm, ax=ax, shrink=0.7, label="magnitude")
        pairs = {1: (SOURCE, SINK), 2: (RIGHT, LEFT)}.get(k)
        if pairs:
            sel = np.isin(kind, pairs)
            mmax = mag[sel].max() if sel.any() and mag[sel].max() > 0 else 1.0
            for kk, colour in zip(pairs, ("limegreen", "red")):
                s = kind == kk
                p = pos[node[s]]
                ax.scatter(p[:, 0], p[:, 1], s=10 + 250 * (mag[s] / mmax) ** 2,
                           facecolors="none", edgecolors=colour, linewidths=1.2)
        ax.set_title(title, fontsize=10)
        ax.set_xlim(region[0], region[1])
        ax.set_ylim(region[2], region[3])
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
    axes[0].set_ylabel("y (m)")
    fig.suptitle("HHD: circles green = right-handed vortex / source, red = left-handed vortex / "
                 "sink, diameter ~ magnitude", fontsize=10, y=0.9)
    return figutil.save(fig, out_dir, "hhd_fields.png")


def _tubes_3d(d, out_dir):
    pos = d["nodes/position"]
    v = d["nodes/v_coulomb"]  # the potential the centres and tubes are found on
    vn = np.linalg.norm(v, axis=1) if v.ndim == 2 else np.abs(v)
    off = d["tubes/offsets"]
    nodes = d["tubes/nodes"]
    sig = d["extrema/significant"]
    tube_sig = sig[d["tubes/extremum"]] if len(d["tubes/extremum"]) else np.zeros(0, bool)
    kind = d["extrema/kind"][sig]
    node = d["extrema/node"][sig]
    fig = plt.figure(figsize=(7, 7))
    ax = fig.add_subplot(projection="3d")
    top = vn.max() if vn.size and vn.max() > 0 else 1.0
    for t in range(len(off) - 1):
        path = nodes[off[t]:off[t + 1]]
        if len(path) < 2 or not tube_sig[t]:
            continue
        p = pos[path]
        ax.plot(p[:, 0], p[:, 1], p[:, 2], color="green",
                linewidth=0.5 + 4.0 * float(vn[path].mean()) / top)
    for kk, colour, label in ((RIGHT, "darkgreen", "right-handed"), (LEFT, "red", "left-handed")):
        p = pos[node[kind == kk]]
        ax.scatter(p[:, 0], p[:, 1], p[:, 2], color=colour, s=18, label=label)
    true = pos[~d["nodes/ghost"].astype(bool)]
    lo, hi = true.min(axis=0), true.max(axis=0)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title("vortex centres and tubes (seed 000 Fig. 11)")
    return figutil.save(fig, out_dir, "hhd_tubes_3d.png")
