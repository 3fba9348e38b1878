# Snapshots: N steps == k steps, snapshot, restore (in this process or another), N - k steps, bit
# for bit; fork() is independent; damaged bytes are a clear error.
import json
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import rm3d
from conftest import HERE, ROOT

SNAKE = str(ROOT / "worlds" / "snake.lua")
AGENTS = str(HERE / "worlds" / "agents.lua")


def state(w):
    s = w.summary()
    s.pop("wall_seconds")
    return json.dumps(s, sort_keys=True), w.obs.tobytes(), w.reward.tobytes(), w.done.tobytes()


def fill(act, k):
    """A fixed, step-dependent policy (the same in every run), written into an action array."""
    act[:, 0] = 0.5 * np.sin(0.1 * k + np.arange(act.shape[0]))
    act[:, 1] = 1.0 if k % 7 == 0 else 0.0


def policy(w, k):
    fill(w.act, k)


def agents():
    return rm3d.World(AGENTS, params={"modules": 5, "hops": 1}, policy=True)


def run_policy(w, steps, start=0):
    for k in range(start, start + steps):
        policy(w, k)
        w.step()


def test_lua_world_snapshot_restore_bit_exact():
    a = rm3d.World(SNAKE, seed=4, params={"modules": 8})
    a.step(200)
    ref = state(a)
    b = rm3d.World(SNAKE, seed=4, params={"modules": 8})
    b.step(80)
    snap = b.snapshot()
    b.step(50)  # wander off, then come back
    b.restore(snap)
    assert b.steps == 80
    b.step(120)
    assert state(b) == ref


def test_policy_world_snapshot_restore_and_fork():
    n, k = 150, 60
    a = agents()
    run_policy(a, n)
    ref = state(a)
    b = agents()
    run_policy(b, k)
    snap = b.snapshot()
    c = b.fork()
    run_policy(b, n - k, start=k)
    assert state(b) == ref
    # The fork is at step k, independent of b, and arrives at the same state.
    assert c.steps == k
    run_policy(c, n - k, start=k)
    assert state(c) == ref
    d = rm3d.World.from_snapshot(snap, threads=2)  # any thread count
    run_policy(d, n - k, start=k)
    assert state(d) == ref


def test_views_kept_from_before_a_restore_go_on_driving_the_world():
    # A kept w.act (and w.obs) view went on writing into the arrays of the world before restore():
    # the restored world no longer saw the actions. Views now stay the world's own.
    n, k = 120, 40
    b = agents()
    act, obs = b.act, b.obs
    run_policy(b, k)
    snap = b.snapshot()
    run_policy(b, 30, start=k)
    b.restore(snap)
    assert np.array_equal(obs, b.obs)
    for step in range(k, n):
        fill(act, step)  # the view from before the restore, not b.act
        b.step()
    a = agents()
    run_policy(a, n)
    assert state(b) == state(a) and np.array_equal(obs, b.obs)


def test_snapshot_restores_in_another_process(tmp_path):
    n, k = 120, 45
    a = rm3d.World(AGENTS, params={"modules": 4, "hops": 1}, policy=True)
    run_policy(a, n)
    ref = state(a)
    b = rm3d.World(AGENTS, params={"modules": 4, "hops": 1}, policy=True)
    run_policy(b, k)
    (tmp_path / "snap.bin").write_bytes(b.snapshot())
    script = f"""
import sys, json
sys.path.insert(0, {str(HERE)!r})
import rm3d
from test_snapshot import run_policy, state
w = rm3d.World.from_snapshot(open({str(tmp_path / 'snap.bin')!r}, 'rb').read())
run_policy(w, {n - k}, start={k})
s, obs, rew, done = state(w)
open({str(tmp_path / 'out.json')!r}, 'w').write(json.dumps([s, obs.hex(), rew.hex(), done.hex()]))
"""
    env = dict(os.environ, PYTHONPATH=str(pathlib.Path(rm3d.__file__).resolve().parents[1]))
    subprocess.run([sys.executable, "-c", script], check=True, cwd=str(tmp_path), env=env)
    s, obs, rew, done = json.loads((tmp_path / "out.json").read_text())
    assert (s, bytes.fromhex(obs), bytes.fromhex(rew), bytes.fromhex(done)) == ref


def test_damaged_snapshots_are_clear_errors():
    w = rm3d.World(SNAKE, params={"modules": 3})
    w.step(5)
    snap = w.snapshot()
    with pytest.raises(rm3d.Error, match="not an RM3D snapshot"):
        w.restore(b"hello")
    with pytest.raises(rm3d.Error, match="damaged|truncated"):
        w.restore(snap[:-20])
    with pytest.raises(rm3d.Error, match="damaged|truncated"):
        w.restore(snap[:12] + bytes(len(snap) - 12))
    assert w.steps == 5  # unchanged by the failed restores


