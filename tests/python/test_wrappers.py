"""rm3d.gym.Env, rm3d.gym.VectorEnv and rm3d.pettingzoo.ParallelEnv on worlds/python/py_chain.lua
(SuperBots in a line; obs row: pitch angle and velocity, act row: the pitch target; reward: how
far the chain's mean x moved in the step).

    PYTHONPATH=build/python /usr/bin/python3 -m pytest tests/python -q
"""
import pathlib

import numpy as np
import pytest

import rm3d
import rm3d.gym
import rm3d.pettingzoo

ROOT = pathlib.Path(__file__).resolve().parents[2]
CHAIN = str(ROOT / "worlds" / "python" / "py_chain.lua")


def wave(t, n, amplitude=0.8):
    """A travelling wave on n pitch joints: moves the chain."""
    return amplitude * np.sin(2 * np.pi * t / 1.5 - 2 * np.pi / 5 * np.arange(n))


# --- rm3d.gym.Box (the fallback space) ---------------------------------------------------------

def test_box_sample_contains_and_shape():
    box = rm3d.gym.Box(-1.0, 2.0, shape=(3,), seed=4)
    for _ in range(20):
        x = box.sample()
        assert x.shape == (3,) and box.contains(x)
        assert np.all(x >= -1) and np.all(x <= 2)
    assert not box.contains(np.array([0.0, 0.0]))           # wrong shape
    assert not box.contains(np.array([0.0, 3.0, 0.0]))      # above high
    assert not box.contains(np.array([0.0, np.nan, 0.0]))
    free = rm3d.gym.Box(-np.inf, np.inf, shape=(2, 2))
    assert free.sample().shape == (2, 2) and free.contains(np.zeros((2, 2)))
    with pytest.raises(ValueError):
        rm3d.gym.Box(1.0, 0.0, shape=(1,))


# --- rm3d.gym.Env ------------------------------------------------------------------------------

def test_env_spaces_follow_the_modules_rows():
    env = rm3d.gym.Env(CHAIN, params={"modules": 3}, action_bounds=(-1.5, 1.5))
    try:
        assert env.modules == ["m1", "m2", "m3"]
        assert env.observation_space.shape == (6,)   # 3 modules x (angle, velocity)
        assert env.action_space.shape == (3,)        # 3 modules x (pitch target)
        assert np.all(env.action_space.low == -1.5) and np.all(env.action_space.high == 1.5)
        obs, info = env.reset()
        assert obs.shape == (6,) and obs.dtype == np.float64
        assert env.observation_space.contains(obs)
        assert info["time"] == 0.0
        assert env.action_space.contains(env.action_space.sample())
    finally:
        env.close()


def test_env_step_reward_is_the_distance_and_reset_is_bit_exact():
    env = rm3d.gym.Env(CHAIN, params={"modules": 3, "seconds": 2})

    def episode(steps):
        obs, _ = env.reset()
        seen, total = [obs], 0.0
        for k in range(steps):
            obs, reward, terminated, truncated, info = env.step(wave(k / 60, 3))
            assert isinstance(reward, float)
            assert terminated is False and truncated is False
            seen.append(obs)
            total += reward
        return np.array(seen), total, info

    try:
        a, ret_a, info = episode(60)
        # The return is the distance the chain's mean x moved: the world's own "moved" metric.
        assert abs(ret_a - info["metrics"]["moved"]) < 1e-9
        assert ret_a != 0.0
        assert info["steps"] == 60 and abs(info["time"] - 1.0) < 1e-9
        b, ret_b, _ = episode(60)
        assert np.array_equal(a, b) and ret_a == ret_b     # reset restores the very same state
        assert not np.array_equal(a[0], a[-1])             # and the joints did move
    finally:
        env.close()


