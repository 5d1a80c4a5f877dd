#!/usr/bin/env python3
"""Writes docs/examples/granoscope_tour.ipynb (the notebook's source is this file, so that its
diffs stay readable). Run with Debian's /usr/bin/python3 (nbformat)."""
import os
import sys

import nbformat as nbf

cells = []


def md(text):
    cells.append(nbf.v4.new_markdown_cell(text.strip("\n")))


def code(text):
    cells.append(nbf.v4.new_code_cell(text.strip("\n")))


md("""
# granoscope from Python: a tour

Runs a scene, opens its trajectory, maps it with REV cells and decomposes a displacement
increment (Helmholtz–Hodge, seed 000 eqs 17–18) — all as numpy arrays, with the numbers of the
`granoscope` CLI. The scene is the YADE oedometer case shipped in `data/scenes/` (883 spheres,
a top wall moving down under gravity).

The tests execute this notebook headless (`jupyter nbconvert --execute`), so it cannot rot.
""")

code("""
import os, pathlib, tempfile
import numpy as np
import matplotlib
matplotlib.use("Agg")  # headless; in Jupyter the figures show inline all the same
import matplotlib.pyplot as plt
import granoscope as gs

# The repository (for data/scenes) and where this tour writes its run and figures.
root = pathlib.Path(os.environ.get("GRANOSCOPE_SOURCE_DIR", pathlib.Path.cwd()))
while not (root / "data" / "scenes").is_dir() and root != root.parent:
    root = root.parent
out = pathlib.Path(os.environ.get("GRANOSCOPE_TOUR_OUT") or tempfile.mkdtemp(prefix="gs_tour_"))
figures = pathlib.Path(os.environ.get("GRANOSCOPE_TOUR_FIGURES", out))
figures.mkdir(parents=True, exist_ok=True)
print("granoscope", gs.__version__, "| output in", out)
""")

md("""
## 1. Run a scene

`gs.Scene` loads a scene file as `granoscope simulate` does; any key can be set from Python and is
checked at once. `run` takes a progress callback (a `tqdm` bar's `update` fits too); returning
`False` from it stops the run after a checkpoint, and `run(..., resume=True)` continues it bit
for bit.
""")

code("""
scene = gs.Scene(root / "data" / "scenes" / "oedometer_yade.toml")
scene["output.every"] = 500           # a frame every 500 steps
scene["output.history_every"] = 50
print(scene, "| dt =", scene.dt, "s, P-wave step", f"{scene.dt_pwave:.3g}", "s")

def progress(p):
    if p["step"] % 1000 == 0:
        print(f"step {p['step']:5d}  {100 * p['fraction']:5.1f} %  {p['steps_per_s']:.3g} steps/s")

run = scene.run(out / "oedometer", steps=3000, progress=progress, every=500)
print(run)
""")

code("""
h = run.history()
fig, ax = plt.subplots(1, 2, figsize=(9, 3.2))
ax[0].plot(h["time_s"] * 1e3, h["top_fz_N"], label="top")
ax[0].plot(h["time_s"] * 1e3, h["bottom_fz_N"], label="bottom")
ax[0].set(xlabel="time (ms)", ylabel="force on the wall, z (N)", title="wall forces")
ax[0].legend()
ax[1].semilogy(h["time_s"] * 1e3, h["kinetic_J"])
ax[1].set(xlabel="time (ms)", ylabel="kinetic energy (J)", title="monitor history")
fig.tight_layout()
fig.savefig(figures / "python_tour_history.png", dpi=110)
""")

md("""
## 2. Open the trajectory

`gs.open` reads every format `granoscope info` reads; an HDF5 trajectory is read frame by frame.
A frame's fields are numpy views (no copy).
""")

code("""
traj = run.open()
f = traj[-1]
print(len(traj), "frames;", f.n_particles, "particles,", f.n_contacts, "contacts at t =", f.time, "s")
print("positions", f.positions.shape, f.positions.dtype, "| d50 =", gs.d50(f), "m")
""")

