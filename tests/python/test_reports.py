"""The scene reports from Python (silo, interface, materials) give the CLI's numbers."""
import csv

import h5py
import numpy as np
import pytest

import granoscope as gs

# 120 grains in a 20 x 30 x 7.5 mm silo with R_n = 1 teeth, filled in two layers, then the
# bottom moved down 1 mm (the CLI test's quasi-static silo, tests/apps/test_silo.cpp).
SILO = """[scene]
name = "silo"
test = "silo"
[material]
young_Pa = 1.0e7
stiffness_ratio = 0.3
friction_deg = 25.0
density_kg_m3 = 2600.0
rolling_stiffness = 0.2
rolling_limit = 0.4
[solver]
dt_s = "auto"
dt_safety = 0.5
damping = 0.3
gravity_m_s2 = [0.0, 0.0, -9.81]
[output]
every = 5000
history_every = 1000
curve_every = 200
checkpoint_every = 20000
[fill]
region_lo_m = [0.0021, 0.0, 0.012]
region_hi_m = [0.0179, 0.0075, 0.03]
layers = 2
count = 120
dmin_m = 0.0015
dmax_m = 0.0025
distribution = "linear"
seed = 1
[silo]
width_m = 0.02
height_m = 0.03
depth_m = 0.0075
roughness = 1.0
mode = "quasi_static"
bottom_velocity_m_s = 0.005
bottom_travel_m = 0.001
frame_every_m = 0.00025
"""


def test_silo_of_a_simulated_silo_equals_the_cli(cli, tmp_path):
    (tmp_path / "silo.toml").write_text(SILO)
    run = gs.Scene(tmp_path / "silo.toml").run(tmp_path / "out")
    assert run.ended and run.curve()["G_N"][0] > 0
    traj = run.trajectory
    t0 = run.curve()["time_s"][0]  # the end of the filling: the initial state
    rc, _, err = cli("analyze", "silo", traj, "-o", tmp_path / "s.h5", "--layer-bin-d50", 1,
                     "--from-time", repr(t0))
    assert rc == 0, err
    py = gs.silo(run.open(), layer_bin_d50=1, from_time=t0)
    assert py["from_frame"] > 0
    with h5py.File(tmp_path / "s.h5", "r") as h:
        assert h.attrs["d50"] == py["d50"]
        for name, v in py["series"].items():
            np.testing.assert_array_equal(h["series"][name][()], v, err_msg=name)
        for st in py["states"]:
            g = h["profiles"][st["name"]]
            assert g.attrs["frame"] == st["frame"]
            for k in ("sigma11_left_Pa", "sigma21_right_Pa", "height_m"):
                np.testing.assert_array_equal(g[k][()], st["profile"][k], err_msg=k)
            np.testing.assert_array_equal(g["zone_rotation_rad"][()], st["zone"]["rotation_rad"])
            for k in ("extent_left_m", "extent_right_m", "core_rad"):
                np.testing.assert_array_equal(g.attrs["zone_" + k], st["zone"][k], err_msg=k)
            assert g.attrs["P_G_en1991"] == st["P_G_en1991"] or np.isnan(st["P_G_en1991"])
    # The weight is carried by the bottom and the walls: (P + T_left + T_right) / G = 1 at rest
    # (seed 004 §5.3.1), the balance column the report computes.
    s = py["series"]
    np.testing.assert_allclose(s["balance_G"], s["P_G"] + s["T_left_G"] + s["T_right_G"],
                               rtol=1e-12)
    assert s["balance_G"][0] == pytest.approx(1.0, abs=0.03)
    assert [st["name"] for st in py["states"]] == ["initial", "maximum", "residual"]
    with pytest.raises(gs.Error, match=r"^<trajectory>: --phi-i: not in \(0, 90\) deg \(95\)$"):
        gs.silo(run.open(), phi_i=95.0)
    # The seed's REV cells for the wall zones (5 d50 moved by d50), as the CLI's option.
    rc, _, err = cli("analyze", "silo", traj, "-o", tmp_path / "w.h5", "--zone-window-d50", 5,
                     "--from-time", repr(t0))
    assert rc == 0, err
    win = gs.silo(run.open(), zone_window_d50=5, from_time=t0)["states"][-1]["zone"]
    with h5py.File(tmp_path / "w.h5", "r") as h:
        g = h["profiles"]["residual"]
        np.testing.assert_array_equal(g["zone_rotation_rad"][()], win["rotation_rad"])
        np.testing.assert_array_equal(g["zone_across_m"][()], win["across_m"])
    step = np.diff(win["across_m"])
    np.testing.assert_allclose(step, py["d50"], rtol=1e-9)
    assert len(win["across_m"]) != len(py["states"][-1]["zone"]["across_m"])


