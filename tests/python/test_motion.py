"""Strain, void cells, HHD and vortex series from Python give the CLI's numbers."""
import csv

import h5py
import numpy as np
import pytest

import granoscope as gs
from conftest import packing


def hex_disks(nx=12, ny=10, d=1e-3):
    """A 2D hexagonal packing of touching disks (diameter d, m) with its contacts."""
    x, y = np.meshgrid(np.arange(nx), np.arange(ny), indexing="xy")
    pos = np.stack([(x + 0.5 * (y % 2)) * d, y * d * np.sqrt(3) / 2, 0 * x], -1).reshape(-1, 3)
    n = len(pos)
    i, j = np.triu_indices(n, 1)
    dist = np.linalg.norm(pos[j] - pos[i], axis=1)
    touch = np.abs(dist - d) < 1e-9 * d
    i, j = i[touch], j[touch]
    normal = (pos[j] - pos[i]) / d
    return dict(positions=pos, radii=np.full(n, 0.5 * d), contact_ids=np.stack([i, j], 1),
                contact_points=0.5 * (pos[i] + pos[j]), contact_normals=normal,
                normal_forces=normal, overlaps=np.zeros(len(i)), two_d=True)


def test_strain_of_an_affine_motion_is_exact_and_equals_the_cli(cli, tmp_path):
    p = packing(n=200, seed=11)
    H = np.array([[1e-3, 2e-4, 0.0], [0.0, -5e-4, 3e-4], [1e-4, 0.0, 2e-4]])
    f = gs.Frame.from_arrays(**p)
    g = gs.Frame.from_arrays(**dict(p, positions=p["positions"] @ (np.eye(3) + H).T), time=1.0)
    gs.save(tmp_path / "a.h5", [f, g])
    rc, _, err = cli("analyze", "strain", tmp_path / "a.h5", "--to", 1, "-o", tmp_path / "s.h5")
    assert rc == 0, err
    py = gs.strain(f, to=g)
    assert py["motion"] == "displacement" and py["dim"] == 3
    with h5py.File(tmp_path / "s.h5", "r") as h:
        for k in ("id", "position", "valid", "volumetric_strain", "equivalent_shear_strain",
                  "rotation_xy"):
            np.testing.assert_array_equal(h["particles"][k][()], py["particles"][k], err_msg=k)
        np.testing.assert_array_equal(h["particles/gradient"][()].reshape(-1, 3, 3),
                                      py["particles"]["gradient"])
        np.testing.assert_array_equal(h["simplices/vertices"][()], py["simplices"]["vertices"])
        np.testing.assert_array_equal(h["mean_gradient"][()], py["mean_gradient"])
    # An affine displacement has the same gradient H in every tetrahedron (exact).
    np.testing.assert_allclose(py["simplices"]["gradient"] - H, 0.0, atol=1e-12)
    np.testing.assert_allclose(py["mean_gradient"], H, atol=1e-13)
    assert py["simplices"]["volumetric_strain"][0] == pytest.approx(np.trace(H), abs=1e-12)


def test_strain_of_a_slab_from_velocities(cli, tmp_path):
    p = packing(n=300, seed=2)
    L = np.array([[0.0, 0.0, 0.5], [0.0, 0.0, 0.0], [0.0, 0.0, -1.0]])  # 1/s
    f = gs.Frame.from_arrays(**p, velocities=p["positions"] @ L.T)
    gs.save(tmp_path / "v.h5", f)
    slab = dict(slab_origin=[0.005, 0.005, 0.005], slab_normal=[0, 1, 0], slab_axis=[1, 0, 0])
    rc, _, err = cli("analyze", "strain", tmp_path / "v.h5", "-o", tmp_path / "s.h5",
                     "--slab-origin", 0.005, 0.005, 0.005, "--slab-normal", 0, 1, 0,
                     "--slab-axis", 1, 0, 0, "--slab-d50", 2)
    assert rc == 0, err
    py = gs.strain(f, slab_d50=2, **slab)
    assert py["dim"] == 2 and py["slab"] and py["motion"] == "velocity"
    with h5py.File(tmp_path / "s.h5", "r") as h:
        np.testing.assert_array_equal(h["simplices/alpha"][()], py["simplices"]["alpha"])
        np.testing.assert_array_equal(h["simplices/w"][()], py["simplices"]["w"])
        np.testing.assert_array_equal(h["particles/id"][()], py["particles"]["id"])
    # In the plane (e1 = x, e2 = n x e1 = -z... ): the in-plane gradient has trace L_xx + L_zz.
    assert np.trace(py["mean_gradient"][:2, :2]) == pytest.approx(-1.0, rel=1e-9)


