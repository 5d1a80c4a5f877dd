"""DIC maps (seed 004 Figs A.9-A.15 style): u, v, exx, eyy, exy over the reference image.

Input: dic.h5 written by `granoscope dic` (root attribute format = "granoscope-dic").
"""
import os

import h5py
import numpy as np

import figutil

FIELDS = [
    ("u", "u (px)", "RdBu_r"),
    ("v", "v (px)", "RdBu_r"),
    ("exx", r"$E_{xx}$", "RdBu_r"),
    ("eyy", r"$E_{yy}$", "RdBu_r"),
    ("exy", r"$E_{xy}$", "RdBu_r"),
]


def _reference_image(images_attr, input_path):
    text = images_attr.decode() if isinstance(images_attr, bytes) else str(images_attr)
    first = text.split("\n")[0] if text else ""
    if not first:
        return None
    path = first if os.path.isabs(first) else os.path.join(os.path.dirname(input_path), first)
    if not os.path.exists(path) and os.path.exists(first):
        path = first
    try:
        import matplotlib.image as mpimg

        img = mpimg.imread(path)
    except (OSError, ValueError, SyntaxError):
        return None
    if img.ndim == 3:
        img = img[..., :3].mean(axis=2)
    return img


def _check_shapes(f):
    """Malformed files are a ValueError (one error line), not a traceback from matplotlib."""
    x, y = f["x"], f["y"]
    if x.ndim != 1 or y.ndim != 1 or x.shape[0] < 1 or y.shape[0] < 1:
        raise ValueError("x, y must be non-empty 1-D datasets (shapes %s, %s)"
                         % (x.shape, y.shape))
    want = (y.shape[0], x.shape[0])
    frames = f["u"].shape[0] if f["u"].ndim == 3 else None
    for name in [n for n, _, _ in FIELDS] + ["valid"]:
        d = f[name]
        if d.ndim != 3 or d.shape[1:] != want or d.shape[0] != frames:
            raise ValueError("dataset %s has shape %s, expected (frames, %d, %d)"
                             % (name, d.shape, want[0], want[1]))


def make(input_path, out_dir, args):
    plt = figutil.plt
    with h5py.File(input_path, "r") as f:
        _check_shapes(f)
        x = f["x"][()]
        y = f["y"][()]
        nframes = f["u"].shape[0]
        frame = getattr(args, "frame", -1)
        if frame < 0:
            frame += nframes
        if not 0 <= frame < nframes:
            raise ValueError("frame index out of range (%d of %d)" % (frame, nframes))
        data = {name: f[name][frame] for name, _, _ in FIELDS}
        valid = f["valid"][frame].astype(bool)
        vsg = float(f.attrs.get("vsg_px", 0.0))
        subset = int(f.attrs.get("subset_px", 0))
        bg = _reference_image(f.attrs.get("images", b""), input_path)
    step = x[1] - x[0] if len(x) > 1 else 1.0
    extent = [x[0] - step / 2, x[-1] + step / 2, y[-1] + step / 2, y[0] - step / 2]
    written = []
    for name, label, cmap in FIELDS:
        a = np.where(valid, data[name], np.nan)
        fig, ax = plt.subplots(figsize=(6, 5))
        if bg is not None:
            ax.imshow(bg, cmap="gray", interpolation="nearest")
        finite = a[np.isfinite(a)]
        lim = float(np.percentile(np.abs(finite), 99)) if finite.size else 1.0
        lim = lim if lim > 0 else 1.0
        im = ax.imshow(np.ma.masked_invalid(a), cmap=cmap, vmin=-lim, vmax=lim, extent=extent,
                       alpha=0.85, interpolation="nearest")
        if bg is not None:
            ax.set_xlim(-0.5, bg.shape[1] - 0.5)
            ax.set_ylim(bg.shape[0] - 0.5, -0.5)
        fig.colorbar(im, ax=ax, label=label)
        ax.set_xlabel("x (px)")
        ax.set_ylabel("y (px)")
        ax.set_title("%s, image %d (subset %d px, VSG %.0f px)" % (label, frame + 1, subset, vsg))
        written.append(figutil.save(fig, out_dir, "dic_%s_%04d.png" % (name, frame + 1)))
    return written
