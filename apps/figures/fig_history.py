"""Monitors of a `granoscope simulate` run: wall forces and the energy ledger against time.
Reads history.csv beside the trajectory; writes nothing when there is none (imported data)."""
import csv
import os

import matplotlib.pyplot as plt
import numpy as np

import figutil


def make(path, out_dir, args):
    hist = os.path.join(os.path.dirname(os.path.abspath(path)), "history.csv")
    if not os.path.exists(hist):
        return []
    with open(hist) as f:
        rows = list(csv.reader(f))
    if len(rows) < 2:
        raise ValueError(f"{hist}: no rows")
    head, data = rows[0], np.array([[float(v) for v in r] for r in rows[1:]])
    col = {h: i for i, h in enumerate(head)}
    t = data[:, col["time_s"]] * 1e3
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7, 7), sharex=True)
    walls = sorted({h[:-5] for h in head if h.endswith("_fx_N")})
    for w in walls:
        f = np.linalg.norm(data[:, [col[w + "_fx_N"], col[w + "_fy_N"], col[w + "_fz_N"]]], axis=1)
        a1.plot(t, f, label=w)
    a1.set_ylabel("|wall force| (N)")
    if walls:
        a1.legend(fontsize=8, ncol=3)
    for key, label in [("kinetic_J", "kinetic"), ("elastic_J", "elastic"),
                       ("friction_dissipation_J", "friction dissipation"),
                       ("damping_dissipation_J", "damping dissipation"),
                       ("gravity_work_J", "work of gravity"), ("wall_work_J", "work of walls"),
                       ("energy_residual_J", "ledger residual")]:
        a2.plot(t, data[:, col[key]], label=label)
    a2.set_xlabel("time (ms)")
    a2.set_ylabel("energy (J)")
    a2.legend(fontsize=8, ncol=2)
    a1.set_title(os.path.basename(path))
    stem = os.path.splitext(os.path.basename(path))[0]
    return [figutil.save(fig, out_dir, f"{stem}_history.png")]
