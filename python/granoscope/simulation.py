"""Scenes from Python: load a scene file, set values over it, run it with progress, stop and
resume, and read its curves as numpy arrays.

    sc = granoscope.Scene("data/scenes/triaxial.toml")
    sc["solver.threads"] = 2                 # any key of the file (docs/scenes.md), checked now
    run = sc.run("out/tri", progress=lambda p: print(p["step"], p["fraction"]))
    run.curve()["q_Pa"]                      # the test's curve, a column per name
    run.open()[-1]                           # the last frame of its trajectory

The run is `granoscope simulate`'s own (same outputs, same numbers, same checkpoints). A progress
callback returning False stops the run after writing a checkpoint; Ctrl-C does the same and then
raises KeyboardInterrupt; `run(..., resume=True)` continues it bit for bit.
"""

import math as _math
import os as _os
import tomllib as _tomllib

from . import _granoscope as _c


def _toml_value(value):
    """A Python value as TOML text (numbers, bools, strings, lists, dicts of those)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if _math.isnan(value):
            return "nan"
        if _math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        out = '"'
        for ch in value:
            if ch in '"\\':
                out += "\\" + ch
            elif ord(ch) < 0x20 or ord(ch) == 0x7F:
                out += "\\u%04x" % ord(ch)
            else:
                out += ch
        return out + '"'
    if isinstance(value, _os.PathLike):
        return _toml_value(_os.fspath(value))
    if isinstance(value, dict):
        return "{" + ", ".join("%s = %s" % (_toml_key(k), _toml_value(v))
                               for k, v in value.items()) + "}"
    try:
        items = list(value)
    except TypeError:
        raise TypeError("cannot write %r as a TOML value" % (value,)) from None
    return "[" + ", ".join(_toml_value(v.item() if hasattr(v, "item") else v)
                           for v in items) + "]"


def _toml_key(key):
    bare = key and all(c.isalnum() or c in "_-" for c in key)
    return key if bare else _toml_value(key)


def _parse_value(text):
    return _tomllib.loads("v = " + text)["v"]


class Run:
    """The outcome of Scene.run: paths of its outputs and what it reached.

    out, trajectory, history_path, curve_path: paths (curve_path None for a plain run).
    ended: the last programme ended; stopped: stopped from outside, resumable.
    step: the last step; steps_run, seconds: this call's; results: results.csv as a dict.
    """

    def __init__(self, d):
        d = dict(d)
        d["history_path"] = d.pop("history")
        d["curve_path"] = d.pop("curve")
        self.__dict__.update(d)

    def __repr__(self):
        state = "stopped" if self.stopped else "ended" if self.ended else "at its step limit"
        return "<granoscope.Run %s: step %d, %s>" % (self.out, self.step, state)

    def open(self):
        """The trajectory (granoscope.open)."""
        from . import open as _open
        return _open(self.trajectory)

    def history(self):
        """The monitor history (step, time_s, energies, wall forces...) as {column: array}."""
        return _read_csv(_finished_or_partial(self.history_path))

    def curve(self):
        """The laboratory test's curve as {column: array} (None for a plain run)."""
        if self.curve_path is None:
            return None
        return _read_csv(_finished_or_partial(self.curve_path))


def _finished_or_partial(path):
    """A stopped run's outputs are still `<name>.partial`."""
    path = _os.fspath(path)
    return path if _os.path.exists(path) else path + ".partial"


def _read_csv(path):
    import numpy as np
    with open(_os.fspath(path)) as fh:
        names = fh.readline().strip().split(",")
        rows = [line.split(",") for line in fh if line.strip()]
    data = np.array(rows, dtype=float).reshape(len(rows), len(names))
    return {n: data[:, k] for k, n in enumerate(names)}


class Scene:
    """A scene file (docs/scenes.md) with values set over it from Python.

    Scene(path, sweep_point=None, **{}) loads and checks the file as `granoscope simulate` does
    (bad input raises granoscope.Error with the CLI's message). scene[key] reads a value by its
    dotted key ("solver.dt_s", "triaxial.confining_Pa", "walls" for an array of tables);
    scene[key] = value sets it (SECTION.INDEX.KEY reaches into an array of tables, e.g.
    "walls.0.friction_deg"), checked at once. name, test, particles, dt, dt_pwave describe it.
    """

    def __init__(self, path, sweep_point=None, overrides=None):
        path = _os.fspath(path)
        if not _os.path.exists(path):
            from . import FileNotFound
            raise FileNotFound("%s: no such scene file" % path)
        self.path = path
        self.sweep_point = -1 if sweep_point is None else int(sweep_point)
        self._overrides = {}
        self._info = None
        for k, v in (overrides or {}).items():
            self._overrides[k] = _toml_value(v)
        self._reload()

    def _reload(self):
        self._info = _c._scene_info(self.path, list(self._overrides.items()), self.sweep_point)

    def __getitem__(self, key):
        values = self._info["values"]
        if key not in values:
            raise KeyError(key)
        return _parse_value(values[key])

    def __setitem__(self, key, value):
        old = dict(self._overrides)
        self._overrides[key] = _toml_value(value)
        try:
            self._reload()
        except Exception:
            self._overrides = old
            raise

    def keys(self):
        return list(self._info["values"].keys())

    @property
    def overrides(self):
        """The values set from Python, as TOML text."""
        return dict(self._overrides)

    name = property(lambda self: self._info["name"])
    test = property(lambda self: self._info["test"])
    particles = property(lambda self: self._info["particles"],
                         doc="number of particles the file gives (a generated specimen: 0)")
    dt = property(lambda self: self._info["dt"], doc="time step (s)")
    dt_pwave = property(lambda self: self._info["dt_pwave"], doc="P-wave time step (s)")
    toml = property(lambda self: self._info["toml"], doc="the scene as run, TOML text")

    def __repr__(self):
        return "<granoscope.Scene %s (%s), %d values set>" % (
            self.name, self.test or "plain run", len(self._overrides))

    def run(self, out=None, steps=None, threads=0, resume=False, progress=None, every=64,
            log=None):
        """Runs the scene as `granoscope simulate` does, into directory `out` (default
        out/<name>). steps: stop at this step. progress(p) is called at each programme's start
        and every `every` steps with a dict (phase, phase_index, phases, step, time_s,
        phase_fraction, fraction, steps_per_s, eta_s, phase_start); returning False stops the
        run after a checkpoint (resume=True continues it). log(line) gets the summaries.
        Returns a Run."""
        out = _os.path.join("out", self.name) if out is None else _os.fspath(out)
        return Run(_c._run_scene(self.path, list(self._overrides.items()), self.sweep_point, out,
                                 None if steps is None else int(steps), int(threads),
                                 bool(resume), progress, int(every), log))