def test_env_truncated_when_the_world_ends_terminated_when_done():
    env = rm3d.gym.Env(CHAIN, params={"modules": 2, "seconds": 0.5})
    try:
        env.reset()
        flags = [env.step(np.zeros(2))[3] for _ in range(30)]
        assert flags[-1] is True and not any(flags[:-1])   # 0.5 s = 30 steps of 1/60 s
        obs, info = env.reset()
        assert info["time"] == 0.0
        _, _, terminated, truncated, _ = env.step(np.zeros(2))
        assert terminated is False and truncated is False
    finally:
        env.close()
    env = rm3d.gym.Env(CHAIN, params={"modules": 2, "done_after": 0.25})
    try:
        env.reset()
        terms = []
        while not terms or not terms[-1]:
            terms.append(env.step(np.zeros(2))[2])
            assert len(terms) <= 20
        assert len(terms) - 1 in (14, 15)
        # The episode ended: a step without reset() is an error, not a silent step past the end.
        with pytest.raises(rm3d.Error, match=r"after the episode ended .*reset\(\)"):
            env.step(np.zeros(2))
        env.reset()
        assert env.step(np.zeros(2))[2] is False
    finally:
        env.close()


def test_env_reset_with_a_seed_and_the_recreate_mode():
    for mode in ("snapshot", "recreate"):
        env = rm3d.gym.Env(CHAIN, params={"modules": 2}, reset=mode)
        try:
            first, _ = env.reset()
            for k in range(10):
                env.step(wave(k / 60, 2))
            again, info = env.reset()
            assert np.array_equal(first, again) and info["time"] == 0.0
            seeded, info = env.reset(seed=7)
            assert info["time"] == 0.0 and seeded.shape == first.shape
        finally:
            env.close()


def test_env_actions_outside_their_bounds_are_refused_or_clipped_and_np_random_is_seeded():
    env = rm3d.gym.Env(CHAIN, params={"modules": 2}, action_bounds=(-1.5, 1.5))
    clipped = rm3d.gym.Env(CHAIN, params={"modules": 2}, action_bounds=(-1.5, 1.5), clip_actions=True)
    edge = rm3d.gym.Env(CHAIN, params={"modules": 2}, action_bounds=(-1.5, 1.5))
    try:
        env.reset()
        with pytest.raises(ValueError, match=r"action\[1\] = 2 lies outside action_bounds \[-1.5, 1.5\]"):
            env.step(np.array([0.0, 2.0]))
        assert env.world.steps == 0
        clipped.reset()
        edge.reset()
        for _ in range(20):
            a, _, _, _, _ = clipped.step(np.array([-9.0, 2.0]))
            b, _, _, _, _ = edge.step(np.array([-1.5, 1.5]))
        assert np.array_equal(a, b)  # clipping gives what the bounds themselves give
        env.reset(seed=5)
        x = env.np_random.random(3)
        env.reset(seed=5)
        assert np.array_equal(x, env.np_random.random(3))
    finally:
        for e in (env, clipped, edge):
            e.close()


def test_env_refuses_bad_actions_and_calls_after_close():
    env = rm3d.gym.Env(CHAIN, params={"modules": 2})
    env.reset()
    with pytest.raises(ValueError, match=r"shape \(2,\)"):
        env.step(np.zeros(3))
    with pytest.raises((rm3d.Error, ValueError)):
        env.step(np.array([np.nan, 0.0]))
    env.close()
    env.close()  # twice is fine
    with pytest.raises(rm3d.Error, match="closed"):
        env.step(np.zeros(2))
    with pytest.raises(rm3d.Error, match="closed"):
        env.reset()
    penv = rm3d.pettingzoo.ParallelEnv(CHAIN, params={"modules": 2})
    penv.close()
    with pytest.raises(rm3d.Error, match="closed"):
        penv.step({"m1": np.zeros(1)})


def test_env_missing_world_is_an_rm3d_error():
    with pytest.raises(rm3d.Error, match="no_such_world"):
        rm3d.gym.Env(str(ROOT / "worlds" / "python" / "no_such_world.lua"))


# --- rm3d.gym.VectorEnv ------------------------------------------------------------------------

