"""granoscope from Python: snapshots as numpy arrays, and the toolkit's analyses.

    import granoscope as gs
    run = gs.open("run.h5")          # any format `granoscope info` reads
    f = run[-1]                      # a Frame; f.positions is an (N, 3) numpy view, m
    gs.fabric(f)["omega"]            # the numbers of `granoscope analyze fabric`
    g = gs.Frame.from_arrays(xyz, r) # frames from your own arrays
    gs.save("out.vtu", g)

Units are SI (m, s, N, Pa, kg) unless a name says otherwise. Bad input raises
granoscope.Error (a ValueError) whose message is the line the CLI prints after "error: ";
a missing file raises granoscope.FileNotFound (a FileNotFoundError and a granoscope.Error).
See docs/python.md.
"""

import os as _os

from . import _granoscope as _c
from ._granoscope import (Error, Frame, Trajectory, chains, d50, dic, fabric, hhd, interface,
                          invariants, materials, render, rev, rose, rotation, shearzone, silo,
                          strain, stress_invariants, voidcells, vortices, walls)

__all__ = ["Error", "FileNotFound", "Frame", "Run", "Scene", "Trajectory", "open", "save",
           "chains", "d50", "dic", "fabric", "hhd", "interface", "invariants", "materials",
           "render", "rev", "rose", "rotation", "shearzone", "silo", "strain", "stress_invariants",
           "voidcells", "vortices", "walls", "__version__"]

from .simulation import Run, Scene  # noqa: E402 (needs the compiled module)

__version__ = _c.code_version().split()[-1]


class FileNotFound(FileNotFoundError, Error):
    """A file that does not exist; str() is the CLI's message ("PATH: no such file")."""


def open(path, contacts=None, dt=0.0, pair_columns=None):  # noqa: A001 (the package's verb)
    """Opens a snapshot or trajectory file of any format `granoscope info` reads.

    path: our HDF5 trajectory, .vtu/.pvd, YADE .vtk, packing .csv, LIGGGHTS dump.
    contacts: contacts file kept apart from the particles (YADE interactions .vtk, LIGGGHTS
        local dump); default: found by naming convention.
    dt: time step in s for LIGGGHTS dumps (time = step x dt).
    pair_columns: list of the LIGGGHTS pair dump columns (default x1,y1,z1,x2,y2,z2,id1,id2,
        periodic,fx,fy,fz).
    Returns a Trajectory (len(), [i] -> Frame; HDF5 files are read frame by frame).
    """
    path = _os.fspath(path)
    if not _os.path.exists(path):
        raise FileNotFound("%s: no such file" % path)
    if contacts is not None:
        contacts = _os.fspath(contacts)
        if not _os.path.exists(contacts):
            raise FileNotFound("%s: no such file" % contacts)
    return _c._open(path, contacts, float(dt), None if pair_columns is None else list(pair_columns))


def save(path, frames, frame=-1):
    """Writes frames to any format `granoscope convert` writes.

    frames: a Frame, a list of Frames or a Trajectory. .h5 and .pvd take every frame; .vtu
    (contacts in a .vtp beside it) and .csv take one, `frame` (default the last).
    """
    path = _os.fspath(path)
    if isinstance(frames, Trajectory):
        frames.save(path, frame)
        return
    if isinstance(frames, Frame):
        frames = [frames]
    _c._save_frames(path, list(frames), frame)
