"""The example notebook (docs/examples/granoscope_tour.ipynb) runs headless from start to end,
so that it cannot rot: `jupyter nbconvert --execute` (Debian's jupyter-nbconvert)."""
import os
import shutil
import subprocess
import sys

from conftest import BUILD, SOURCE


def test_the_tour_notebook_executes(tmp_path):
    nbconvert = shutil.which("jupyter-nbconvert")
    assert nbconvert, "jupyter-nbconvert is missing: run scripts/setup"
    env = dict(os.environ)
    env["PYTHONPATH"] = os.path.join(os.path.abspath(BUILD), "python") + os.pathsep + env.get(
        "PYTHONPATH", "")
    env["GRANOSCOPE_SOURCE_DIR"] = SOURCE
    env["GRANOSCOPE_TOUR_OUT"] = str(tmp_path / "run")
    env["MPLBACKEND"] = "Agg"
    nb = os.path.join(SOURCE, "docs", "examples", "granoscope_tour.ipynb")
    p = subprocess.run([sys.executable, nbconvert, "--to", "notebook", "--execute",
                        "--ExecutePreprocessor.timeout=600", "--output-dir", str(tmp_path),
                        "--output", "tour_executed.ipynb", nb],
                       env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert p.returncode == 0, p.stderr[-4000:]
    for name in ("python_tour_history.png", "python_tour_rev.png", "python_tour_hhd.png"):
        assert (tmp_path / "run" / name).stat().st_size > 10000, name
    import nbformat
    done = nbformat.read(str(tmp_path / "tour_executed.ipynb"), as_version=4)
    errors = [o for c in done.cells if c.cell_type == "code" for o in c.get("outputs", [])
              if o.get("output_type") == "error"]
    assert not errors
    text = "".join(o.get("text", "") for c in done.cells if c.cell_type == "code"
                   for o in c.get("outputs", []))
    assert "error: <frame>: --method must be box or gaussian (boxes)" in text
