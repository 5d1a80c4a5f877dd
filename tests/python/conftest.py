"""pytest fixtures for the Python package: the build tree's package and CLI, a scratch folder."""
import os
import subprocess
import sys

import numpy as np
import pytest

BUILD = os.environ.get("GRANOSCOPE_BUILD_DIR",
                       os.path.join(os.path.dirname(__file__), "..", "..", "build"))
sys.path.insert(0, os.path.join(BUILD, "python"))
SOURCE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
CLI = os.path.join(BUILD, "bin", "granoscope")


def run_cli(*args):
    """Runs the granoscope CLI; returns (exit code, stdout, stderr)."""
    p = subprocess.run([CLI] + [str(a) for a in args], stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, text=True)
    return p.returncode, p.stdout, p.stderr


def packing(n=60, seed=3):
    """A loose random cloud of spheres with their touching pairs as contacts (numpy only)."""
    rng = np.random.default_rng(seed)
    pos = rng.uniform(0.0, 0.01, size=(n, 3))
    rad = rng.uniform(0.0009, 0.0013, size=n)
    i, j = np.triu_indices(n, 1)
    d = np.linalg.norm(pos[j] - pos[i], axis=1)
    touch = d < rad[i] + rad[j]
    i, j, d = i[touch], j[touch], d[touch]
    normal = (pos[j] - pos[i]) / d[:, None]
    point = pos[i] + normal * (rad[i] - 0.5 * (rad[i] + rad[j] - d))[:, None]
    fn = normal * rng.uniform(0.1, 2.0, size=len(i))[:, None]
    return dict(positions=pos, radii=rad, contact_ids=np.stack([i, j], axis=1),
                contact_points=point, contact_normals=normal, normal_forces=fn,
                overlaps=rad[i] + rad[j] - d)


@pytest.fixture
def cli():
    return run_cli


@pytest.fixture
def source_dir():
    return SOURCE
