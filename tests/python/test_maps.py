"""REV maps and shear zones from Python give the CLI's numbers on the same input."""
import csv

import h5py
import numpy as np
import pytest

import granoscope as gs
from conftest import packing


def lattice(nx=24, nz=24, ny=4, d=1e-3):
    """A simple cubic lattice of touching spheres, diameter d (m), spanning x-z."""
    g = np.stack(np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij"), -1)
    return (g.reshape(-1, 3) + 0.5) * d, np.full(nx * ny * nz, 0.5 * d)


def band_motion(x, angle_deg, centre, width, gamma):
    """Simple shear gamma inside a band of `width` (m) through `centre`, inclined `angle_deg` to
    x in the x-z plane: u = gamma * clip(n.(x - c), -w/2, w/2) * t."""
    a = np.radians(angle_deg)
    t = np.array([np.cos(a), 0.0, np.sin(a)])
    n = np.array([-np.sin(a), 0.0, np.cos(a)])
    s = np.clip((x - centre) @ n, -0.5 * width, 0.5 * width)
    return gamma * s[:, None] * t[None, :]


def cli_cells(path):
    with h5py.File(path, "r") as h:
        return {k: h["cells"][k][()] for k in h["cells"]}, dict(h.attrs), h["grid/dims"][()]


def test_rev_box_equals_the_cli_bit_for_bit(cli, tmp_path):
    p = packing(n=300, seed=5)
    f = gs.Frame.from_arrays(**p)
    x1 = p["positions"] + 1e-5 * np.sin(p["positions"] * 500.0)
    g = gs.Frame.from_arrays(**dict(p, positions=x1), time=1.0)
    gs.save(tmp_path / "p.h5", [f, g])
    args = ["--cell-d50", 2, "--step-d50", 1]
    rc, _, err = cli("analyze", "rev", tmp_path / "p.h5", "--frame", 0, "--to", 1, "-o",
                     tmp_path / "rev.h5", "--csv", tmp_path / "rev.csv", *args)
    assert rc == 0, err
    py = gs.rev(f, to=g, cell_d50=2, step_d50=1)
    cells, attrs, dims = cli_cells(tmp_path / "rev.h5")
    assert py["mode"] == "3d" and attrs["mode"] in ("3d", b"3d")
    np.testing.assert_array_equal(py["grid"]["dims"], dims)
    assert set(cells) == set(py["cells"])
    for k, v in cells.items():
        np.testing.assert_array_equal(py["cells"][k].reshape(v.shape), v, err_msg=k)
    for k in ("d50", "cell", "step"):
        assert py[k] == attrs[k]
    # By hand: void ratio e = (V_cell - V_s) / V_s of each cell with solids, V_cell = L^3.
    c = py["cells"]
    solid = c["solid_volume"] > 0
    np.testing.assert_allclose(c["void_ratio"][solid],
                               py["cell"] ** 3 / c["solid_volume"][solid] - 1.0, rtol=1e-12)
    assert c["stress"].shape == (len(c["p"]), 3, 3) and c["displacement"].shape[1] == 3
    assert np.abs(c["displacement"]).max() > 0
    # cells reshaped to dims[::-1] index [k, j, i]: centres increase along i.
    cx = c["centre"][:, 0].reshape(tuple(py["grid"]["dims"][::-1]))
    assert np.all(np.diff(cx, axis=2) > 0)


def test_rev_gaussian_slab_and_profile_equal_the_cli(cli, tmp_path):
    p = packing(n=300, seed=9)
    f = gs.Frame.from_arrays(**p)
    gs.save(tmp_path / "p.h5", f)
    line = [0.001, 0.005, 0.002, 0.009, 0.005, 0.008]
    rc, _, err = cli("analyze", "rev", tmp_path / "p.h5", "--method", "gaussian", "--slab",
                     "--slab-d50", 3, "--width-d50", 0.7, "--step-d50", 0.5, "-o",
                     tmp_path / "g.h5", "--csv", tmp_path / "prof.csv", "--profile", *line,
                     "--profile-points", 17)
    assert rc == 0, err
    py = gs.rev(f, method="gaussian", slab=True, slab_d50=3, width_d50=0.7, step_d50=0.5,
                profile=line, profile_points=17)
    cells, attrs, _ = cli_cells(tmp_path / "g.h5")
    assert py["mode"] == "slab" and py["width"] == attrs["width"]
    for k, v in cells.items():
        np.testing.assert_array_equal(py["cells"][k].reshape(v.shape), v, err_msg=k)
    with open(tmp_path / "prof.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 17 == len(py["profile"]["distance"])
    got = np.array([[float(r["density"]), float(r["p"]), float(r["distance"])] for r in rows])
    want = np.stack([py["profile"]["density"], py["profile"]["p"], py["profile"]["distance"]], 1)
    np.testing.assert_allclose(got, want, rtol=1e-11, atol=0)  # the CSV has 12 digits


def test_shearzone_of_a_band_equals_the_cli(cli, tmp_path):
    d = 1e-3
    x, r = lattice(d=d)
    centre = np.array([12e-3, 2e-3, 12e-3])
    f = gs.Frame.from_arrays(x, r)
    g = gs.Frame.from_arrays(x + band_motion(x, 30.0, centre, 4 * d, 0.05), r, time=1.0)
    gs.save(tmp_path / "band.h5", [f, g])
    rc, _, err = cli("analyze", "shearzone", tmp_path / "band.h5", "--frame", 0, "--to", 1,
                     "--field", "shear", "--cell-d50", 3, "--slab-d50", 4, "-o", tmp_path / "s.h5")
    assert rc == 0, err
    py = gs.shearzone(f, to=g, field="shear", cell_d50=3, slab_d50=4)
    with h5py.File(tmp_path / "s.h5", "r") as h:
        for k in ("inclination_deg", "angle_deg", "thickness_m", "lower_m", "upper_m",
                  "peak_value"):
            assert h.attrs[k] == py[k], k
        np.testing.assert_array_equal(h["map/value"][()], py["map"]["value"])
        np.testing.assert_array_equal(h["ridge/points"][()], py["ridge"]["points"])
        np.testing.assert_array_equal(h["profile/value"][()], py["profile"]["value"])
    # The band's own geometry: 30 degrees, 4 d wide, smeared by the 3 d REV cells.
    assert abs(py["inclination_deg"]) == pytest.approx(30.0, abs=3.0)
    assert 2 * d < py["thickness_m"] < 8 * d


def test_map_errors_are_the_cli_lines():
    f = gs.Frame.from_arrays(**packing(n=50))
    with pytest.raises(gs.Error, match=r"^<frame>: --method must be box or gaussian \(boxes\)$"):
        gs.rev(f, method="boxes")
    with pytest.raises(gs.Error, match=r"^<frame>: --profile needs two distinct finite points$"):
        gs.rev(f, cell_d50=2, profile=[0, 0, 0, 0, 0, 0])
    with pytest.raises(gs.Error, match=r"--region is for 3D grids"):
        gs.rev(f, slab=True, region=[0, 0, 0, 1, 1, 1])
    with pytest.raises(gs.Error, match=r"^<frame>: --field shear needs a displacement"):
        gs.shearzone(f, field="shear")
    with pytest.raises(gs.Error, match=r"--cell"):
        gs.rev(f, cell=-1.0)
