"""Macroscopic curves of a laboratory-test run (`granoscope simulate` with scene.test): reads
curve.csv (and preparation.csv) beside the trajectory; nothing when there is none.
  triaxial / plane strain: mobilised friction angle and σ1/σ3 vs ε1, volumetric strain vs ε1
  (dilation positive, as seed 004 Figs 4.2-4.8 and seed 000 Fig 3);
  direct shear: τ/σn and volumetric strain vs horizontal displacement u (seed 004 Fig 4.12);
  interface shear: φs (μeff = T/P on the right) and εv vs u (seed 004 Figs 4.37-4.38, 4.73-4.74);
  silo: P/G, T/G, N/G per wall vs the bottom's travel u or the discharge time (seed 004 §5.3.1);
  periodic biaxial (2D): σ22 − σ11 and σ22/σ11 vs ε22, area strain vs ε22 (seed 002 Fig 7b);
  principal stress rotation: the six stress and strain components against α, the x-z strain
  trajectory and εv, εyy against cycles (seed 003 Figs 5-7, 9; strains from the rotation's
  start); with `granoscope analyze rotation RUN -o DIR` written beside the run (DIR = the run's
  `rotation/`), also the non-coaxiality, the fabric loop, α − α_F and the orientation fabric of
  the clumps (Figs 10, 14, 15, 17);
  preparation: void ratio and friction against steps."""
import csv
import os

import matplotlib.pyplot as plt
import numpy as np

import figutil


def read(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    if len(rows) < 2:
        raise ValueError(f"{path}: no rows")
    head = rows[0]
    data = np.array([[float(v) for v in r] for r in rows[1:]])
    return {h: data[:, i] for i, h in enumerate(head)}


def strength_and_dilatancy(x, x_label, y, y_label, peak, ratio, ratio_label, ev, ev_label,
                           title):
    """Two panels over the loading strain x (%): a strength measure y with its peak marked and a
    stress ratio on the right axis, and the volumetric (or area) strain below."""
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(6.5, 7), sharex=True)
    a1.plot(x, y, "k-")
    a1.set_ylabel(y_label)
    k = int(np.argmax(y))
    a1.plot(x[k], y[k], "ro")
    a1.annotate(peak(y[k], x[k]), (x[k], y[k]), textcoords="offset points", xytext=(8, -14),
                fontsize=8)
    r = a1.twinx()
    r.plot(x, ratio, color="0.6", lw=0.8)
    r.set_ylabel(ratio_label, color="0.5")
    a2.plot(x, ev, "k-")
    a2.axhline(0, color="0.7", lw=0.5)
    a2.set_ylabel(ev_label)
    a2.set_xlabel(x_label)
    a1.set_title(title)
    return fig


def compression(c, title):
    return strength_and_dilatancy(
        100 * c["eps1_shortening"], "axial strain ε1 (%)", c["phi_deg"],
        "mobilised friction angle φ (°)", lambda y, x: f"peak {y:.1f}° at ε1 = {x:.1f} %",
        c["sigma1_Pa"] / c["sigma3_Pa"], "σ1/σ3", 100 * c["eps_v_dilation"],
        "volumetric strain εv (%, dilation +)", title)


def shear(c, title):
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(6.5, 7), sharex=True)
    u = 1e3 * c["u_m"]
    a1.plot(u, c["tau_over_sigma_n"], "k-")
    a1.set_ylabel("τ/σn")
    a2.plot(u, 100 * c["eps_v_dilation"], "k-")
    a2.axhline(0, color="0.7", lw=0.5)
    a2.set_ylabel("volumetric strain εv (%, dilation +)")
    a2.set_xlabel("horizontal displacement u (mm)")
    a1.set_title(title)
    return fig


def interface(c, title):
    return strength_and_dilatancy(
        1e3 * c["u_m"], "horizontal displacement u (mm)", c["phi_s_deg"],
        "mobilised surface friction angle φs (°)", lambda y, x: f"{y:.1f}° at u = {x:.2f} mm",
        c["mu_eff"], "μeff = T/P", 100 * c["eps_v"], "volumetric strain εv (%, dilation +)", title)