def test_voidcells_of_an_affine_velocity_equal_the_cli(cli, tmp_path):
    p = hex_disks()
    L = np.array([[0.2, 0.3, 0.0], [-0.1, -0.4, 0.0], [0.0, 0.0, 0.0]])
    f = gs.Frame.from_arrays(**p, velocities=p["positions"] @ L.T)
    gs.save(tmp_path / "h.h5", f)
    rc, _, err = cli("analyze", "voidcells", tmp_path / "h.h5", "-o", tmp_path / "v.h5")
    assert rc == 0, err
    py = gs.voidcells(f)
    with h5py.File(tmp_path / "v.h5", "r") as h:
        for k in ("faces", "edges", "vertices", "euler"):
            assert h.attrs[k] == py[k], k
        for k in ("offsets", "vertices", "polygon", "area", "alpha", "w"):
            np.testing.assert_array_equal(h["cells"][k][()], py["cells"][k], err_msg=k)
        np.testing.assert_array_equal(h["cells/gradient"][()].reshape(-1, 2, 2),
                                      py["cells"]["gradient"])
        np.testing.assert_array_equal(h["particles/relative_velocity"][()],
                                      py["particles"]["relative_velocity"])
    # Seed 002 eq 7 is exact for an affine field: every cell's gradient is L; alpha = 1, w = 0
    # against the mean L (eqs 18, 20); Euler L - M + N = 1.
    np.testing.assert_allclose(py["cells"]["gradient"] - L[:2, :2], 0.0, atol=1e-12)
    np.testing.assert_allclose(py["mean_gradient"], L[:2, :2], atol=1e-12)
    np.testing.assert_allclose(py["cells"]["alpha"], 1.0, atol=1e-12)
    assert py["euler"] == 1 and py["faces"] == 2 * (12 - 1) * (10 - 1)
    with pytest.raises(gs.Error, match="^<frame>: void cells need a 2D frame"):
        gs.voidcells(gs.Frame.from_arrays(**packing(n=40)))


def test_hhd_of_points_equals_the_cli_csv(cli, tmp_path):
    """A 2D vortex (rigid rotation about the centre) and a source: one of each is found."""
    rng = np.random.default_rng(4)
    x = rng.uniform(-1.0, 1.0, size=(400, 2))
    r2 = (x ** 2).sum(1)
    u = np.stack([-x[:, 1], x[:, 0]], 1) * np.exp(-4 * r2)[:, None]
    with open(tmp_path / "pts.csv", "w") as fh:
        w = csv.writer(fh)
        w.writerow(["x", "y", "ux", "uy"])
        for a, b in zip(x, u):
            w.writerow([repr(a[0]), repr(a[1]), repr(b[0]), repr(b[1])])
    rc, _, err = cli("analyze", "hhd", "--csv", tmp_path / "pts.csv", "-o", tmp_path / "h.h5")
    assert rc == 0, err
    py = gs.hhd(points=x, vectors=u)
    with h5py.File(tmp_path / "h.h5", "r") as h:
        np.testing.assert_array_equal(h["nodes/u"][()], py["nodes"]["u"])
        np.testing.assert_array_equal(h["nodes/v"][()], py["nodes"]["v"])
        np.testing.assert_array_equal(h["extrema/kind"][()], py["extrema"]["kind"])
        np.testing.assert_array_equal(h["extrema/position"][()], py["extrema"]["position"])
        assert h.attrs["norm_curl_v"] == py["norm_curl_v"]
    # The field is solenoidal: the curl part carries it, one significant vortex near the centre,
    # counter-clockwise (left-handed about +z: kind 1) or right by the package's convention.
    assert py["norm_grad_u"] < 0.1 * py["norm_curl_v"]
    sig = py["extrema"]["significant"].astype(bool)
    vort = sig & (py["extrema"]["kind"] <= 1)
    assert vort.sum() == 1
    assert np.linalg.norm(py["extrema"]["position"][vort][0, :2]) < 0.15