def sheared_block(gamma=0.02, n=(20, 3, 12), d=1e-3, surface=0.0):
    """A cubic lattice of spheres above z = surface, then the same sheared u_x = gamma (z - z0)
    plus a rigid slide of 2 d."""
    g = np.stack(np.meshgrid(*[np.arange(k) for k in n], indexing="ij"), -1).reshape(-1, 3)
    x = (g + 0.5) * d + [0, 0, surface]
    u = np.zeros_like(x)
    u[:, 0] = gamma * (x[:, 2] - surface) + 2 * d
    r = np.full(len(x), 0.5 * d)
    return gs.Frame.from_arrays(x, r), gs.Frame.from_arrays(x + u, r, time=1.0)


def test_interface_equals_the_cli(cli, tmp_path):
    a, b = sheared_block()
    gs.save(tmp_path / "is.h5", [a, b])
    rc, _, err = cli("analyze", "interface", tmp_path / "is.h5", "--surface-z", 0.0, "-o",
                     tmp_path / "i.h5")
    assert rc == 0, err
    py = gs.interface(gs.open(tmp_path / "is.h5"), surface_z=0.0)
    with h5py.File(tmp_path / "i.h5", "r") as h:
        for k in ("u_top_m", "u_surface_m", "slip_ratio", "x_lo_m", "bin"):
            assert h.attrs[k] == py[k], k
        np.testing.assert_array_equal(h["displacement_x_m"][()], py["displacement_x_m"])
        np.testing.assert_array_equal(h["count"][()], py["count"])
    # By hand: bins of 1 d50 hold one layer each; the displacement of a layer at height z is
    # gamma z + 2 d, so the top's is gamma (11.5 d) + 2 d and the surface bin's gamma (0.5 d) + 2 d.
    d = 1e-3
    assert py["u_top_m"] == pytest.approx(0.02 * 11.5 * d + 2 * d, rel=1e-12)
    assert py["u_surface_m"] == pytest.approx(0.02 * 0.5 * d + 2 * d, rel=1e-12)
    with pytest.raises(gs.Error, match=r"^<trajectory>: --surface-z: needed"):
        gs.interface([a, b])


