"""Analyses from Python give the CLI's numbers on the same input."""
import os

import h5py
import numpy as np
import pytest

import granoscope as gs
from conftest import packing


def test_fabric_equals_the_cli_bit_for_bit(cli, tmp_path):
    f = gs.Frame.from_arrays(**packing(n=120))
    gs.save(tmp_path / "p.h5", f)
    rc, out, err = cli("analyze", "fabric", tmp_path / "p.h5", "-o", tmp_path / "fab.h5")
    assert rc == 0, err
    py = gs.fabric(f)
    with h5py.File(tmp_path / "fab.h5", "r") as h:
        assert h.attrs["omega"] == py["omega"]
        assert h.attrs["D_norm"] == py["D_norm"]
        assert h.attrs["contacts"] == py["contacts"]
        assert h.attrs["particles"] == py["particles"]
        np.testing.assert_array_equal(h["M"][()], py["M"])
        np.testing.assert_array_equal(h["D"][()], py["D"])
        np.testing.assert_array_equal(h["D_principal"][()], py["D_principal"])
    # By hand (seed 003 eq 20, each contact counted from both sides): M = 2/N_p sum n n^T,
    # omega = trace M = 2 N_c / N_p.
    n = f.contact_normals
    np.testing.assert_allclose(py["M"], 2.0 * n.T @ n / f.n_particles, rtol=1e-12)
    assert py["omega"] == pytest.approx(2.0 * f.n_contacts / f.n_particles, rel=1e-14)
    assert np.trace(py["M"]) == pytest.approx(py["omega"], rel=1e-14)


def test_stress_invariants_by_hand():
    s = gs.stress_invariants(np.diag([300e3, 100e3, 100e3]))  # triaxial compression
    assert s["p"] == pytest.approx(500e3 / 3)
    assert s["q"] == pytest.approx(200e3)
    assert s["b"] == pytest.approx(0.0, abs=1e-15)
    np.testing.assert_allclose(s["principal"], [300e3, 100e3, 100e3])
    iso = gs.stress_invariants(np.eye(3) * 50e3)
    assert iso["q"] == pytest.approx(0.0, abs=1e-9) and iso["p"] == pytest.approx(50e3)
    with pytest.raises(gs.Error, match="^dim: must be 2 or 3 \\(4\\)$"):
        gs.stress_invariants(np.eye(3), dim=4)


def test_fabric_and_rose_with_a_selection_equal_the_cli(cli, tmp_path):
    """The selection keywords are the CLI's --slab* / --region options, same numbers."""
    f = gs.Frame.from_arrays(**packing(n=160, seed=7))
    gs.save(tmp_path / "p.h5", f)
    region = [0.001, 0.001, 0.001, 0.009, 0.009, 0.009]
    rc, _, err = cli("analyze", "fabric", tmp_path / "p.h5", "-o", tmp_path / "fab.h5",
                     "--region", *region)
    assert rc == 0, err
    py = gs.fabric(f, region=region)
    with h5py.File(tmp_path / "fab.h5", "r") as h:
        assert h.attrs["omega"] == py["omega"] and h.attrs["particles"] == py["particles"]
        np.testing.assert_array_equal(h["D"][()], py["D"])
        np.testing.assert_array_equal(h["view_axes"][()], py["view_axes"])
    assert py["particles"] < f.n_particles  # the region did select
    args = ["--slab", "--slab-d50", 3, "--bin-deg", 15, "--3d", "--bins3d", 6, 12]
    rc, _, err = cli("analyze", "rose", tmp_path / "p.h5", "-o", tmp_path / "rose.h5", *args)
    assert rc == 0, err
    r = gs.rose(f, slab=True, slab_d50=3, bin_deg=15, three_d=True, bins3d=(6, 12))
    with h5py.File(tmp_path / "rose.h5", "r") as h:
        for key in ("angle_deg", "count", "density", "mean_fn", "mean_fs"):
            np.testing.assert_array_equal(h["rose2d/" + key][()], r["rose2d"][key], err_msg=key)
        np.testing.assert_array_equal(h["rose2d/axes"][()], r["axes"])
        assert h["rose2d"].attrs["contacts"] == r["rose2d"]["contacts"]
        for key in ("direction", "count", "mean_fn"):
            np.testing.assert_array_equal(h["rose3d/" + key][()], r["rose3d"][key], err_msg=key)
    # every contact counted once in the 2D rose (those normal to the plane skipped)
    assert sum(r["rose2d"]["count"]) + r["rose2d"]["skipped"] == r["rose2d"]["contacts"]


def test_contact_analysis_errors_are_the_cli_lines():
    f = gs.Frame.from_arrays(**packing())
    with pytest.raises(gs.Error, match=r"^<frame>: --bin-deg must divide 360 into 2 or more bins \(7\)$"):
        gs.rose(f, bin_deg=7)
    with pytest.raises(gs.Error, match="--region needs finite x0 y0 z0 x1 y1 z1"):
        gs.fabric(f, region=[0, 0, 0, -1, 1, 1])
    with pytest.raises(gs.Error, match="--region needs 6 numbers"):
        gs.fabric(f, region=[0, 0, 0])
    with pytest.raises(gs.Error, match="^<frame>: --d50 must be a finite number > 0"):
        gs.fabric(f, slab=True, d50=-1.0)
    with pytest.raises(gs.Error, match="no contact in the selection"):
        gs.rose(f, region=[1, 1, 1, 2, 2, 2])


