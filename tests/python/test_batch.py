# rm3d.Batch: worlds stepped by C++ threads are the same worlds stepped one by one, bit for bit;
# different bodies in one batch; reset(mask); rm3d.evaluate.
import numpy as np
import pytest

import rm3d
from conftest import HERE, ROOT

SNAKE = str(ROOT / "worlds" / "snake.lua")
AGENTS = str(HERE / "worlds" / "agents.lua")
MIXED = str(HERE / "worlds" / "mixed.lua")


def drive(b, steps):
    for k in range(steps):
        b.act[..., 0] = 0.4 * np.sin(0.2 * k)
        b.step()
    return b.obs.copy(), b.reward.copy(), [s["modules"] for s in b.summaries()]


def test_batch_threads_equal_sequential_worlds():
    seeds = [1, 2, 3, 4, 5]
    params = [{"modules": m} for m in (3, 4, 5, 4, 3)]
    one = drive(rm3d.Batch(AGENTS, seeds=seeds, params=params, threads=1, policy=True), 40)
    two = drive(rm3d.Batch(AGENTS, seeds=seeds, params=params, threads=2, policy=True), 40)
    assert one[0].tobytes() == two[0].tobytes() and one[1].tobytes() == two[1].tobytes()
    assert one[2] == two[2]
    for i, (s, p) in enumerate(zip(seeds, params)):
        w = rm3d.World(AGENTS, seed=s, params=p, policy=True)
        for k in range(40):
            w.act[:, 0] = 0.4 * np.sin(0.2 * k)
            w.step()
        n = p["modules"]
        assert w.obs.tobytes() == one[0][i, :n].tobytes()
        assert w.summary()["modules"] == one[2][i]


def test_batch_of_different_bodies_has_a_mask():
    b = rm3d.Batch(MIXED, params=[{"wheelbots": 0}, {"wheelbots": 2}], threads=2)
    assert b.obs.shape[:2] == (2, 3)
    assert b.mask.tolist() == [[True, False, False], [True, True, True]]
    assert np.all(b.obs[0, 1:] == 0)
    b.step(10)
    assert list(b.time) == pytest.approx([10 / 60, 10 / 60])


def test_reset_mask_restarts_only_those_worlds():
    b = rm3d.Batch(SNAKE, seeds=[1, 2, 3], params={"modules": 3}, threads=2)
    start = b.obs.copy()
    b.step(30)
    moved = b.obs.copy()
    b.reset(np.array([False, True, False]))
    assert list(b.time) == pytest.approx([0.5, 0.0, 0.5])
    assert b.obs[1].tobytes() == start[1].tobytes()
    assert b.obs[0].tobytes() == moved[0].tobytes()
    with pytest.raises(ValueError, match=r"mask: expected a bool array of shape \(3,\)"):
        b.reset(np.array([True]))


def test_batch_errors():
    with pytest.raises(ValueError, match="seeds: 2 given for 3 worlds"):
        rm3d.Batch([SNAKE] * 3, seeds=[1, 2])
    with pytest.raises(rm3d.Error, match="world 1: .*no such file"):
        rm3d.Batch([SNAKE, "/no/such/world.lua"])
    b = rm3d.Batch(AGENTS, seeds=[1, 2], params={"modules": 3}, policy=True)
    b.act[1, 2, 0] = np.inf
    with pytest.raises(rm3d.Error, match=r"world 1: act\[2\]\[0\] is infinite"):
        b.step()
    # Checked before any world stepped: the batch stays in step (world 0 used to step alone).
    assert list(b.time) == [0.0, 0.0]
    b.act[1, 2, 0] = 0.1
    b.step()
    assert list(b.time) == pytest.approx([1 / 60, 1 / 60])
    b.close()
    with pytest.raises(rm3d.Error, match="closed"):
        b.step()


