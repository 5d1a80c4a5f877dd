"""Figures for `granoscope analyze silo` (format granoscope-silo), seed 004 §5.3:
silo_forces.png   P/G, T/G, N/G per side wall and phi_w against time (Figs 5.5-5.7), with the
                  slice method's P/G at the three states (Eq 5.1-5.2, EN 1991-4);
silo_profiles.png wall stresses sigma11 and sigma21 against the height at the initial, maximum
                  and residual states (Figs 5.8-5.11), from the wall contacts (thick) and from
                  the Love-Weber stress in near-wall cells (thin);
silo_fabric.png   top: the last state's downward displacement, rotation and void ratio across
                  the width at the layers' heights (Figs 5.15-5.17); bottom, per state: the void
                  ratio across, the rotation profile the wall shear zones are read from
                  (Table 5.4), and the polar histogram of the left half's contact normals
                  (Fig 5.27).
"""
import h5py
import numpy as np

import figutil
from figutil import plt

STATES = ("initial", "maximum", "residual")
COLOURS = {"initial": "tab:blue", "maximum": "tab:red", "residual": "tab:green"}


def _states(f):
    out = {}
    for s in STATES:
        if "profiles/" + s not in f:
            continue
        g = f["profiles/" + s]
        out[s] = {k: g[k][()] for k in g.keys()}
        out[s].update({k: figutil.attr(g, k) for k in g.attrs.keys()})
    if not out:
        raise ValueError("no profiles in the report")
    return out


