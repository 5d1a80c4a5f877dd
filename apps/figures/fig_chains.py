"""Figure for `granoscope analyze chains` (format granoscope-chains): the contact network in
front view (the slab plane when one was chosen), strong contacts (|Fn| above the threshold) in
red with line widths in proportion to |Fn|, the others thin and grey (seed 004 Fig. 4.55).
"""
import h5py
import numpy as np
from matplotlib.collections import LineCollection

import figutil
from figutil import plt


def make(input_path, out_dir, args):
    with h5py.File(input_path, "r") as f:
        axes = f["view_axes"][()]
        a, b = f["segments/a"][()], f["segments/b"][()]
        fn = f["segments/fn"][()]
        strong = f["segments/strong"][()].astype(bool)
        thr, mean = float(f.attrs["threshold"]), float(f.attrs["mean_fn"])
        chains, largest = int(f.attrs["chains"]), int(f.attrs["largest_chain"])
    if a.size == 0:
        raise ValueError("no contact segments")
    pa = np.stack([a @ axes[0], a @ axes[1]], axis=1)
    pb = np.stack([b @ axes[0], b @ axes[1]], axis=1)
    seg = np.stack([pa, pb], axis=1)
    fmax = fn.max() if fn.size and fn.max() > 0 else 1.0
    fig, ax = plt.subplots(figsize=(7, 7))
    ax.add_collection(LineCollection(seg[~strong], colors="0.75", linewidths=0.3))
    ax.add_collection(LineCollection(seg[strong], colors="tab:red",
                                     linewidths=0.3 + 3.0 * fn[strong] / fmax))
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_xlabel("view x (m)")
    ax.set_ylabel("view y (m)")
    ax.set_title("strong contacts |Fn| > %.3g N (mean %.3g N, max %.3g N): %d in %d chains, "
                 "largest %d particles" % (thr, mean, fmax, int(strong.sum()), chains, largest),
                 fontsize=9)
    return [figutil.save(fig, out_dir, "chains.png")]
