"""granoscope.dic on numpy images gives the CLI's numbers on the same images, bit for bit."""
import os

import h5py
import numpy as np
import pytest

import granoscope as gs


def speckle(shift=(0.0, 0.0), n=96, seed=5):
    """Gaussian-blob speckle (8-bit) moved by `shift` (px, x right, y down), sampled exactly."""
    rng = np.random.default_rng(seed)
    m = n * n // 12
    cx, cy = rng.uniform(-8, n + 8, m), rng.uniform(-8, n + 8, m)
    s, a = rng.uniform(1.5, 2.5, m), rng.uniform(60, 120, m)
    yy, xx = np.mgrid[0:n, 0:n].astype(float)
    img = np.full((n, n), 40.0)
    for k in range(m):
        d2 = (xx - shift[0] - cx[k]) ** 2 + (yy - shift[1] - cy[k]) ** 2
        img += a[k] * np.exp(-0.5 * d2 / s[k] ** 2)
    return np.clip(np.rint(img), 0, 255).astype(np.uint8)


def write_pgm(path, img):
    with open(path, "wb") as f:
        f.write(b"P5\n%d %d\n255\n" % (img.shape[1], img.shape[0]))
        f.write(img.tobytes())


def test_dic_equals_the_cli(cli, tmp_path):
    ref, d1, d2 = speckle(), speckle((0.4, -0.3)), speckle((0.9, 0.2))
    names = []
    for k, im in enumerate((ref, d1, d2)):
        names.append(tmp_path / ("f%d.pgm" % k))
        write_pgm(names[-1], im)
    rc, out, err = cli("dic", *names, "-o", tmp_path / "d.h5", "--subset", 21, "--step", 4,
                       "--strain-window", 5, "--threads", 2, "--no-csv", "--no-vtk")
    assert rc == 0, err
    py = gs.dic([ref, d1, d2], subset=21, step=4, strain_window=5, threads=2)
    files = gs.dic(names, subset=21, step=4, strain_window=5, threads=1)  # file names, 1 thread
    with h5py.File(tmp_path / "d.h5", "r") as h:
        for key in ("x", "y", "u", "v", "zncc", "exx", "eyy", "exy", "exx_small"):
            np.testing.assert_array_equal(h[key][()], py[key], err_msg=key)
            np.testing.assert_array_equal(files[key], py[key], err_msg=key)
        np.testing.assert_array_equal(h["valid"][()].astype(bool), py["valid"])
        assert h.attrs["vsg_px"] == py["vsg_px"]
    assert py["u"].shape == (2, py["y"].size, py["x"].size)
    # every POI valid but those whose subset touches the border and moves out of the image
    assert py["valid"][:, 1:-1, 1:-1].all()
    inner = np.s_[1:-1, 1:-1]
    np.testing.assert_allclose(py["u"][0][inner], 0.4, atol=0.01)  # the motion itself
    np.testing.assert_allclose(py["v"][0][inner], -0.3, atol=0.01)
    np.testing.assert_allclose(py["u"][1][inner], 0.9, atol=0.01)
    np.testing.assert_allclose(py["v"][1][inner], 0.2, atol=0.01)


def test_dic_options_and_errors():
    ref = speckle()
    flat = np.full_like(ref, 128)
    with pytest.raises(gs.Error, match=r"^<image 1>: image has no texture \(uniform grey level\)$"):
        gs.dic([ref, flat], subset=21)
    with pytest.raises(gs.Error, match=r"^--subset: must be an odd number of px >= 5 \(30\)$"):
        gs.dic([ref, ref], subset=30)
    with pytest.raises(gs.Error, match="image size differs from the reference"):
        gs.dic([ref, ref[:50]], subset=21)
    with pytest.raises(gs.Error, match="image dtype must be"):
        gs.dic([ref, ref.astype(np.int64)], subset=21)
    q = gs.dic([ref.astype(np.float64), speckle((0.3, 0.1)).astype(np.float32)], subset=21,
               step=8, strain_window=5, shape="quadratic")
    assert q["shape_function"] == "quadratic"
    np.testing.assert_allclose(q["u"][0][q["valid"][0]], 0.3, atol=0.02)