def test_hhd_and_vortices_of_a_trajectory_equal_the_cli(cli, tmp_path):
    p = packing(n=250, seed=8)
    frames = []
    for k in range(6):
        c = np.array([0.005, 0.005, 0.005])
        d = p["positions"] - c
        a = 0.01 * k
        rot = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
        x = c + (d * [1, 1, 1 - 0.01 * k]) @ rot.T
        frames.append(gs.Frame.from_arrays(**dict(p, positions=x), time=float(k)))
    gs.save(tmp_path / "t.h5", frames)
    rc, _, err = cli("analyze", "hhd", tmp_path / "t.h5", "--to", 2, "-o", tmp_path / "h.h5")
    assert rc == 0, err
    py = gs.hhd(frames[0], to=frames[2])
    with h5py.File(tmp_path / "h.h5", "r") as h:
        np.testing.assert_array_equal(h["nodes/u"][()], py["nodes"]["u"])
        np.testing.assert_array_equal(h["nodes/v_coulomb"][()], py["nodes"]["v_coulomb"])
        np.testing.assert_array_equal(h["simplices/curl_v"][()], py["simplices"]["curl_v"])
        assert h.attrs["residual_eq18"] == py["report"]["residual_eq18"]
    rc, _, err = cli("analyze", "vortices", tmp_path / "t.h5", "--every", 1, "-o",
                     tmp_path / "v.h5")
    assert rc == 0, err
    seen = []
    run = gs.open(tmp_path / "t.h5")
    v = gs.vortices(run, every=1, progress=lambda a, b, e, c: seen.append((a, b)))
    assert seen == [(k, k + 1) for k in range(5)]
    with h5py.File(tmp_path / "v.h5", "r") as h:
        for k in ("strain", "right", "left", "sources", "sinks", "tubes", "right_all"):
            np.testing.assert_array_equal(h["series"][k][()], v["series"][k], err_msg=k)
        np.testing.assert_array_equal(h["spectrum/right/amplitude"][()],
                                      v["spectrum"]["right"]["amplitude"])
    # Strain: relative shortening of the particles' extent along z (spheres included).
    ext = [(fr.positions[:, 2] + fr.radii).max() - (fr.positions[:, 2] - fr.radii).min()
           for fr in frames]
    np.testing.assert_allclose(v["series"]["strain"], 1.0 - np.array(ext[:5]) / ext[0],
                               atol=1e-15)
    assert v["series"]["strain"][1] > 0.005
    # The same series from a list of frames.
    w = gs.vortices(frames, every=1)
    np.testing.assert_array_equal(w["series"]["right"], v["series"]["right"])


def test_motion_errors_are_the_cli_lines():
    f = gs.Frame.from_arrays(**packing(n=60))
    with pytest.raises(gs.Error, match=r"^<frame>: --min-quality must be in \[0, 1\) \(1\.5\)$"):
        gs.strain(f, min_quality=1.5)
    with pytest.raises(gs.Error, match=r"^<frame>: --solver: unknown solver \(magic\)$"):
        gs.hhd(f, solver="magic")
    with pytest.raises(gs.Error, match=r"^<frame>: give either a frame or points and vectors$"):
        gs.hhd()
    with pytest.raises(gs.Error, match=r"^<trajectory>: --every must be >= 1 \(0\)$"):
        gs.vortices([f, f], every=0)
    with pytest.raises(gs.Error, match=r"no frame pair"):
        gs.vortices([f], every=1)


@pytest.mark.parametrize("solver", ["projection", "projection-amg"])
def test_ctrl_c_interrupts_a_long_hhd(solver):
    """A 3D decomposition of 20 000 nodes that would iterate for hours (a random field, a
    tolerance no solve reaches, 10^6 iterations a system: ~3 ms each here): SIGINT after 0.5 s
    raises KeyboardInterrupt from the iterations (the projection's after a direct path (b), or
    the AMG path (b)'s) within seconds; what runs before the first poll (Delaunay, assembly,
    factorisation) takes 0.2 s here. No longer timed against a whole default decomposition: with
    another test running beside it, the interrupted run once took 5.4 s against 4.2 s for the
    whole one a moment before."""
    import os
    import signal
    import threading
    import time
    rng = np.random.default_rng(0)
    x = rng.uniform(0.0, 1.0, size=(20000, 3))
    u = rng.normal(size=(20000, 3))
    # (the same field to a few iterations: both paths iterate, and do not converge)
    short = gs.hhd(points=x, vectors=u, solver=solver, tolerance=1e-300, max_iterations=20)
    assert not short["report"]["converged"]
    assert short["report"]["iterations_v"] == 20
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    t0 = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        gs.hhd(points=x, vectors=u, solver=solver, tolerance=1e-300, max_iterations=1_000_000)
    elapsed = time.monotonic() - t0
    timer.join()
    print("%s interrupted after %.2f s" % (solver, elapsed))
    assert elapsed < 60.0, elapsed
