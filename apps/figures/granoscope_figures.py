#!/usr/bin/env python3
"""Figure dispatcher for `granoscope figures INPUT -o DIR [--type NAME]`.

Reads the `format` attribute at the root of the HDF5 input and runs the figure module registered
for it. Each module `fig_<name>.py` exposes `make(input_path, out_dir, args) -> [written files]`.
Exit code 2 with one line `error: FILE: what` on bad input.
"""
import argparse
import importlib
import os
import sys

# format attribute -> figure modules (first is the default for that format)
FIGURES = {
    "granoscope-trajectory": ["fig_positions", "fig_history", "fig_labcurve"],
    "granoscope-dic": ["fig_dic"],
    "granoscope-strain": ["fig_strain"],
    "granoscope-voidcells": ["fig_strain"],
    "granoscope-rev": ["fig_rev"],
    "granoscope-shearzone": ["fig_rev"],
    "granoscope-invariants": ["fig_invariants"],
    "granoscope-fabric": ["fig_rose"],
    "granoscope-rose": ["fig_rose"],
    "granoscope-chains": ["fig_chains"],
    "granoscope-walls": ["fig_walls"],
    "granoscope-silo": ["fig_silo"],
    "granoscope-hhd": ["fig_hhd"],
    "granoscope-vortices": ["fig_vortices"],
}
# figure modules made only when asked for with --type
ON_REQUEST = {
    "granoscope-trajectory": ["fig_layers", "fig_rotation"],
}


def main(argv):
    ap = argparse.ArgumentParser(prog="granoscope figures")
    ap.add_argument("input")
    ap.add_argument("-o", "--out", required=True)
    ap.add_argument("--type", default=None, help="figure module name, e.g. positions")
    ap.add_argument("--frame", type=int, default=-1, help="frame index (trajectory figures)")
    ap.add_argument("--field", default=None, help="field of a map figure (rev), e.g. void_ratio")
    args = ap.parse_args(argv)
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import h5py  # noqa: E402

    try:
        with h5py.File(args.input, "r", swmr=True) as f:
            fmt = f.attrs.get("format", b"")
            fmt = fmt.decode() if isinstance(fmt, bytes) else str(fmt)
    except OSError as e:
        print(f"error: {args.input}: cannot open HDF5 file ({e})", file=sys.stderr)
        return 2
    if fmt not in FIGURES:
        print(f"error: {args.input}: no figures for format ({fmt or 'missing'})", file=sys.stderr)
        return 2
    modules = FIGURES[fmt]
    if args.type:
        name = "fig_" + args.type
        if name not in modules + ON_REQUEST.get(fmt, []):
            print(f"error: {args.input}: figure type not available for {fmt} ({args.type})",
                  file=sys.stderr)
            return 2
        modules = [name]
    os.makedirs(args.out, exist_ok=True)
    for m in modules:
        try:
            written = importlib.import_module(m).make(args.input, args.out, args)
        except Exception as e:  # any failure of a figure script is one line, never a traceback
            print(f"error: {args.input}: {m}: {e}".replace("\n", " "),
                  file=sys.stderr)
            return 2
        for w in written:
            print(w)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
