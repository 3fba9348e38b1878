# rm3d.World: the same run as `rm3d run`, the agents' arrays, observe()/act(a), reward/done,
# messages through docks, records, and errors.
import json
import math
import pathlib
import subprocess

import numpy as np
import pytest

import rm3d
from conftest import HERE, ROOT, rm3d_bin

SNAKE = str(ROOT / "worlds" / "snake.lua")
AGENTS = str(HERE / "worlds" / "agents.lua")


def strip(summary):
    """The summary without what depends on the wall clock or the command line."""
    keep = dict(summary)
    for k in ("wall_seconds", "command", "version", "arguments", "params", "interrupted", "warnings",
              "output_errors", "exit_code", "run"):
        keep.pop(k, None)
    return keep


def test_import_and_names():
    assert callable(rm3d.World) and callable(rm3d.Batch) and callable(rm3d.evaluate)
    assert issubclass(rm3d.Error, RuntimeError)


def test_import_under_the_wrong_interpreter_says_what_to_do(tmp_path):
    # Under an interpreter without numpy, or one the engine was not built for, `import rm3d` said
    # "No module named numpy" or "No module named rm3d._rm3d" and nothing more.
    import shutil
    import sys
    pkg = pathlib.Path(rm3d.__file__).parent
    fake = tmp_path / "nonumpy" / "numpy"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text("raise ImportError('No module named numpy')\n")
    r = subprocess.run([sys.executable, "-c", "import rm3d"], capture_output=True, text=True,
                       env={"PYTHONPATH": "%s:%s" % (fake.parent, pkg.parent)})
    assert "rm3d needs numpy, which this Python" in r.stderr and sys.executable in r.stderr, r.stderr
    other = tmp_path / "other" / "rm3d"
    other.mkdir(parents=True)
    for f in pkg.glob("*.py"):
        shutil.copy(f, other / f.name)
    # The engine as another interpreter's build would be named: this one does not load it.
    shutil.copy(next(pkg.glob("_rm3d*.so")), other / "_rm3d.cpython-39-x86_64-linux-gnu.so")
    r = subprocess.run([sys.executable, "-c", "import rm3d"], capture_output=True, text=True,
                       env={"PYTHONPATH": str(other.parent)})
    assert "rm3d's engine was built for CPython 3.9" in r.stderr, r.stderr
    assert "-DPython_EXECUTABLE=%s" % sys.executable in r.stderr


def test_world_equals_rm3d_run(tmp_path):
    out = tmp_path / "run.json"
    subprocess.run([rm3d_bin(), "run", SNAKE, "--headless", "--quiet", "--steps", "150", "--seed", "5",
                    "--param", "modules=6", "--json", str(out)], check=True, capture_output=True)
    ran = json.loads(out.read_text())
    w = rm3d.World(SNAKE, seed=5, params={"modules": 6})
    w.step(150)
    got = w.finish()
    assert w.steps == 150 and got["steps"] == 150
    for key in ("modules", "connections", "events", "metrics", "sim_time", "seed", "messages", "failures"):
        assert got[key] == ran[key], key
    assert got["modules"][0]["position"] == ran["modules"][0]["position"]  # every bit (JSON round-trips)


def test_lua_control_loop_in_python_equals_one_call():
    a = rm3d.World(SNAKE, seed=2)
    for _ in range(90):
        a.step()
    b = rm3d.World(SNAKE, seed=2)
    b.step(90)
    assert strip(a.summary()) == strip(b.summary())


def test_default_arrays_and_joint_targets():
    w = rm3d.World(str(HERE / "worlds" / "mixed.lua"), policy=True)
    assert w.modules == ["superbot_1", "wheelbot_2"]  # numbered across types
    sizes = list(w.obs_size)
    # SuperBot: 3 angles, 3 velocities, 6 docks; the other row is shorter and zero-padded.
    assert sizes[0] == 12 and sizes[1] < 12
    assert w.obs.shape == (2, 12)
    assert list(w.act_size)[0] == 3
    assert not w.obs.flags.writeable and w.act.flags.writeable
    w.act[0, :3] = [0.0, 0.4, 0.0]  # the SuperBot's second joint to 0.4 rad, the others held at 0
    w.step(120)
    joints = w.summary()["modules"][0]["joints"]
    assert abs(w.obs[0, 1] - 0.4) < 0.05, w.obs[0]
    assert w.obs[0, 1] in joints.values()  # obs: the joint angles first, every bit as the summary's
    assert sorted(abs(v) < 0.01 for v in joints.values()) == [False, True, True]
    assert np.all(w.obs[1, w.obs_size[1]:] == 0)