def test_materials_equal_the_cli(cli, tmp_path):
    rng = np.random.default_rng(1)
    frames = []
    for k in range(3):
        x = rng.uniform(-0.01, 0.01, size=(50, 3))
        frames.append(gs.Frame.from_arrays(x, np.full(50, 5e-4), material_ids=np.arange(50) % 2,
                                           masses=np.full(50, 1e-6), time=0.1 * k, step=10 * k))
    gs.save(tmp_path / "m.h5", frames)
    rc, _, err = cli("analyze", "materials", tmp_path / "m.h5", "--drum", "--zone",
                     "top:-inf,-inf,0,inf,inf,inf", "-o", tmp_path / "m.csv")
    assert rc == 0, err
    py = gs.materials(gs.open(tmp_path / "m.h5"), drum=True, zones=["top:-inf,-inf,0,inf,inf,inf"])
    with open(tmp_path / "m.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0].keys()) == list(py.keys())
    for name, v in py.items():
        np.testing.assert_allclose([float(r[name]) for r in rows], v, rtol=1e-11, err_msg=name)
    # By hand: material 1 is the odd particles; its count in the x+z- quadrant and its centre.
    x = frames[2].positions
    odd = np.arange(50) % 2 == 1
    assert py["material1_count"][2] == 25
    assert py["x+z-_material1_count"][2] == np.sum(odd & (x[:, 0] > 0) & (x[:, 2] < 0))
    assert py["material1_com_x_m"][2] == pytest.approx(x[odd, 0].mean(), rel=1e-12)


# Dimers (seed 003 §2.4, scaled down) deposited in a 5 mm box, the n = 8 polyhedron of
# R = 1.5 mm carved out, consolidated to 100 kPa, sheared to eta = 0.3 and sigma_1 turned by 18
# degrees (the CLI test's small specimen, tests/apps/test_stress_rotation.cpp).
ROTATION = """[scene]
name = "sr"
test = "stress_rotation"
[specimen]
size_m = [0.005, 0.005, 0.0052]
dmin_m = 0.0005
dmax_m = 0.0007
void_ratio = 0.6
seed = 1
cloud_solid_fraction = 0.35
[material]
normal_stiffness_N_m = 1.0e5
stiffness_ratio = 1.0
friction_deg = 26.56505117707799
density_kg_m3 = 2700.0
[[clump_template]]
name = "dimer"
shape = "dimer"
member_radius_m = 0.0003
[clumps]
replace = "dimer"
mass = "union"
seed = 1
[solver]
dt_s = "auto"
dt_safety = 0.5
threads = 1
[stress_rotation]
radius_m = 0.0015
p_Pa = 1.0e5
eta = 0.3
eta_step = 0.1
alpha_step_deg = 3.0
cycles = 0.1
frame_every_deg = 6.0
deposition_gravity_m_s2 = [0.0, 0.0, -5000.0]
deposition_damping = 0.5
deposition_tolerance = 5e-3
tolerance = 5e-3
stress_tolerance = 0.02
min_stage_steps = 500
servo_max_strain_step = 1e-5
[output]
every = 100000
curve_every = 100
history_every = 1000
checkpoint_every = 100000
"""


def test_rotation_of_a_simulated_rotation_equals_the_cli(cli, tmp_path):
    (tmp_path / "sr.toml").write_text(ROTATION)
    run = gs.Scene(tmp_path / "sr.toml").run(tmp_path / "out")
    assert run.ended
    rc, out, err = cli("analyze", "rotation", run.trajectory, "-o", tmp_path / "rot")
    assert rc == 0, err
    py = gs.rotation(run.open(), run.curve_path)
    for table in ("strain", "increments", "fabric", "cycles"):
        with open(tmp_path / "rot" / f"rotation_{table}.csv") as f:
            rows = list(csv.DictReader(f))
        assert len(rows) == len(py[table]["alpha_deg" if table != "cycles" else "cycle"])
        for name, v in py[table].items():
            np.testing.assert_allclose([float(r[name]) for r in rows], v, rtol=1e-9,
                                       atol=1e-300, err_msg=f"{table}.{name}")
    # The path: 18 degrees in steps of 3, frames at 0, 6, 12 and 18 degrees and the end; the strains counted
    # from the rotation's start; D_ij deviatoric.
    assert py["strain"]["alpha_deg"][-1] == 18.0
    assert py["strain"]["eps_v"][0] == 0.0
    assert len(py["fabric"]["step"]) == 5  # and the last state
    assert py["fabric"]["alpha_deg"][0] == 0.0
    np.testing.assert_allclose(py["fabric"]["Dxx"] + py["fabric"]["Dyy"] + py["fabric"]["Dzz"],
                               0.0, atol=1e-12)
    # Windows of at least 3 degrees between curve rows (an increment shorter than curve_every
    # steps has no row of its own, and its window spans two).
    mids = py["increments"]["alpha_deg"]
    assert 4 <= len(mids) <= 6 and np.all(np.diff(mids) >= 3.0 - 1e-9) and mids[-1] <= 18.0
    with pytest.raises(gs.Error, match=r"window_deg must be positive"):
        gs.rotation(run.open(), run.curve_path, window_deg=0.0)