def test_chains_equal_the_cli(cli, tmp_path):
    f = gs.Frame.from_arrays(**packing(n=160, seed=11))
    gs.save(tmp_path / "p.h5", f)
    rc, _, err = cli("analyze", "chains", tmp_path / "p.h5", "-o", tmp_path / "c.h5",
                     "--mean-factor", 1.5, "--slab", "--slab-d50", 4)
    assert rc == 0, err
    c = gs.chains(f, mean_factor=1.5, slab=True, slab_d50=4)
    with h5py.File(tmp_path / "c.h5", "r") as h:
        for key in ("mean_fn", "max_fn", "threshold"):
            assert h.attrs[key] == c[key], key
        assert h.attrs["strong"] == c["strong_count"] and h.attrs["chains"] == c["chains"]
        np.testing.assert_array_equal(h["segments/a"][()], c["a"])
        np.testing.assert_array_equal(h["segments/fn"][()], c["fn"])
        np.testing.assert_array_equal(h["segments/strong"][()].astype(bool), c["strong"])
        np.testing.assert_array_equal(h["segments/chain"][()], c["chain"])
    # by hand: strong = |Fn| above 1.5 x the mean over the selected contacts
    assert c["threshold"] == pytest.approx(1.5 * np.mean(c["fn"]), rel=1e-14)
    np.testing.assert_array_equal(c["strong"], np.asarray(c["fn"]) > c["threshold"])
    with pytest.raises(gs.Error, match=r"^<frame>: --threshold must be a force >= 0 in N \(-2\)$"):
        gs.chains(f, threshold=-2.0)


def test_walls_equal_the_cli(cli, source_dir, tmp_path):
    """The YADE oedometer scene (883 spheres between six walls), 1000 steps, last frame."""
    scene = os.path.join(source_dir, "data", "scenes", "oedometer_yade.toml")
    rc, _, err = cli("simulate", scene, "--steps", 1000, "-q", "-o", tmp_path / "run")
    assert rc == 0, err
    run = tmp_path / "run" / "oedometer_yade.h5"
    rc, _, err = cli("analyze", "walls", run, "-o", tmp_path / "w.h5", "--bin-d50", 3)
    assert rc == 0, err
    w = gs.walls(gs.open(run)[-1], bin_d50=3)
    with h5py.File(tmp_path / "w.h5", "r") as h:
        for key in ("P", "T", "N", "G", "phi_w_deg", "bin"):
            assert h.attrs[key] == w[key] or (np.isnan(h.attrs[key]) and np.isnan(w[key])), key
        assert len(h["walls"]) == len(w["walls"]) > 0
        for k, wall in enumerate(w["walls"]):
            g = h["walls/%d" % k]
            role = g.attrs["role"]
            assert (role.decode() if isinstance(role, bytes) else role) == wall["role"]
            assert g.attrs["contacts"] == wall["contacts"] > 0
            np.testing.assert_array_equal(g["sigma_n"][()], wall["sigma_n"])
            np.testing.assert_array_equal(g["force"][()], wall["force"])
    with pytest.raises(gs.Error, match=r"^<frame>: --gravity must be a finite number > 0 \(0\)$"):
        gs.walls(gs.open(run)[-1], gravity=0.0)


def test_invariants_equal_the_cli(cli, source_dir, tmp_path):
    """Specimen stress (with the walls' eq 14) and the fitted F between two frames."""
    scene = os.path.join(source_dir, "data", "scenes", "oedometer_yade.toml")
    rc, _, err = cli("simulate", scene, "--steps", 2000, "-q", "-o", tmp_path / "run")
    assert rc == 0, err
    run = tmp_path / "run" / "oedometer_yade.h5"
    rc, _, err = cli("analyze", "invariants", run, "--frame", 0, "--to", -1, "-o",
                     tmp_path / "i.h5")
    assert rc == 0, err
    t = gs.open(run)
    py = gs.invariants(t[0], to=t[-1])
    with h5py.File(tmp_path / "i.h5", "r") as h:
        np.testing.assert_array_equal(h["stress/tensor"][()], py["stress"]["tensor"])
        assert ("boundary_eq14" in h["stress"]) == ("boundary_eq14" in py["stress"])
        for key in ("p", "q", "volume"):
            assert h["stress"].attrs[key] == py["stress"][key], key
        np.testing.assert_array_equal(h["strain/F"][()], py["strain"]["F"])
        assert h["strain"].attrs["eps_v"] == py["strain"]["eps_v"]
    # the last frame, with contacts on the walls: seed 003 eq 14 as well
    rc, _, err = cli("analyze", "invariants", run, "-o", tmp_path / "j.h5")
    assert rc == 0, err
    last = gs.invariants(t[-1])["stress"]
    with h5py.File(tmp_path / "j.h5", "r") as h:
        np.testing.assert_array_equal(h["stress/tensor"][()], last["tensor"])
        np.testing.assert_array_equal(h["stress/boundary_eq14"][()], last["boundary_eq14"])
    # a given tensor: its invariants, no frame needed
    s = gs.invariants(stress=np.diag([2.0, 1.0, 1.0]))["stress"]
    assert s["q"] == pytest.approx(1.0) and s["p"] == pytest.approx(4.0 / 3.0)
    with pytest.raises(gs.Error, match="^<frame>: nothing to evaluate$"):
        gs.invariants()