def test_observe_act_and_messages_one_hop_per_step():
    w = rm3d.World(AGENTS, params={"modules": 4, "hops": 1}, policy=True)
    assert w.obs.shape == (4, 3) and w.act.shape == (4, 2)
    assert list(w.act_size) == [2, 2, 2, 2]
    w.act[:, 0] = 0.2
    w.act[0, 1] = 7.0  # the head sends 7 through its back dock, once
    w.step()
    w.act[0, 1] = 0.0
    heard = [list(w.obs[:, 1])]
    for _ in range(3):
        w.step()
        heard.append(list(w.obs[:, 1]))
    # Row i of `heard` is after step i + 1. The head sent in step 1; module k (0-based, k hops
    # away) reads it in its step() of step k + 1: one step per hop.
    for k in range(1, 4):
        first = next(i for i, row in enumerate(heard) if row[k] == 7.0)
        assert first == k, (k, heard)
    assert w.obs[0, 2] == 4  # the head's step() ran 4 times
    pitch = w.summary()["modules"][0]["joints"]["pitch"]
    assert pitch > 0.05  # act(a) set the pitch target


def test_reward_and_done_from_the_world_script():
    w = rm3d.World(AGENTS, params={"modules": 3, "goal": -1}, policy=True)
    w.act[:, 0] = 0.0
    w.step(10)
    assert w.reward.shape == (3,) and w.done.dtype == np.bool_
    assert np.all(w.done)  # the head is past x = -1 from the start
    assert np.all(np.isfinite(w.reward))
    w2 = rm3d.World(AGENTS, params={"modules": 3}, policy=True)
    w2.step(1)
    assert not np.any(w2.done)


def test_act_assignment_checks_shape_and_dtype():
    w = rm3d.World(AGENTS, params={"modules": 3}, policy=True)
    with pytest.raises(ValueError, match=r"act: expected shape \(3, 2\), got \(2, 2\)"):
        w.act = np.zeros((2, 2))
    with pytest.raises(TypeError, match="act: expected a float array"):
        w.act = np.array([["a", "b"]] * 3)
    w.act = np.ones((3, 2), dtype=np.float32)
    assert w.act[2, 1] == 1.0


def test_nan_actions_raise_before_stepping():
    w = rm3d.World(AGENTS, params={"modules": 3}, policy=True)
    w.act[1, 0] = float("nan")
    with pytest.raises(rm3d.Error, match=r"act\[1\]\[0\] is nan .*snake_2"):
        w.step()
    assert w.steps == 0
    w.act[1, 0] = 0.0
    w.step()
    assert w.steps == 1


def test_errors_name_file_and_line(tmp_path):
    with pytest.raises(rm3d.Error, match="no such file"):
        rm3d.World(tmp_path / "missing.lua")
    bad = tmp_path / "bad.lua"
    bad.write_text("world.set{dt = 1/60}\nworld.spawn('nosuchtype')\n")
    with pytest.raises(rm3d.Error, match=r"bad.lua:2:"):
        rm3d.World(bad)
    hook = tmp_path / "hook.lua"
    hook.write_text("world.ground{}\nworld.at(0.05, function() error('boom') end)\n")
    w = rm3d.World(hook)
    with pytest.raises(rm3d.Error, match=r"hook.lua:2: boom"):
        w.step(10)
    # A reward or done function that returns the wrong count or type: named by its file and line.
    for hook, body, want in (("reward", "return {1}", r"a list of 1; expected a finite number"),
                             ("reward", "return 'x'", r"a string; expected a finite number"),
                             ("reward", "return 0/0", r"a number; expected a finite number"),
                             ("done", "return {true, 1}", r"a number at \[2\]; expected a boolean"),
                             ("done", "return nil", r"a nil; expected a boolean")):
        src = tmp_path / f"{hook}.lua"
        src.write_text("world.spawn('superbot')\nworld.spawn('superbot', {at = {0.5, 0, 0}})\n"
                       f"world.{hook}(function(t)\n  {body}\nend)\n")
        w = rm3d.World(src, policy=True, root=ROOT)
        with pytest.raises(rm3d.Error, match=rf"{hook}.lua:3: world.{hook}'s function returned {want}"):
            w.step()
    # Read before the first step, a reward of 0/0 was handed to Python as nan, the error unseen.
    nan = tmp_path / "nan.lua"
    nan.write_text("world.spawn('superbot')\nworld.reward(function(t)\n  return 0 / t\nend)\n")
    w = rm3d.World(nan, policy=True, root=ROOT)
    with pytest.raises(rm3d.Error, match=r"nan.lua:2: world.reward's function returned a number; expected a finite"):
        w.reward
    assert w.reward.tolist() == [0.0]
    with pytest.raises(TypeError, match="params: expected a dict"):
        rm3d.World(SNAKE, params=[1])
    with pytest.raises(TypeError, match=r"params\['x'\]: expected str, int, float or bool"):
        rm3d.World(SNAKE, params={"x": [1]})
    with pytest.raises(ValueError, match="finite"):
        rm3d.World(SNAKE, params={"x": math.inf})
    with pytest.raises(TypeError, match="seed"):
        rm3d.World(SNAKE, seed="one")
    with pytest.raises(rm3d.Error, match="threads=0"):
        rm3d.World(SNAKE, threads=0)