def test_snapshots_off_keeps_no_log():
    w = rm3d.World(AGENTS, params={"modules": 3}, policy=True, snapshots=False)
    w.step(5)
    with pytest.raises(rm3d.Error, match="snapshots=False"):
        w.snapshot()
    with pytest.raises(rm3d.Error, match="snapshots=False"):
        w.fork()


def test_a_size_field_past_what_zlib_can_hold_is_refused_before_allocating():
    w = rm3d.World(SNAKE, params={"modules": 2})
    snap = bytearray(w.snapshot())
    snap[8:16] = (1 << 40).to_bytes(8, "little")  # 1 TiB claimed for a few KiB of bytes
    with pytest.raises(rm3d.Error, match="size field is implausible"):
        rm3d.World.from_snapshot(bytes(snap))


def test_ctrl_c_stops_a_long_restore_and_leaves_the_world_as_it_was(sigint):
    import signal
    import threading
    w = rm3d.World(SNAKE, params={"modules": 20})
    w.step(3000)
    snap = w.snapshot()
    v = rm3d.World(SNAKE, params={"modules": 20})
    v.step(5)
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        v.restore(snap)
    timer.join()
    assert v.steps == 5
    v.step(1)
    assert v.steps == 6


def _header(snapshot):
    import struct
    import zlib

    raw = zlib.decompress(snapshot[16:])
    (hlen,) = struct.unpack("<Q", raw[:8])
    return json.loads(raw[8 : 8 + hlen]), raw, hlen


def _with_header(snapshot, header):
    import struct
    import zlib

    _, raw, hlen = _header(snapshot)
    text = json.dumps(header).encode()
    body = struct.pack("<Q", len(text)) + text + raw[8 + hlen :]
    return snapshot[:8] + struct.pack("<Q", len(body)) + zlib.compress(body)


def test_a_snapshot_header_cannot_name_a_root_outside_any_project():
    # Snapshot bytes are untrusted input: root = "/" (no assets/modules) is not taken; the root
    # is found as for a new World of that file, and the restored world is the same world.
    w = rm3d.World(str(ROOT / "worlds" / "snake.lua"), params={"modules": 3}, root=str(ROOT))
    w.step(5)
    snap = w.snapshot()
    header, _, _ = _header(snap)
    header["root"] = "/"
    restored = rm3d.World.from_snapshot(_with_header(snap, header))
    assert _header(restored.snapshot())[0]["root"] == str(ROOT)
    assert restored.summary()["steps"] == 5
    header["world"] = "relative/w.lua"
    with pytest.raises(rm3d.Error, match=r"snapshot: its world path 'relative/w\.lua' is not absolute"):
        rm3d.World.from_snapshot(_with_header(snap, header))


def test_a_snapshot_reads_its_world_folder_only_where_its_world_file_is_there(tmp_path):
    # After the re-run, what the texts do not hold comes from the disk. The world's folder counts
    # only where the world file there is the one the bytes carry: a header naming another folder
    # had a hook's require read a file there (its text coming back in the error), and a deleted
    # world file made the snapshot unusable though the bytes carry its text.
    home, secret = tmp_path / "home", tmp_path / "secret"
    home.mkdir()
    secret.mkdir()
    world = home / "w.lua"
    world.write_text('world.at(0.5, function() world.metric("x", require("helper").x) end)\n')
    (home / "helper.lua").write_text("return {x = 42}\n")
    (secret / "helper.lua").write_text("SECRET-TEXT is not Lua\n")
    w = rm3d.World(str(world), root=str(ROOT))
    w.step(10)
    snap = w.snapshot()
    same = rm3d.World.from_snapshot(snap)  # the world file is there as it was: its folder is read
    same.step(30)
    assert same.metrics["x"] == 42
    header, _, _ = _header(snap)
    header["world"] = str(secret / "w.lua")
    header["texts"] = [[str(secret / "w.lua") if p == str(world) else p, t] for p, t in header["texts"]]
    forged = rm3d.World.from_snapshot(_with_header(snap, header))
    assert forged.steps == 10
    with pytest.raises(rm3d.Error, match=r"require: .*helper\.lua' leads outside .*snapshot whose world file") as e:
        forged.step(30)
    assert "SECRET" not in str(e.value)
    world.rename(home / "gone.lua")
    gone = rm3d.World.from_snapshot(snap)  # restored from the texts the bytes carry
    assert gone.steps == 10
    gone.step(10)
    with pytest.raises(rm3d.Error, match=r"not here as it was"):
        gone.step(30)
