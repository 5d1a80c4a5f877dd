"""Scenes from Python: values set over the file, runs equal to `granoscope simulate`, progress,
stop and resume bit for bit, Ctrl-C."""
import os
import signal
import threading

import numpy as np
import pytest

import granoscope as gs


@pytest.fixture
def oedometer(source_dir):
    return os.path.join(source_dir, "data", "scenes", "oedometer_yade.toml")


def read(path):
    with open(path, "rb") as fh:
        return fh.read()


def test_scene_values_can_be_read_and_set(oedometer):
    sc = gs.Scene(oedometer)
    assert sc.name == "oedometer_yade" and sc.test == "" and sc.particles == 883
    assert sc["solver.dt_s"] == 1e-6 and sc["solver.gravity_m_s2"] == [0.0, 0.0, -9.81]
    assert sc["walls"][0]["name"] == "bottom"
    sc["solver.dt_s"] = 5e-7
    sc["walls.0.name"] = "floor"
    sc["output.every"] = 250
    assert sc.dt == 5e-7 and sc["walls"][0]["name"] == "floor" and sc["output.every"] == 250
    import tomllib
    assert tomllib.loads(sc.toml)["solver"]["dt_s"] == 5e-7  # the scene as it will run
    # Checked at once, with the CLI's message; a rejected value leaves the scene as it was.
    with pytest.raises(gs.Error, match=r"oedometer_yade.toml: solver\.dt_s: "):
        sc["solver.dt_s"] = -1.0
    assert sc.dt == 5e-7
    with pytest.raises(gs.Error, match=r"walls\.9\.name: no such element \(9\)"):
        sc["walls.9.name"] = "x"
    with pytest.raises(gs.Error, match=r"\[nonsense\]: unknown section"):
        sc["nonsense.key"] = 1
    with pytest.raises(gs.FileNotFound):
        gs.Scene("no/such/scene.toml")


def test_a_run_is_the_cli_run(cli, oedometer, tmp_path):
    rc, _, err = cli("simulate", oedometer, "--steps", 600, "-q", "-o", tmp_path / "cli")
    assert rc == 0, err
    seen = []
    run = gs.Scene(oedometer).run(tmp_path / "py", steps=600, every=100,
                                  progress=lambda p: seen.append((p["step"], p["fraction"])))
    assert run.stopped is False and run.step == 600 and run.steps_run == 600
    assert read(tmp_path / "cli" / "history.csv") == read(run.history_path)
    a, b = gs.open(tmp_path / "cli" / "oedometer_yade.h5"), run.open()
    assert len(a) == len(b) == 2
    np.testing.assert_array_equal(a[-1].positions, b[-1].positions)
    np.testing.assert_array_equal(a[-1].normal_forces, b[-1].normal_forces)
    # Progress: the start, then every 100 steps, fractions of the 600 steps.
    assert [s for s, _ in seen] == [0, 100, 200, 300, 400, 500, 600]
    assert seen[-1][1] == pytest.approx(1.0)
    h = run.history()
    assert h["step"][-1] == 600 and len(h["kinetic_J"]) == 7


def test_stop_and_resume_is_bit_for_bit(oedometer, tmp_path):
    sc = gs.Scene(oedometer)
    sc["output.every"] = 200
    sc["output.checkpoint_every"] = 1000
    whole = sc.run(tmp_path / "whole", steps=800)
    part = sc.run(tmp_path / "part", steps=800, every=50,
                  progress=lambda p: p["step"] < 350)  # False at step 350: stop there
    assert part.stopped and part.step == 350 and not os.path.exists(part.trajectory)
    assert part.history()["step"][-1] == 300  # (rows every 100 steps; the partial file)
    rest = sc.run(tmp_path / "part", steps=800, resume=True)
    assert not rest.stopped and rest.step == 800 and rest.steps_run == 450
    assert read(whole.history_path) == read(rest.history_path)
    a, b = whole.open(), rest.open()
    assert len(a) == len(b) == 5
    for k in range(5):
        np.testing.assert_array_equal(a[k].positions, b[k].positions)
        np.testing.assert_array_equal(a[k].velocities, b[k].velocities)
    # A resume of a finished run runs nothing.
    again = sc.run(tmp_path / "part", steps=800, resume=True)
    assert again.was_complete and again.steps_run == 0
    # A changed scene is not resumed into a run of another.
    sc["material.friction_deg"] = 25.0
    part2 = gs.Scene(oedometer).run(tmp_path / "p2", steps=800, progress=lambda p: p["step"] < 100)
    assert part2.stopped
    with pytest.raises(gs.Error, match="scene differs from the run being resumed"):
        sc.run(tmp_path / "p2", steps=800, resume=True)


def test_ctrl_c_stops_after_a_checkpoint(oedometer, tmp_path):
    sc = gs.Scene(oedometer)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        sc.run(tmp_path / "run", steps=2_000_000)
    timer.join()
    assert os.path.exists(tmp_path / "run" / "checkpoint.txt")
    rest = sc.run(tmp_path / "run", steps=0, resume=True)  # stops at once: nothing more to do
    assert rest.step > 0


def test_a_tqdm_bar_follows_the_run(oedometer, tmp_path):
    """The progress callback drives a tqdm bar (Debian's python3-tqdm) as it is: bar.update's
    return value (True or None) does not stop the run."""
    import io
    import tqdm
    out = io.StringIO()
    bar = tqdm.tqdm(total=400, file=out, mininterval=0)
    run = gs.Scene(oedometer).run(tmp_path / "run", steps=400, every=100,
                                  progress=lambda p: bar.update(p["step"] - bar.n))
    bar.close()
    assert not run.stopped and run.step == 400 and bar.n == 400
    assert "400/400" in out.getvalue()
    # By fraction (a laboratory test's steps are not known beforehand), as docs/python.md shows.
    bar = tqdm.tqdm(total=100, unit="%", file=io.StringIO(), mininterval=0)
    gs.Scene(oedometer).run(tmp_path / "run2", steps=400, every=100,
                            progress=lambda p: bar.update(100 * p["fraction"] - bar.n))
    assert bar.n == pytest.approx(100)