def test_calls_after_close_raise():
    w = rm3d.World(SNAKE)
    w.close()
    assert w.closed
    for call in (lambda: w.step(), lambda: w.obs, lambda: w.summary(), lambda: w.snapshot(), lambda: w.time):
        with pytest.raises(rm3d.Error, match="closed"):
            call()
    w.close()  # twice is fine
    with rm3d.World(SNAKE) as v:
        v.step()
    assert v.closed


def test_a_faulty_behaviour_faults_its_module_only(tmp_path):
    (tmp_path / "bad.lua").write_text("function step(dt) if sim.time() > 0.05 then error('broken servo') end end\n")
    (tmp_path / "w.lua").write_text(
        "world.ground{}\nworld.spawn('superbot', {at = {0, 0, 0.06}, behavior = 'bad.lua'})\n"
        "world.spawn('superbot', {at = {1, 0, 0.06}})\n")
    w = rm3d.World(tmp_path / "w.lua")
    w.step(30)
    assert list(w.faults) == ["superbot_1"] and "bad.lua:1: broken servo" in w.faults["superbot_1"]
    assert w.steps == 30 and not w.finished
    strict = rm3d.World(tmp_path / "w.lua", strict=True)
    strict.step(30)
    assert strict.finished and strict.steps < 30


def test_past_the_duration_a_world_steps_on_when_asked_and_stays_finished(tmp_path):
    # As rm3d run --seconds runs past a world's duration (docs/python.md); a stopped world does not.
    w = rm3d.World.from_string("world.set{duration = 0.1}\nworld.spawn('superbot')\n")
    w.step(6)
    assert w.finished and w.steps == 6
    w.step(6)
    assert w.finished and w.steps == 12 and abs(w.time - 0.2) < 1e-9
    stopped = rm3d.World.from_string("world.at(0.05, function() world.stop() end)\nworld.spawn('superbot')\n")
    stopped.step(10)
    assert stopped.finished and stopped.steps == 3
    stopped.step(10)
    assert stopped.steps == 3


def test_a_relative_world_path_is_found_as_rm3d_run_finds_it(tmp_path, monkeypatch):
    # From a folder outside the project, "worlds/snake.lua" is the data root's (as rm3d run does).
    monkeypatch.chdir(tmp_path)
    w = rm3d.World("worlds/snake.lua", params={"modules": 3})
    assert w.path == str(ROOT / "worlds" / "snake.lua")
    w.step(2)
    with pytest.raises(rm3d.Error, match=r"worlds/nope\.lua: not found in the working folder .* nor in the data root"):
        rm3d.World("worlds/nope.lua")
    (tmp_path / "worlds").mkdir()
    (tmp_path / "worlds" / "snake.lua").write_text("world.spawn('superbot')\n")
    own = rm3d.World("worlds/snake.lua", root=ROOT)  # the working folder's comes first
    assert own.path == str(tmp_path / "worlds" / "snake.lua") and len(own.modules) == 1


def test_finish_runs_on_end_once_and_ends_the_world():
    w = rm3d.World(SNAKE, params={"modules": 4})
    w.step(60)
    s = w.finish()
    assert set(s["metrics"]) == {"speed_m_s", "pieces", "broken"}
    assert w.finish()["metrics"] == s["metrics"]
    with pytest.raises(rm3d.Error, match="finished"):
        w.step()


