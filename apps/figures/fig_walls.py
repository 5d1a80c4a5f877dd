"""Figure for `granoscope analyze walls` (format granoscope-walls): the normal and shear wall
stresses along each wall (seed 004 Figs 5.8-5.11) and the resultants P, T, N over the weight G
and the mobilised wall friction angle (seed 004 §5.3.1).
"""
import h5py
import numpy as np

import figutil
from figutil import plt


def make(input_path, out_dir, args):
    with h5py.File(input_path, "r") as f:
        walls = []
        for key in sorted(f["walls"].keys(), key=int):
            g = f["walls"][key]
            if g["position"].size == 0:
                continue
            walls.append((int(figutil.attr(g, "id")), figutil.attr(g, "role"), g["position"][()],
                          g["sigma_n"][()], g["tau"][()]))
        text = "P/G %.3f, T/G %.3f, N/G %.3f, phi_w %.1f deg, (T + P)/G %.3f" % tuple(
            float(f.attrs[k]) for k in ("P_over_G", "T_over_G", "N_over_G", "phi_w_deg",
                                        "balance"))
    if not walls:
        raise ValueError("no wall with contacts")
    fig, axes = plt.subplots(1, 2, figsize=(11, 6), sharey=True)
    for wid, role, pos, sn, tau in walls:
        label = "wall %d (%s)" % (wid, role)
        axes[0].plot(sn, pos, ".-", label=label)
        axes[1].plot(tau, pos, ".-", label=label)
    axes[0].set_xlabel("normal wall stress sigma_n (Pa)")
    axes[1].set_xlabel("wall shear stress tau (Pa)")
    axes[0].set_ylabel("position along the wall (m)")
    for ax in axes:
        ax.axvline(0.0, color="0.7", lw=0.5)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.suptitle(text)
    return [figutil.save(fig, out_dir, "walls.png")]
