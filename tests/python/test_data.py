"""Frames and trajectories from Python: numpy views, round trips through every writer, the
same counts as `granoscope info`, and one-line errors."""
import os

import numpy as np
import pytest

import granoscope as gs
from conftest import packing


def test_open_reads_what_info_reads(cli, source_dir):
    path = os.path.join(source_dir, "tests", "data", "trajectory_v1.h5")
    run = gs.open(path)
    rc, out, _ = cli("info", path)
    assert rc == 0
    assert len(run) == 2 and "frames:       2" in out
    f = run[-1]
    assert f.n_particles == 3 and f.n_contacts == 1 and f.n_walls == 1
    assert run.times == [0.0, 0.5]
    assert f.step == 1000
    assert f.positions.shape == (3, 3) and f.positions.dtype == np.float64
    # the bounding box `info` prints, from the arrays
    lo = (f.positions - f.radii[:, None]).min(axis=0)
    hi = (f.positions + f.radii[:, None]).max(axis=0)
    assert "[%.6g, %.6g, %.6g] .. [%.6g, %.6g, %.6g]" % (*lo, *hi) in out
    assert gs.d50(f) == pytest.approx(0.002, rel=1e-12)


def test_other_formats(source_dir):
    yade = gs.open(os.path.join(source_dir, "tests", "data", "yade",
                                "yade_export-spheres-00000000.vtk"))
    assert yade.format.startswith("YADE") and yade[0].n_particles > 0 and yade[0].n_contacts > 0
    lig = gs.open(os.path.join(source_dir, "tests", "data", "liggghts", "dump.atoms"), dt=1e-5)
    assert lig[0].n_particles > 0
    csv = gs.open(os.path.join(source_dir, "tests", "data", "packing_small.csv"))
    assert len(csv) == 1 and csv[0].n_particles > 0


def test_fields_are_views_of_the_frame():
    f = gs.Frame.from_arrays(**packing())
    p = f.positions
    assert not p.flags.owndata and p.flags.writeable
    p[0, 0] = 0.123
    assert f.positions[0, 0] == 0.123  # the frame itself changed
    # one array of particles, strided views: interleaved, never the same bytes
    assert np.may_share_memory(f.positions, f.radii) and not np.shares_memory(f.positions, f.radii)
    # a view keeps its frame alive
    r = gs.Frame.from_arrays(**packing()).radii
    assert r.shape == (60,) and np.all(r > 0)
    # contacts: ids as the pairs given, normals unit
    f = gs.Frame.from_arrays(**packing())
    ids = f.contact_ids
    assert ids.dtype == np.int64 and ids.shape == (f.n_contacts, 2)
    np.testing.assert_allclose(np.linalg.norm(f.contact_normals, axis=1), 1.0, rtol=1e-14)


@pytest.mark.parametrize("ext", [".h5", ".vtu", ".csv", ".pvd"])
def test_round_trip_through_every_writer(tmp_path, ext):
    a = packing()
    f = gs.Frame.from_arrays(**a, velocities=np.full((60, 3), 0.25), time=1.5, step=42)
    path = tmp_path / ("run" + ext)
    gs.save(path, f)
    g = gs.open(path)[0]
    assert g.n_particles == 60
    np.testing.assert_array_equal(g.positions, a["positions"])  # bit for bit, every format
    np.testing.assert_array_equal(g.radii, a["radii"])
    if ext != ".csv":  # the packing CSV holds particles only
        assert g.n_contacts == f.n_contacts
        np.testing.assert_array_equal(g.contact_ids, f.contact_ids)
        np.testing.assert_array_equal(g.normal_forces, f.normal_forces)
        np.testing.assert_array_equal(g.velocities, f.velocities)


def test_integer_fields_stay_exact(tmp_path):
    big = np.array([2**60 + 1, 2**60 + 3], dtype=np.int64)  # not representable as doubles
    f = gs.Frame.from_arrays(np.array([[0.0, 0, 0], [3.0, 0, 0]]), np.ones(2), ids=big,
                             clump_ids=big - 1, contact_ids=big[None, :],
                             contact_normals=np.array([[1.0, 0, 0]]))
    np.testing.assert_array_equal(f.ids, big)
    np.testing.assert_array_equal(f.clump_ids, big - 1)
    np.testing.assert_array_equal(f.contact_ids, big[None, :])
    gs.save(tmp_path / "big.h5", f)
    np.testing.assert_array_equal(gs.open(tmp_path / "big.h5")[0].ids, big)
    with pytest.raises(gs.Error, match="material_ids must be in"):
        gs.Frame.from_arrays(np.zeros((1, 3)), np.ones(1), material_ids=np.array([2**40]))


def test_trajectory_of_frames_saves_all(tmp_path):
    frames = []
    for k in range(3):
        a = packing(seed=k)
        frames.append(gs.Frame.from_arrays(a["positions"], a["radii"], time=0.1 * k, step=k))
    gs.save(tmp_path / "t.h5", gs.Trajectory(frames))
    run = gs.open(tmp_path / "t.h5")
    assert len(run) == 3 and run.times == pytest.approx([0.0, 0.1, 0.2])
    np.testing.assert_array_equal(run[1].positions, frames[1].positions)
    assert "Python" in run.provenance


def test_missing_file_has_the_cli_message(cli, tmp_path):
    missing = tmp_path / "nope.h5"
    with pytest.raises(gs.FileNotFound) as e:
        gs.open(missing)
    assert isinstance(e.value, FileNotFoundError) and isinstance(e.value, gs.Error)
    rc, _, err = cli("info", missing)
    assert rc == 2 and err == "error: " + str(e.value) + "\n"


def test_bad_file_has_the_cli_message(cli, tmp_path):
    bad = tmp_path / "bad.h5"
    bad.write_text("not hdf5")
    with pytest.raises(gs.Error) as e:
        gs.open(bad)
    assert isinstance(e.value, ValueError)
    rc, _, err = cli("info", bad)
    assert rc == 2 and err == "error: " + str(e.value) + "\n"


def test_bad_arrays_raise_one_line_errors():
    a = packing()
    with pytest.raises(gs.Error, match=r"^<arrays>: radii has the wrong shape \(shape \(59,\), expected \(60,\)\)$"):
        gs.Frame.from_arrays(a["positions"], a["radii"][:-1])
    with pytest.raises(gs.Error, match="positions must be an"):
        gs.Frame.from_arrays(np.zeros((4, 2)), np.ones(4))
    r = a["radii"].copy()
    r[3] = -1.0
    with pytest.raises(gs.Error, match="radius"):
        gs.Frame.from_arrays(a["positions"], r)
    with pytest.raises(gs.Error, match="contact fields given without contact_ids"):
        gs.Frame.from_arrays(a["positions"], a["radii"], overlaps=np.zeros(3))
    with pytest.raises(IndexError):
        gs.Trajectory([gs.Frame.from_arrays(a["positions"], a["radii"])])[5]