def test_record_replays_with_rm3d_replay(tmp_path):
    rec = tmp_path / "episode.rm3drec"
    w = rm3d.World(AGENTS, params={"modules": 3}, policy=True, record=rec)
    w.act[:, 0] = 0.3
    w.step(30)
    w.close()
    assert rec.stat().st_size > 0
    out = tmp_path / "last.png"
    r = subprocess.run([rm3d_bin(), "replay", str(rec), "--png", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert out.stat().st_size > 1000


def test_ctrl_c_ends_a_long_step_at_a_step_boundary(sigint):
    import os
    import signal
    import threading
    w = rm3d.World(SNAKE, params={"modules": 20})
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        w.step(10**7)
    timer.join()
    assert 0 < w.steps < 10**7 and w.steps % 64 == 0
    before = w.steps
    w.step(2)  # the world is whole and goes on
    assert w.steps == before + 2


def test_positional_arguments_as_the_contract_writes_them():
    a = rm3d.World(SNAKE, 3, {"modules": 3}, 1)
    b = rm3d.World(SNAKE, seed=3, params={"modules": 3}, threads=2)
    a.step(20)
    b.step(20)
    assert strip(a.summary()) == strip(b.summary()) and a.summary()["seed"] == 3
    batch = rm3d.Batch(SNAKE, [1, 2], {"modules": 2}, 2)
    assert batch.obs.shape == (2, 2, 12)


def test_a_second_thread_gets_busy_not_a_crash():
    import threading
    w = rm3d.World(SNAKE, params={"modules": 30})
    errors = []

    def long_step():
        w.step(600)

    t = threading.Thread(target=long_step)
    t.start()
    seen = 0
    while t.is_alive():
        try:
            w.obs  # from this thread while the other steps
        except rm3d.Error as e:
            errors.append(str(e))
        seen += 1
    t.join()
    assert w.steps == 600
    assert errors and all("busy" in e for e in errors), (seen, errors[:1])
    b = rm3d.Batch(SNAKE, seeds=[1, 2], params={"modules": 20}, threads=2)
    t = threading.Thread(target=lambda: b.step(300))
    t.start()
    busy = 0
    while t.is_alive():
        try:
            b.step()
        except rm3d.Error as e:
            assert "busy" in str(e)
            busy += 1
    t.join()
    assert busy > 0
    assert b.time[0] == b.time[1] and b.time[0] >= 300 / 60


def test_close_while_another_thread_steps_is_busy(tmp_path):
    # close() and leaving a `with` block freed the world under a running step (a recording
    # world crashed); like every other call they get "busy", and the step finishes.
    import threading
    rec = tmp_path / "r.rec"
    w = rm3d.World(SNAKE, params={"modules": 30}, record=str(rec))
    t = threading.Thread(target=lambda: w.step(400))
    t.start()
    refused = 0
    while t.is_alive() and not w.closed:  # a close that gets in after the step ended is fine
        for call in (w.close, lambda: w.__exit__(None, None, None)):
            try:
                call()
            except rm3d.Error as e:
                assert "busy" in str(e)
                refused += 1
    t.join()
    assert refused > 0
    if not w.closed:
        assert w.steps == 400
        w.close()
    out = tmp_path / "last.json"
    r = subprocess.run([rm3d_bin(), "replay", str(rec), "--json", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr  # the recording was finished, not cut off


def test_record_never_overwrites_an_input(tmp_path):
    # The output rule (docs/limits.md): record= may not be the world script, a file the world read
    # (a behaviour), or a link to either; the file is left as it was.
    world = tmp_path / "w.lua"
    behaviour = tmp_path / "b.lua"
    behaviour.write_text("function step(dt) end\n")
    world.write_text('world.set{duration = 0.1}\nworld.spawn("superbot", {behavior = "b.lua"})\n')
    link = tmp_path / "link.rec"
    link.symlink_to(world)
    before = {p: p.read_bytes() for p in (world, behaviour)}
    with pytest.raises(rm3d.Error, match=r"record= .*w\.lua: is also the world script"):
        rm3d.World(str(world), record=str(world), root=str(ROOT))
    with pytest.raises(rm3d.Error, match=r"record= .*b\.lua: is also a file the world read"):
        rm3d.World(str(world), record=str(behaviour), root=str(ROOT))
    with pytest.raises(rm3d.Error, match=r"record= .*link\.rec: is also the world script"):
        rm3d.World(str(world), record=str(link), root=str(ROOT))
    assert {p: p.read_bytes() for p in (world, behaviour)} == before


def test_a_nul_in_a_path_is_refused(tmp_path):
    # The operating system would stop at the NUL and open another file ("w.lua" for
    # "w.lua\0x"): refused instead, naming the argument and where the NUL is.
    world = tmp_path / "w.lua"
    world.write_text("world.set{duration = 0.1}\n")
    with pytest.raises(rm3d.Error, match=r"path: holds a NUL character \(byte \d+\)"):
        rm3d.World(str(world) + "\0x", root=str(ROOT))
    with pytest.raises(rm3d.Error, match=r"record: holds a NUL character"):
        rm3d.World(str(world), record=str(tmp_path / "r.rec") + "\0x", root=str(ROOT))
    with pytest.raises(rm3d.Error, match=r"root: holds a NUL character"):
        rm3d.World(str(world), root=str(ROOT) + "\0x")
    assert not (tmp_path / "r.rec").exists()


def test_seed_and_path_type_errors_name_the_argument(tmp_path):
    # A world's seed is a Lua integer: above 2**63-1 is refused here, as by rm3d run --seed (it
    # was refused by the world script's first line, which sets no seed).
    world = tmp_path / "w.lua"
    world.write_text("world.set{duration = 0.1}\n")
    with pytest.raises(ValueError, match=r"seed = 9223372036854775808: expected 0 to 2\*\*63-1"):
        rm3d.World(str(world), seed=2**63, root=str(ROOT))
    w = rm3d.World(str(world), seed=2**63 - 1, root=str(ROOT))
    assert w.summary()["seed"] == 2**63 - 1

    class BadPath:
        def __fspath__(self):
            return 5

    with pytest.raises(TypeError, match=r"path: its __fspath__\(\) returned int; expected a str"):
        rm3d.World(BadPath(), root=str(ROOT))


def test_render_draws_the_world_headless_from_any_folder(tmp_path, monkeypatch):
    # From a folder outside the project, the shipped snake drawn offscreen: a (240, 320, 3) uint8
    # frame with the modules in it (their orange covers part of the frame; the ground is grey).
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("DISPLAY", raising=False)
    w = rm3d.World("worlds/snake.lua")
    w.step(30)
    f = w.render(320, 240)
    assert f.shape == (240, 320, 3) and f.dtype == np.uint8
    r, g, b = (f[..., i].astype(int) for i in range(3))
    orange = (r > 150) & (r - b > 80)  # the SuperBots' brackets
    assert 0.02 < orange.mean() < 0.6
    assert len(np.unique(f.reshape(-1, 3), axis=0)) > 100
    # The automatic camera keeps its frame; a camera given wins and changes the picture.
    assert w.render(320, 240).tobytes() == f.tobytes()
    near = w.render(320, 240, camera={"eye": (0.3, -0.6, 0.4), "target": (0, 0, 0.05), "fov": 40})
    assert near.shape == f.shape and near.tobytes() != f.tobytes()
    assert w.render(64, 48).shape == (48, 64, 3)


def test_render_refuses_bad_sizes_and_cameras():
    w = rm3d.World(SNAKE, params={"modules": 2})
    bad = [({"width": 0}, r"render: 0x480: expected a width and a height from 1 to 8192"),
           ({"width": 8192, "height": 8192}, r"at most 7680x4320 pixels"),
           ({"camera": {"eye": (1, 2)}}, r"render: camera eye: expected three numbers"),
           ({"camera": {"target": (0, 0, float("nan"))}}, r"render: camera target: expected three finite numbers"),
           ({"camera": {"fov": 180}}, r"render: camera fov 180.* expected degrees between 0 and 180"),
           ({"camera": {"zoom": 2}}, r"render: camera: unknown key 'zoom' \(expected eye, target or fov\)"),
           ({"camera": "above"}, r"render: camera must be a dict")]
    for kwargs, message in bad:
        with pytest.raises(rm3d.Error, match=message):
            w.render(**kwargs)
    w.close()
    with pytest.raises(rm3d.Error, match="closed"):
        w.render()
