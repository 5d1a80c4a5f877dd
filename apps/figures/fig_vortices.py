"""Figures for `granoscope analyze vortices` (format granoscope-vortices), after seed 000
Figs 16-18: the number of right- and left-handed vortex centres (and of sources and sinks)
against strain, and the Fourier amplitude of the vortex counts against the period T = 1/f in
units of strain."""
import h5py
import numpy as np

import figutil
from figutil import plt


def make(input_path, out_dir, args):
    with h5py.File(input_path, "r") as f:
        if figutil.attr(f, "format", "") != "granoscope-vortices":
            raise ValueError("not a vortex series (format %s)" % figutil.attr(f, "format", ""))
        if "series/strain" not in f:
            raise KeyError("series/strain missing")
        s = {k: f["series/" + k][()] for k in ("strain", "right", "left", "sources", "sinks")}
        spectra = {}
        for hand in ("right", "left"):
            g = "spectrum/" + hand
            if g in f:
                spectra[hand] = (f[g + "/period"][()], f[g + "/amplitude"][()],
                                 float(f[g].attrs.get("dominant_period", 0.0)))
        axis = figutil.attr(f, "strain_axis", "z")
    written = []
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    eps = 100.0 * s["strain"]
    axes[0].plot(eps, s["right"], "-o", ms=3, color="darkgreen", label="right-handed")
    axes[0].plot(eps, s["left"], "-o", ms=3, color="red", label="left-handed")
    axes[0].set_title("vortex centres (Fig. 16)")
    axes[1].plot(eps, s["sources"], "-o", ms=3, color="limegreen", label="sources")
    axes[1].plot(eps, s["sinks"], "-o", ms=3, color="firebrick", label="sinks")
    axes[1].set_title("sources and sinks")
    for ax in axes:
        ax.set_xlabel("strain along %s (%%)" % axis)
        ax.set_ylabel("number N")
        ax.legend(fontsize=8)
    written.append(figutil.save(fig, out_dir, "vortices_counts.png"))
    if spectra:
        fig, axes = plt.subplots(1, len(spectra), figsize=(5.5 * len(spectra), 4), squeeze=False)
        for ax, (hand, (period, amp, dom)) in zip(axes[0], spectra.items()):
            ax.plot(100.0 * period, amp, "-o", ms=3, color="darkgreen" if hand == "right" else "red")
            ax.set_xscale("log")
            ax.set_xlabel("period T = 1/f (%% strain)")
            ax.set_ylabel("amplitude of N")
            ax.set_title("%s-handed: dominant T = %.3g %%" % (hand, 100.0 * dom))
        written.append(figutil.save(fig, out_dir, "vortices_spectrum.png"))
    return written
