"""Analyses from Python give the CLI's numbers on the same input."""
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