def test_ctrl_c_interrupts_a_long_dic():
    """A long gs.dic releases the GIL and stops at the next propagation front on SIGINT."""
    import signal
    import subprocess
    import sys
    import time

    from conftest import BUILD
    code = r"""
import signal, time
signal.signal(signal.SIGINT, signal.default_int_handler)  # even when started with SIGINT ignored
import numpy as np, granoscope as gs
rng = np.random.default_rng(1)
img = rng.integers(0, 256, size=(1200, 1200), dtype=np.uint8)  # white-noise speckle
print("ready", flush=True)
t0 = time.time()
try:
    gs.dic([img, img], subset=21, step=1, threads=1)
    print("finished", time.time() - t0, flush=True)
except KeyboardInterrupt:
    print("interrupted", time.time() - t0, flush=True)
"""
    env = dict(os.environ, PYTHONPATH=os.path.join(BUILD, "python"))
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True, env=env)
    assert p.stdout.readline().strip() == "ready"
    time.sleep(2.0)  # inside the correlation (1.4 million POIs: about a minute on one thread)
    p.send_signal(signal.SIGINT)
    out, _ = p.communicate(timeout=60)
    word, seconds = out.split()
    assert word == "interrupted"
    assert float(seconds) < 10.0


def test_render_equals_the_cli_and_its_truth_is_the_motion(cli, tmp_path):
    """Speckle images of two frames (the second translated by dx along x): the CLI's images and
    ground truth, and u = dx px_per_m, v = 0 on every grain pixel."""
    import matplotlib.image as mpimg
    rng = np.random.default_rng(2)
    n = 40
    xyz = np.column_stack([rng.uniform(0, 0.01, n), rng.uniform(0, 0.002, n),
                           rng.uniform(0, 0.01, n)])
    r = rng.uniform(0.0008, 0.0012, n)
    dx = 1.3e-4
    frames = [gs.Frame.from_arrays(xyz, r), gs.Frame.from_arrays(xyz + [dx, 0, 0], r, time=1.0)]
    gs.save(tmp_path / "t.h5", frames)
    rc, _, err = cli("render", tmp_path / "t.h5", "-o", tmp_path / "img", "--px-per-d50", 12)
    assert rc == 0, err
    py = gs.render(gs.open(tmp_path / "t.h5"), px_per_d50=12)
    assert py["images"].dtype == np.uint8 and py["images"].shape[0] == 2
    for k in range(2):
        png = mpimg.imread(str(tmp_path / "img" / ("frame_%04d.png" % k)))
        np.testing.assert_array_equal(np.rint(png * 255).astype(np.uint8), py["images"][k])
    with h5py.File(tmp_path / "img" / "ground_truth.h5", "r") as h:
        np.testing.assert_array_equal(h["u"][()], py["u"].astype(np.float32))
        np.testing.assert_array_equal(h["grain"][()], py["grain"][0])
        ppm = h.attrs["px_per_m"]
    assert py["camera"]["px_per_m"] == ppm
    grain = py["grain"][1] >= 0
    assert grain.mean() > 0.2
    np.testing.assert_allclose(py["u"][1][grain], dx * ppm, rtol=1e-9)
    np.testing.assert_allclose(py["v"][1][grain], 0.0, atol=1e-9)
    # The same from a list of frames; 16 bits.
    same = gs.render(frames, px_per_d50=12)
    np.testing.assert_array_equal(same["images"], py["images"])
    assert gs.render(frames, px_per_d50=12, bits=16)["images"].dtype == np.uint16
    with pytest.raises(gs.Error, match=r"^--bits: must be 8 or 16 \(12\)$"):
        gs.render(frames, bits=12)