md("""
## 3. A REV map

REV cells of 3 d50 every d50 in the front slab (seed 000 §3): void ratio from exact sphere–box
volumes and the Love–Weber stress. Cell fields come flat; `grid["dims"][::-1]` reshapes them to
`[k, j, i]`.
""")

code("""
m = gs.rev(f, slab=True, cell_d50=3, step_d50=0.5)
ny, nx = m["grid"]["dims"][1], m["grid"]["dims"][0]
e = m["cells"]["void_ratio"].reshape(ny, nx)
p = m["cells"]["p"].reshape(ny, nx)
loc = m["cells"]["local"]
extent = [loc[:, 0].min(), loc[:, 0].max(), loc[:, 1].min(), loc[:, 1].max()]
fig, ax = plt.subplots(1, 2, figsize=(9, 3.8))
for a, field, title in ((ax[0], e, "void ratio"), (ax[1], p / 1e3, "mean stress p (kPa)")):
    im = a.imshow(field, origin="lower", extent=[1e3 * x for x in extent])
    a.set(title=title, xlabel="x (mm)", ylabel="z (mm)")
    fig.colorbar(im, ax=a, shrink=0.8)
fig.tight_layout()
fig.savefig(figures / "python_tour_rev.png", dpi=110)
print(f"mean void ratio {np.nanmean(e):.3f}; mode {m['mode']}, {nx} x {ny} cells")
""")

md("""
## 4. Helmholtz–Hodge decomposition of an increment

The displacement from frame 4 to frame 6 in a 5 d50 slice (seed 000 §5), decomposed on the
Delaunay mesh of the centres into a gradient, a curl and a harmonic part; vortex centres are
the extrema of the vector potential.
""")

code("""
d = gs.hhd(traj[len(traj) - 3], to=traj[-1], slice=True)
x = d["nodes"]["position"]
curl = d["simplices"]["curl_v"]
tri = d["simplices"]["vertices"]
centre = x[tri].mean(axis=1)
ext = d["extrema"]
sig = ext["significant"].astype(bool)
fig, ax = plt.subplots(figsize=(5, 5))
ax.quiver(1e3 * centre[:, 0], 1e3 * centre[:, 1], curl[:, 0], curl[:, 1], color="0.4")
for kind, style in ((0, "r^"), (1, "bv")):
    k = sig & (ext["kind"] == kind)
    ax.plot(1e3 * ext["position"][k, 0], 1e3 * ext["position"][k, 1], style,
            label=("right", "left")[kind] + "-handed vortices")
ax.set(xlabel="x in the slice (mm)", ylabel="z (mm)", aspect="equal", title="curl part")
ax.legend(loc="upper right", fontsize=8)
fig.tight_layout()
fig.savefig(figures / "python_tour_hhd.png", dpi=110)
print("|grad u| %.3g  |curl v| %.3g  |h| %.3g" % (d["norm_grad_u"], d["norm_curl_v"],
                                                   d["norm_harmonic"]))
print("counts", d["counts"])
""")

md("""
## 5. Fabric and the numbers of the CLI

Every `granoscope analyze` subcommand is a function with the same options as keyword arguments
(`fabric`, `rose`, `chains`, `walls`, `invariants`, `rev`, `shearzone`, `strain`, `voidcells`,
`hhd`, `vortices`) and gives the CLI's numbers; bad input raises `gs.Error` with the CLI's line.
""")

code("""
fab = gs.fabric(f)
print("coordination", round(fab["omega"], 3), "| anisotropy |D|", round(fab["D_norm"], 4))
inv = gs.invariants(f)
print("specimen p = %.4g Pa, q = %.4g Pa" % (inv["stress"]["p"], inv["stress"]["q"]))
try:
    gs.rev(f, method="boxes")
except gs.Error as err:
    print("error:", err)
""")

nb = nbf.v4.new_notebook()
nb["cells"] = cells
nb["metadata"] = {"kernelspec": {"name": "python3", "display_name": "Python 3",
                                 "language": "python"},
                  "language_info": {"name": "python"}}
path = os.path.join(os.path.dirname(__file__), "..", "docs", "examples", "granoscope_tour.ipynb")
nbf.write(nb, path)
print("wrote", os.path.normpath(path))
