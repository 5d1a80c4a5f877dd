#!/usr/bin/python3
"""DEM8 Case 1 from a frame (run_dem8_silo_bench.sh, run_dem8_silo_rate_check.sh): the spheres of
WORK/frame.csv (`granoscope convert` of a run of a laptop silo scene) as WORK/packing.csv, and the
scene SCENE.toml rewritten as WORK/silo.toml to discharge them at rest: no [fill] (the packing),
no [[walls]] (the lid gone: the orifice open), the wall mesh read from D8, STEPS steps, no frames
or checkpoints but the last, the history every HISTORY_EVERY steps. Prints the sphere count.

    dem8_silo_frame_scene.py SCENE.toml WORK D8 STEPS [--contact yade|merged] [--threads N]
                             [--history-every K]
"""
import argparse
import csv
import os
import re

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("scene")
ap.add_argument("work")
ap.add_argument("d8")
ap.add_argument("steps", type=int)
ap.add_argument("--contact", choices=("yade", "merged"), default="merged")
ap.add_argument("--threads", type=int, default=None, help="default: the scene's")
ap.add_argument("--history-every", type=int, default=None, help="default: the scene's")
a = ap.parse_args()
rows = list(csv.DictReader(open(os.path.join(a.work, "frame.csv"))))
with open(os.path.join(a.work, "packing.csv"), "w") as f:
    f.write("id,x,y,z,r\n")
    for k, r in enumerate(rows):
        f.write("%d,%s,%s,%s,%s\n" % (k, r["x"], r["y"], r["z"], r["radius"] if "radius" in r else r["r"]))
s = open(a.scene).read()
s = re.sub(r"\n\[fill\].*?(?=\n\[)", "\n", s, flags=re.S)          # no filling: the packing
s = re.sub(r"\n\[\[walls\]\].*?(?=\n\[)", "\n", s, flags=re.S)  # no lid: the orifice open
s = re.sub(r'\nname = "[^"]*"', '\nname = "silo_frame"\npacking = "packing.csv"', s, count=1)
s = s.replace('"../../../shared/dem8/', '"%s/' % a.d8)
s = s.replace('contact = "merged"', 'contact = "%s"' % a.contact)
s = re.sub(r"\nsteps = .*", "\nsteps = %d" % a.steps, s)
if a.threads is not None:
    s = re.sub(r"\nthreads = .*", "\nthreads = %d" % a.threads, s)
s = re.sub(r"\nevery = .*", "\nevery = 100000000", s)
if a.history_every is not None:
    s = re.sub(r"\nhistory_every = .*", "\nhistory_every = %d" % a.history_every, s)
s = re.sub(r"\ncheckpoint_every = .*", "\ncheckpoint_every = 100000000", s)
open(os.path.join(a.work, "silo.toml"), "w").write(s)
print(len(rows))