def make(input_path, out_dir, args):
    with h5py.File(input_path, "r") as f:
        series = {k: f["series"][k][()] for k in f["series"].keys()}
        states = _states(f)
        d50 = float(figutil.attr(f, "d50", np.nan))
    written = []

    # Forces over the weight against time.
    t = series["time_s"]
    fig, ax = plt.subplots(figsize=(8, 5))
    ax.plot(t, series["P_G"], label="P/G (bottom)", color="k")
    ax.plot(t, series["T_left_G"], label="T/G left", color="tab:blue")
    ax.plot(t, series["T_right_G"], "--", label="T/G right", color="tab:blue")
    ax.plot(t, series["N_left_G"], label="N/G left", color="tab:orange")
    ax.plot(t, series["N_right_G"], "--", label="N/G right", color="tab:orange")
    for s, st in states.items():
        for key, marker, name in (("P_G_drescher", "o", "Drescher"), ("P_G_en1991", "s", "EN")):
            v = float(st.get(key, np.nan))
            if np.isfinite(v):
                ax.plot([st["time_s"]], [v], marker, color=COLOURS[s], mfc="none",
                        label="P/G %s (%s)" % (name, s))
    ax.set_title("silo: forces over the weight")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("force / weight G")
    ax.grid(alpha=0.3)
    ax2 = ax.twinx()
    ax2.plot(t, series["phi_w_left_deg"], ":", color="0.4", label="phi_w left")
    ax2.plot(t, series["phi_w_right_deg"], "-.", color="0.4", label="phi_w right")
    ax2.set_ylabel("mobilised wall friction angle phi_w (deg)")
    ax.legend(fontsize=7, loc="upper left")
    ax2.legend(fontsize=7, loc="upper right")
    written.append(figutil.save(fig, out_dir, "silo_forces.png"))

    # Wall stress profiles.
    fig, axes = plt.subplots(1, 2, figsize=(10, 6), sharey=True)
    for s, st in states.items():
        h = st["height_m"]
        for side, style in (("left", "-"), ("right", "--")):
            axes[0].plot(st["sigma11_%s_Pa" % side], h, style, color=COLOURS[s],
                         label="%s, %s wall" % (s, side))
            axes[1].plot(st["sigma21_%s_Pa" % side], h, style, color=COLOURS[s])
            if len(st.get("lw_sigma11_%s_Pa" % side, [])):  # (Love-Weber, near-wall cells)
                axes[0].plot(st["lw_sigma11_%s_Pa" % side], h, style, color=COLOURS[s],
                             lw=0.6, alpha=0.6, label="%s, %s, Love-Weber" % (s, side))
                axes[1].plot(st["lw_sigma21_%s_Pa" % side], h, style, color=COLOURS[s],
                             lw=0.6, alpha=0.6)
    axes[0].set_title("silo: sigma11")
    axes[1].set_title("silo: sigma21")
    axes[0].set_xlabel("horizontal wall stress sigma11 (Pa)")
    axes[1].set_xlabel("vertical wall shear stress sigma21 (Pa)")
    axes[0].set_ylabel("height above the bottom (m)")
    for a in axes:
        a.axvline(0.0, color="0.7", lw=0.5)
        a.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    written.append(figutil.save(fig, out_dir, "silo_profiles.png"))

    # Void ratio layers, rotation profile, rose of the left half.
    fig = plt.figure(figsize=(15, 10))
    # Top row: the residual state's layers (Figs 5.15-5.17: u, omega and e across the width).
    last = states[list(states)[-1]]
    lh = np.asarray(last.get("layer_height_m", []))
    for col, (key, name, label, scale) in enumerate((
            ("layer_displacement_down_m", "displacement", "downward displacement (mm)", 1e3),
            ("layer_rotation_rad", "rotation", "mean |rotation| (rad)", 1.0),
            ("layer_void_ratio", "void ratio", "void ratio e", 1.0))):
        ax = fig.add_subplot(2, 3, col + 1)
        for k, height in enumerate(np.unique(lh)):
            m = lh == height
            ax.plot(last["layer_across_m"][m], scale * np.asarray(last[key])[m],
                    ["-", "--", ":", "-."][k % 4], color="k", label="%.3g m" % height)
        ax.set_title("silo: %s across (%s)" % (name, list(states)[-1]))
        ax.set_xlabel("across (m)")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, title="height above the bottom", title_fontsize=7)
    ax_e = fig.add_subplot(2, 3, 4)
    ax_r = fig.add_subplot(2, 3, 5)
    ax_p = fig.add_subplot(2, 3, 6, projection="polar")
    for s, st in states.items():
        lh = np.asarray(st.get("layer_height_m", []))
        for k, height in enumerate(np.unique(lh)):
            m = lh == height
            ax_e.plot(st["layer_across_m"][m], st["layer_void_ratio"][m],
                      ["-", "--", ":", "-."][k % 4], color=COLOURS[s],
                      label="%s, %.3g m" % (s, height))
        if len(st.get("zone_rotation_rad", [])):
            # (the extent: from reports written since 2026-12-06)
            extent = [float(st.get("zone_extent_%s_m" % w, np.nan)) / d50
                      for w in ("left", "right")]
            ax_r.plot(st["zone_across_m"], st["zone_rotation_rad"], color=COLOURS[s],
                      label="%s (zones %.1f / %.1f d50, extent %.1f / %.1f)" % (
                          s, float(st["zone_left_m"]) / d50, float(st["zone_right_m"]) / d50,
                          extent[0], extent[1]))
        dens = np.asarray(st.get("rose_left_density", []))
        if dens.size:
            ang = np.radians(np.asarray(st["rose_left_angle_deg"]))
            ax_p.plot(np.append(ang, ang[0]), np.append(dens, dens[0]), color=COLOURS[s],
                      label="%s: %.0f deg" % (s, float(st["fabric_left_angle_deg"])))
    ax_e.set_title("silo: void ratio across")
    ax_r.set_title("silo: rotation across at the zones' height")
    ax_e.set_xlabel("across (m)")
    ax_e.set_ylabel("void ratio e")
    ax_e.grid(alpha=0.3)
    ax_e.legend(fontsize=6)
    ax_r.set_xlabel("across (m)")
    ax_r.set_ylabel("mean |rotation| (rad)")
    ax_r.grid(alpha=0.3)
    ax_r.legend(fontsize=7)
    ax_p.set_title("silo: left half contact normals (0 deg = wall normal)", fontsize=9, pad=18)
    ax_p.legend(fontsize=7, loc="lower left", bbox_to_anchor=(0.8, -0.1))
    written.append(figutil.save(fig, out_dir, "silo_fabric.png"))
    return written
