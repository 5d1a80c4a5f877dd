"""`pip install .` offline into a virtual environment that sees Debian's numpy, reusing the
build tree's CMake folder (docs/python.md), then the installed package imports and works."""
import os
import subprocess
import sys

from conftest import BUILD, SOURCE


def test_pip_install_into_a_venv(tmp_path):
    env_dir = tmp_path / "env"
    subprocess.check_call([sys.executable, "-m", "venv", "--system-site-packages", str(env_dir)])
    pip = env_dir / "bin" / "pip"
    env = dict(os.environ, GRANOSCOPE_CMAKE_BUILD_DIR=os.path.abspath(BUILD))
    p = subprocess.run([str(pip), "install", "--no-build-isolation", "--no-index", "-q", SOURCE],
                       env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    assert p.returncode == 0, p.stdout
    code = ("import granoscope as gs, numpy as np; "
            "f = gs.Frame.from_arrays(np.zeros((2, 3)) + [[0, 0, 0], [1, 0, 0]], np.ones(2)); "
            "print(gs.__file__, f.n_particles, gs.d50(f))")
    out = subprocess.check_output([str(env_dir / "bin" / "python"), "-c", code], cwd=tmp_path,
                                  text=True)
    path, n, d50 = out.split()
    assert path.startswith(str(env_dir)) and n == "2" and float(d50) == 2.0