def test_vector_env_steps_every_world_and_resets_finished_ones():
    venv = rm3d.gym.VectorEnv(CHAIN, num_envs=3, params={"modules": 2, "seconds": 0.25})
    try:
        assert venv.num_envs == 3
        obs, info = venv.reset()
        assert obs.shape == (3,) + venv.single_observation_space.shape
        assert venv.single_action_space.shape[0] >= 2
        act = np.zeros((3,) + venv.single_action_space.shape)
        last = None
        for k in range(15):   # 0.25 s = 15 steps
            obs, rewards, terminated, truncated, info = venv.step(act)
            assert rewards.shape == (3,) and terminated.shape == (3,)
            if k < 14:
                assert not truncated.any() and "final_observation" not in info
            last = (obs, truncated, info)
        obs, truncated, info = last
        assert truncated.all() and info["_final_observation"].all()
        assert info["final_observation"][0].shape == venv.single_observation_space.shape
        assert np.all(info["time"] > 0.2)              # the time each world ended at
        assert np.all(np.asarray(venv.batch.time) == 0.0)  # and they started again
        assert "moved" in info["final_info"][1]["metrics"]
        obs, rewards, terminated, truncated, info = venv.step(act)
        assert not truncated.any()
    finally:
        venv.close()


def test_vector_env_worlds_of_different_bodies_share_one_padded_shape():
    venv = rm3d.gym.VectorEnv(CHAIN, params=[{"modules": 2}, {"modules": 4}], seeds=[1, 1])
    try:
        assert venv.num_envs == 2
        mask = np.asarray(venv.batch.mask)
        assert mask.sum(axis=1).tolist() == [2, 4]
        obs, _ = venv.reset()
        act = np.zeros((2,) + venv.single_action_space.shape)
        act[:, 0] = 0.5
        obs2, rewards, *_ = venv.step(act)
        assert obs2.shape == obs.shape
        per = obs2.reshape(2, mask.shape[1], -1)
        assert np.all(per[0, 2:] == 0)                 # the absent modules' rows are padding
    finally:
        venv.close()


def test_vector_env_matches_single_envs():
    venv = rm3d.gym.VectorEnv(CHAIN, params={"modules": 3}, seeds=[1, 1])
    env = rm3d.gym.Env(CHAIN, seed=1, params={"modules": 3})
    try:
        venv.reset()
        env.reset()
        width = venv.single_action_space.shape[0] // 3
        total_v, total_e = np.zeros(2), 0.0
        for k in range(40):
            a = wave(k / 60, 3)
            rows = np.zeros((3, width))
            rows[:, 0] = a
            _, rv, *_ = venv.step(np.stack([rows.reshape(-1)] * 2))
            _, re, *_ = env.step(a)
            total_v += rv
            total_e += re
        assert total_v[0] == total_v[1] == total_e
    finally:
        venv.close()
        env.close()


# --- rm3d.pettingzoo.ParallelEnv -----------------------------------------------------------------

def test_parallel_env_one_agent_per_module():
    env = rm3d.pettingzoo.ParallelEnv(CHAIN, params={"modules": 3, "seconds": 0.25})
    try:
        assert env.possible_agents == ["m1", "m2", "m3"]
        for agent in env.possible_agents:
            assert env.observation_space(agent).shape == (2,)
            assert env.action_space(agent).shape == (1,)
        obs, infos = env.reset()
        assert set(obs) == set(infos) == {"m1", "m2", "m3"}
        assert env.agents == env.possible_agents
        for k in range(15):
            actions = {a: np.array([wave(k / 60, 3)[i]]) for i, a in enumerate(env.agents)}
            obs, rewards, terms, truncs, infos = env.step(actions)
            assert set(obs) == set(rewards) == set(terms) == set(truncs) == {"m1", "m2", "m3"}
            assert len(set(rewards.values())) == 1     # the world gives every module one reward
            if k < 14:
                assert not any(truncs.values()) and env.agents == ["m1", "m2", "m3"]
        assert all(truncs.values()) and env.agents == []
        obs, _ = env.reset()
        assert env.agents == ["m1", "m2", "m3"] and obs["m2"].shape == (2,)
        with pytest.raises(ValueError, match="unknown agent"):
            env.step({"nobody": np.zeros(1)})
        with pytest.raises(ValueError, match="m1"):
            env.step({"m1": np.zeros(2)})
    finally:
        env.close()