def test_evaluate_matches_single_runs():
    params = [{"modules": 4, "amplitude": a} for a in (0.3, 0.6)]
    got = rm3d.evaluate(SNAKE, params=params, seeds=[1, 2], seconds=1.0, threads=2, metric="speed_m_s")
    assert got.shape == (2, 2)
    for i, p in enumerate(params):
        for j, s in enumerate([1, 2]):
            w = rm3d.World(SNAKE, seed=s, params=p)
            w.step(60)
            assert w.finish()["metrics"]["speed_m_s"] == got[i, j]
    flat = rm3d.evaluate(SNAKE, params=params, seconds=1.0, metric="speed_m_s")
    assert flat.shape == (2,)


def test_evaluate_errors():
    with pytest.raises(TypeError, match="metric"):
        rm3d.evaluate(SNAKE, params=[{}])
    with pytest.raises(rm3d.Error, match="did not set the metric 'nope'"):
        rm3d.evaluate(SNAKE, params=[{"modules": 2}], seconds=0.1, metric="nope")
    with pytest.raises(rm3d.Error, match="no such file"):
        rm3d.evaluate("/no/such.lua", params=[{}], metric="x")
    with pytest.warns(RuntimeWarning, match="run 1"):
        r = rm3d.evaluate(SNAKE, params=[{"modules": 2}, {"modules": "many"}], seconds=0.1, metric="speed_m_s")
    assert np.isfinite(r[0]) and np.isnan(r[1])


def test_reset_restores_the_start_bit_for_bit_and_keeps_the_texts_it_was_made_from(tmp_path):
    # reset() restores each world's start snapshot: the worlds then run as fresh ones, bit for bit,
    # from the texts they were made from (an edit of the file after the batch was made is not read).
    world = tmp_path / "w.lua"
    world.write_text(open(SNAKE).read())
    b = rm3d.Batch(str(world), seeds=[1, 2], params={"modules": 3}, threads=2, policy=True)
    fresh = drive(rm3d.Batch(str(world), seeds=[1, 2], params={"modules": 3}, threads=1, policy=True), 25)
    drive(b, 40)
    world.write_text("world.spawn('superbot')\n")
    b.reset()
    assert list(b.time) == [0.0, 0.0] and len(b.summaries()[0]["modules"]) == 3
    again = drive(b, 25)
    assert again[0].tobytes() == fresh[0].tobytes() and again[1].tobytes() == fresh[1].tobytes()
    assert len(rm3d.Batch(str(world)).summaries()[0]["modules"]) == 1  # a new batch reads the file


def cube_obj(bottom, top):
    v = [(x, y, z) for z in (bottom, top) for y in (-0.1, 0.1) for x in (-0.1, 0.1)]
    faces = [(1, 3, 4, 2), (5, 6, 8, 7), (1, 2, 6, 5), (3, 7, 8, 4), (1, 5, 7, 3), (2, 4, 8, 6)]
    return "".join("v %g %g %g\n" % p for p in v) + "".join("f %d %d %d %d\n" % f for f in faces)


def test_meshes_parsed_once_are_parsed_again_when_the_file_changes(tmp_path):
    # A Batch keeps the meshes its worlds parsed (a file with the same bytes is not parsed again);
    # a mesh file changed on disk is parsed again, by the batch's reset too (a snapshot carries
    # the Lua texts, not the meshes: they are read from the disk as they are).
    (tmp_path / "m.obj").write_text(cube_obj(0, 0.1))
    world = tmp_path / "w.lua"
    world.write_text('world.ground{}\nlocal b = world.mesh{file = "m.obj", mass = 1, at = {0, 0, 0.2}}\n'
                     'world.on_step(function() world.metric("top", b:position().z) end)\n')
    b = rm3d.Batch(str(world), seeds=[1, 2], threads=2)
    b.step(90)
    low = [m["top"] for m in b.metrics]
    assert low[0] == low[1] and low[0] == pytest.approx(0.0, abs=0.01)  # its frame rests on the ground
    (tmp_path / "m.obj").write_text(cube_obj(-0.3, 0.1))
    w = rm3d.World(str(world), seed=1)
    w.step(90)
    high = w.metrics["top"]
    assert high == pytest.approx(0.3, abs=0.01)  # the new hull reaches 0.3 m below its frame
    b.reset()
    b.step(90)
    assert [m["top"] for m in b.metrics] == [high, high]
