"""Figure for `granoscope analyze invariants` (format granoscope-invariants): Mohr's circles of
the principal stresses (compression positive) with the mobilised friction line, the invariants
p, q, eta, b, Lode angle (seed 003 §2.2.3), and the principal Biot strains when a deformation
gradient was evaluated (seed 003 §2.1.3).
"""
import h5py
import numpy as np

import figutil
from figutil import plt


def make(input_path, out_dir, args):
    with h5py.File(input_path, "r") as f:
        has_s, has_e = "stress" in f, "strain" in f
        if not (has_s or has_e):
            raise ValueError("no stress or strain in the file")
        fig, axes = plt.subplots(1, 2 if has_e and has_s else 1, figsize=(11 if has_e and has_s
                                                                           else 6, 5))
        axes = np.atleast_1d(axes)
        fig.subplots_adjust(wspace=0.4)
        k = 0
        if has_s:
            g = f["stress"]
            s = g["principal"][()]
            s = s[np.isfinite(s)]
            ax = axes[k]
            k += 1
            th = np.linspace(0, np.pi, 181)
            for a, b in ((s[0], s[-1]), (s[0], s[1]), (s[1], s[-1])) if s.size == 3 else (
                    (s[0], s[1]),):
                c, r = 0.5 * (a + b), 0.5 * (a - b)
                ax.plot(c + r * np.cos(th), r * np.sin(th), "k")
            rmax = 0.5 * (s.max() - s.min()) or abs(s.max()) or 1.0
            lo, hi = s.min() - 0.6 * rmax, s.max() + 0.6 * rmax
            phi = float(g.attrs["phi_mob_deg"])
            if np.isfinite(phi):
                x = np.linspace(max(lo, 0.0), hi, 2)
                ax.plot(x, x * np.tan(np.radians(phi)), "r--", label="phi_mob = %.1f deg" % phi)
                ax.legend()
            ax.set_xlim(lo, hi)
            ax.set_ylim(0.0, 1.5 * rmax)
            ax.set_aspect("equal", adjustable="datalim")
            ax.set_xlabel("normal stress (Pa, compression positive)")
            ax.set_ylabel("shear stress (Pa)")
            ax.set_title("p %.4g, q %.4g, eta %.3f, b %.3f, Lode %.1f deg" % tuple(
                float(g.attrs[n]) for n in ("p", "q", "eta", "b", "lode_deg")), fontsize=9)
        if has_e:
            g = f["strain"]
            ax = axes[k]
            e = g["principal"][()]
            ax.bar(["e1", "e2", "e3"], e, color="tab:blue")
            ax.axhline(0, color="k", lw=0.5)
            ax.set_ylabel("principal Biot strain (compression positive)")
            ax.set_title("J %.5f, eps_v %.4g, eps_q %.4g, b_eps %.3f" % tuple(
                float(g.attrs[n]) for n in ("J", "eps_v", "eps_q", "b_eps")), fontsize=9)
    return [figutil.save(fig, out_dir, "invariants.png")]
