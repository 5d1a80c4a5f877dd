"""Shared helpers for figure modules: headless matplotlib, HDF5 attributes, atomic PNG writing."""
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def save(fig, out_dir, name, dpi=150):
    """Saves under a temporary name and renames, so no partial PNG is ever left behind."""
    path = os.path.join(out_dir, name)
    tmp = path + ".tmp-%d.png" % os.getpid()
    fig.savefig(tmp, dpi=dpi, bbox_inches="tight")
    plt.close(fig)
    os.replace(tmp, path)
    return path


def attr(obj, name, default=None):
    """An HDF5 attribute of a file, group or dataset, bytes decoded to str."""
    v = obj.attrs.get(name, default)
    return v.decode() if isinstance(v, bytes) else v