def silo(c, title):
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(6.5, 7), sharex=True)
    quasi = np.any(c["u_m"] > 0)
    x = 1e3 * c["u_m"] if quasi else c["flow_time_s"]
    a1.plot(x, c["P_G"], "k-", label="P/G (bottom)")
    for side, style in (("left", "-"), ("right", "--")):
        a1.plot(x, c[f"T_{side}_G"], "b" + style, label=f"T/G {side}")
        a1.plot(x, c[f"N_{side}_G"], "r" + style, label=f"N/G {side}")
    a1.plot(x, c["balance_G"], color="0.6", lw=0.8, label="(P + 2T)/G")
    a1.set_ylabel("wall force / weight G")
    a1.legend(fontsize=7, ncol=2)
    a2.plot(x, c["phi_w_left_deg"], "k-", label="left")
    a2.plot(x, c["phi_w_right_deg"], "k--", label="right")
    a2.set_ylabel("φw = atan(T/N) (°)")
    a2.legend(fontsize=7)
    a2.set_xlabel("bottom travel u (mm)" if quasi else "discharge time (s)")
    a1.set_title(title)
    return fig


def biaxial(c, title):
    return strength_and_dilatancy(
        100 * c["eps22_shortening"], "vertical strain ε22 (%, shortening +)",
        1e-3 * (c["sigma22_Pa"] - c["sigma11_Pa"]), "Δσ22 = σ22 − σ11 (kPa)",
        lambda y, x: f"peak {y:.0f} kPa at ε22 = {x:.2f} %", c["sigma22_over_sigma11"],
        "σ22/σ11", 100 * c["eps_v_dilation"], "area strain (%, dilation +)", title)


def preparation(c, title):
    fig, a1 = plt.subplots(figsize=(6.5, 4))
    a1.plot(c["step"], c["void_ratio"], "k-", label="whole box")
    a1.plot(c["step"], c["core_void_ratio"], "b-", label="core")
    a1.set_xlabel("step")
    a1.set_ylabel("void ratio e")
    a1.legend(fontsize=8)
    r = a1.twinx()
    r.plot(c["step"], c["friction_deg"], color="tab:red", lw=0.8)
    r.set_ylabel("friction during compaction (°)", color="tab:red")
    a1.set_title(title)
    return fig