def test_parallel_env_done_terminates_every_agent():
    env = rm3d.pettingzoo.ParallelEnv(CHAIN, params={"modules": 2, "done_after": 0.1})
    try:
        env.reset()
        for _ in range(10):
            _, _, terms, _, _ = env.step({a: np.zeros(1) for a in env.agents})
            if not env.agents:
                break
        assert all(terms.values()) and env.agents == []
    finally:
        env.close()


# --- against the real libraries, where installed -------------------------------------------------

def test_env_is_a_gymnasium_env():
    gymnasium = pytest.importorskip("gymnasium")
    from gymnasium.utils.env_checker import check_env
    env = rm3d.gym.Env(CHAIN, params={"modules": 2}, action_bounds=(-1.5, 1.5))
    try:
        assert isinstance(env, gymnasium.Env)
        assert isinstance(env.observation_space, gymnasium.spaces.Box)
        check_env(env, skip_render_check=True)
    finally:
        env.close()


def test_parallel_env_passes_the_pettingzoo_api_test():
    pytest.importorskip("pettingzoo")
    from pettingzoo.test import parallel_api_test
    env = rm3d.pettingzoo.ParallelEnv(CHAIN, params={"modules": 2, "seconds": 0.5},
                                      action_bounds=(-1.5, 1.5))
    try:
        parallel_api_test(env, num_cycles=40)
    finally:
        env.close()


def test_env_and_parallel_env_render_rgb_arrays():
    env = rm3d.gym.Env(CHAIN, render_mode="rgb_array", render_size=(160, 120))
    assert "rgb_array" in env.metadata["render_modes"] and env.render_mode == "rgb_array"
    env.reset(seed=0)
    first = env.render()
    assert first.shape == (120, 160, 3) and first.dtype == np.uint8
    assert len(np.unique(first.reshape(-1, 3), axis=0)) > 50
    for _ in range(20):
        env.step(np.full(env.action_space.shape, 0.5))
    assert env.render().tobytes() != first.tobytes()  # the modules moved
    env.reset()
    assert env.render().tobytes() == first.tobytes()  # the start again, drawn the same
    assert rm3d.gym.Env(CHAIN).render() is None  # no render_mode: None, as gymnasium's
    pz = rm3d.pettingzoo.ParallelEnv(CHAIN, render_mode="rgb_array", render_size=(64, 48))
    pz.reset()
    assert pz.render().shape == (48, 64, 3)
    with pytest.raises(ValueError, match="render_mode must be None or 'rgb_array', got 'human'"):
        rm3d.gym.Env(CHAIN, render_mode="human")
    with pytest.raises(ValueError, match=r"render_size must be \(width, height\)"):
        rm3d.gym.Env(CHAIN, render_mode="rgb_array", render_size=320)


def test_vector_env_and_parallel_env_refuse_or_clip_actions_outside_their_bounds():
    v = rm3d.gym.VectorEnv(CHAIN, num_envs=2, params={"modules": 3}, action_bounds=(-1, 1))
    v.reset()
    a = np.zeros((2,) + v.single_action_space.shape)
    a[1, 2] = 1.5
    with pytest.raises(ValueError, match=r"actions\[1\]\[2\] = 1.5 lies outside action_bounds \[-1, 1\]"):
        v.step(a)
    assert list(v.batch.time) == [0.0, 0.0]  # refused before any world stepped
    clipped = rm3d.gym.VectorEnv(CHAIN, num_envs=2, params={"modules": 3}, action_bounds=(-1, 1),
                                 clip_actions=True)
    clipped.reset()
    clipped.step(a)
    assert clipped.batch.act[1].reshape(-1)[2] == 1.0
    p = rm3d.pettingzoo.ParallelEnv(CHAIN, params={"modules": 3}, action_bounds=(-1, 1))
    p.reset()
    agent = p.agents[1]
    bad = np.full(p.action_space(agent).shape, -3.0)
    with pytest.raises(ValueError, match=r"action of agent '%s': action\[0\] = -3 lies outside" % agent):
        p.step({agent: bad})
    pc = rm3d.pettingzoo.ParallelEnv(CHAIN, params={"modules": 3}, action_bounds=(-1, 1), clip_actions=True)
    pc.reset()
    pc.step({agent: bad})
    assert pc.world.act[1, 0] == -1.0