def rotation(c, title):
    k = c["stage"] >= 4
    a = c["alpha_deg"][k]
    e0 = {n: c[n][k][0] for n in ("exx", "eyy", "ezz", "exy", "exz", "eyz", "eps_v")}
    fig, ax = plt.subplots(2, 2, figsize=(11, 8))
    for n, lab in (("sxx", "σxx"), ("syy", "σyy"), ("szz", "σzz"), ("sxy", "σxy"),
                   ("sxz", "σxz"), ("syz", "σyz")):
        ax[0, 0].plot(a, c[n + "_Pa"][k] / 1e3, lw=0.8, label=lab)
    ax[0, 0].set_xlabel("α, σ1 from z (°)")
    ax[0, 0].set_ylabel("stress (kPa, compression +)")
    ax[0, 0].legend(ncol=3, fontsize=8)
    for n in ("exx", "eyy", "ezz", "exy", "exz", "eyz"):
        ax[0, 1].plot(a, 100 * (c[n][k] - e0[n]), lw=0.8, label="ε" + n[1:])
    ax[0, 1].set_xlabel("α (°)")
    ax[0, 1].set_ylabel("strain from the rotation's start (%, compression +)")
    ax[0, 1].legend(ncol=3, fontsize=8)
    dx = 100 * 0.5 * ((c["exx"][k] - e0["exx"]) - (c["ezz"][k] - e0["ezz"]))
    ax[1, 0].plot(dx, 100 * (c["exz"][k] - e0["exz"]), lw=0.8)
    ax[1, 0].set_xlabel("(εxx − εzz)/2 (%)")
    ax[1, 0].set_ylabel("εxz (%)")
    ax[1, 0].set_title("x–z strain trajectory (Fig 7)", fontsize=9)
    ax[1, 0].set_aspect("equal", adjustable="datalim")
    cyc = a / 180.0
    ax[1, 1].plot(cyc, 100 * (c["eps_v"][k] - e0["eps_v"]), label="εv")
    ax[1, 1].plot(cyc, 100 * (c["eyy"][k] - e0["eyy"]), label="εyy")
    ax[1, 1].set_xlabel("cycles (180° each)")
    ax[1, 1].set_ylabel("strain (%, compression +)")
    ax[1, 1].legend()
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def rotation_report(here, title):
    """Non-coaxiality against α, the fabric loop, α − α_F and the clumps' orientation fabric,
    from `analyze rotation`'s tables (seed 003 Figs 10, 14, 15, 17)."""
    inc, fab = (os.path.join(here, "rotation", f) for f in
                ("rotation_increments.csv", "rotation_fabric.csv"))
    if not (os.path.exists(inc) and os.path.exists(fab)):
        return None
    i, f = read(inc), read(fab)
    fig, ax = plt.subplots(2, 2, figsize=(11, 8.5))
    a1, a2, a3, a4 = ax.flat
    a1.plot(i["alpha_deg"], i["non_coaxiality_deg"], ".-", lw=0.8)
    a1.axhspan(30, 40, color="0.9", label="seed 003: 30–40°")
    a1.set_xlabel("α (°)")
    a1.set_ylabel("α^R_Δε − α (°)")
    a1.set_title("non-coaxiality (Fig 10)", fontsize=9)
    a1.legend()
    a2.plot(0.5 * (f["Dxx"] - f["Dzz"]), f["Dxz"], "o-", ms=3, lw=0.8)
    a2.axhline(0, color="0.6", lw=0.5)
    a2.axvline(0, color="0.6", lw=0.5)
    a2.set_xlabel("(Dxx − Dzz)/2")
    a2.set_ylabel("Dxz")
    a2.set_title("contact fabric loop (Fig 14)", fontsize=9)
    a2.set_aspect("equal", adjustable="datalim")
    a3.plot(f["alpha_deg"], f["alpha_minus_F_deg"], "o-", ms=3, lw=0.8)
    a3.set_xlabel("α (°)")
    a3.set_ylabel("α − α_F (°)")
    a3.set_title("stress against fabric direction (Fig 15)", fontsize=9)
    for n, lab in (("Dp_xx", "D^p xx"), ("Dp_yy", "D^p yy"), ("Dp_zz", "D^p zz"),
                   ("Dp_xz", "D^p xz")):
        a4.plot(f["alpha_deg"], f[n], "o-", ms=3, lw=0.8, label=lab)
    a4.set_xlabel("α (°)")
    a4.set_ylabel("particle-orientation fabric")
    a4.set_title("clump long axes (Fig 17)", fontsize=9)
    a4.legend(ncol=2, fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def make(path, out_dir, args):
    here = os.path.dirname(os.path.abspath(path))
    stem = os.path.splitext(os.path.basename(path))[0]
    written = []
    curve = os.path.join(here, "curve.csv")
    if os.path.exists(curve):
        c = read(curve)
        if "alpha_sigma_deg" in c:
            fig = rotation(c, f"{stem}: principal stress rotation")
            report = rotation_report(here, f"{stem}: principal stress rotation")
            if report is not None:
                written.append(figutil.save(report, out_dir, f"{stem}_rotation.png"))
        elif "mu_eff" in c:
            fig = interface(c, f"{stem}: interface shear")
        elif "P_G" in c:
            fig = silo(c, f"{stem}: silo")
        elif "u_m" in c:
            fig = shear(c, f"{stem}: direct shear")
        elif "eps22_shortening" in c:
            fig = biaxial(c, f"{stem}: periodic biaxial")
        elif "eps1_shortening" in c:
            fig = compression(c, f"{stem}: {'plane strain' if 'width_m' in c else 'triaxial'}")
        else:
            raise ValueError(f"{curve}: not a laboratory-test curve")
        written.append(figutil.save(fig, out_dir, f"{stem}_curve.png"))
    prep = os.path.join(here, "preparation.csv")
    if os.path.exists(prep):
        written.append(figutil.save(preparation(read(prep), f"{stem}: preparation"), out_dir,
                                    f"{stem}_preparation.png"))
    return written
