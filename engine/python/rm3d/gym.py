"""Gymnasium-style environments over RM3D worlds.

``Env`` is one :class:`rm3d.World` run with ``policy=True``: the observation is the modules'
observation rows flattened (each row's used columns, ``obs_size``, in module order), the action
the modules' action rows flattened the same way (``act_size``), the reward the mean of the
modules' rewards, ``terminated`` any module done, ``truncated`` the world finished (its duration,
``world.stop()`` or an error).

``VectorEnv`` is a :class:`rm3d.Batch` of worlds stepped together by the C++ pool (no
processes): observations ``(num_envs, modules * obs_dim)`` and actions ``(num_envs, modules *
act_dim)`` with the padding columns (zeros) kept, so that worlds of different bodies share one
shape; a world that ends is started again at once through ``Batch.reset(mask)`` (its last
observation and info are in ``info["final_observation"]`` and ``info["final_info"]``).

When gymnasium is installed, ``Env`` subclasses ``gymnasium.Env`` and the spaces are
``gymnasium.spaces.Box``; without it they are this module's own :class:`Box`.
"""

import numpy as np

from . import Batch, Error, World

try:
    import gymnasium as _gymnasium
    from gymnasium import spaces as _spaces
except ImportError:  # gymnasium is optional
    _gymnasium = None
    _spaces = None

__all__ = ["Box", "Env", "VectorEnv", "make_box"]


class Box:
    """A box in R^n (the part of gymnasium.spaces.Box these environments use).

    ``low`` and ``high`` are arrays of ``shape`` (a scalar is broadcast); infinite bounds are
    allowed. ``sample()`` draws uniformly inside finite bounds, from a normal distribution where
    both are infinite and from an exponential one past a single finite bound.
    """

    def __init__(self, low, high, shape=None, dtype=np.float64, seed=None):
        self.dtype = np.dtype(dtype)
        if shape is None:
            shape = np.broadcast(np.asarray(low), np.asarray(high)).shape
        self.shape = tuple(int(s) for s in shape)
        self.low = np.broadcast_to(np.asarray(low, dtype=self.dtype), self.shape).copy()
        self.high = np.broadcast_to(np.asarray(high, dtype=self.dtype), self.shape).copy()
        if np.any(self.low > self.high):
            raise ValueError("Box: low must not be above high")
        self._rng = np.random.default_rng(seed)

    def seed(self, seed=None):
        self._rng = np.random.default_rng(seed)
        return [seed]

    def sample(self):
        lo, hi = self.low, self.high
        out = np.empty(self.shape, dtype=np.float64)
        both = np.isfinite(lo) & np.isfinite(hi)
        below = np.isfinite(lo) & ~np.isfinite(hi)
        above = ~np.isfinite(lo) & np.isfinite(hi)
        free = ~np.isfinite(lo) & ~np.isfinite(hi)
        out[both] = self._rng.uniform(lo[both], hi[both])
        out[below] = lo[below] + self._rng.exponential(size=int(below.sum()))
        out[above] = hi[above] - self._rng.exponential(size=int(above.sum()))
        out[free] = self._rng.normal(size=int(free.sum()))
        return out.astype(self.dtype)

    def contains(self, x):
        try:
            x = np.asarray(x, dtype=self.dtype)
        except (TypeError, ValueError):
            return False
        return (x.shape == self.shape and not np.any(np.isnan(x))
                and bool(np.all(x >= self.low)) and bool(np.all(x <= self.high)))

    __contains__ = contains

    def __repr__(self):
        return "Box(%s, %s, %s, %s)" % (self.low.min() if self.low.size else "",
                                        self.high.max() if self.high.size else "",
                                        self.shape, self.dtype)

    def __eq__(self, other):
        return (isinstance(other, Box) and self.shape == other.shape
                and self.dtype == other.dtype and np.array_equal(self.low, other.low)
                and np.array_equal(self.high, other.high))


def make_box(low, high, shape, dtype=np.float64):
    """A gymnasium.spaces.Box when gymnasium is installed, else this module's Box."""
    if _spaces is not None:
        return _spaces.Box(low=low, high=high, shape=tuple(shape), dtype=dtype)
    return Box(low, high, shape=shape, dtype=dtype)


def _bounds(bounds):
    if bounds is None:
        return -np.inf, np.inf
    low, high = bounds
    return low, high


def _used_index(sizes, width):
    """Flat indices of each row's first sizes[i] columns in a (rows, width) array."""
    sizes = np.asarray(sizes, dtype=np.int64)
    return np.concatenate([np.arange(i * width, i * width + int(s)) for i, s in enumerate(sizes)]
                          ) if len(sizes) else np.zeros(0, dtype=np.int64)


_EnvBase = _gymnasium.Env if _gymnasium is not None else object


def _within(a, low, high, clip, name):
    """a clipped to [low, high] when clip, else a as it is, or ValueError naming the first number
    outside (its index in a's shape)."""
    low, high = np.broadcast_to(low, a.shape), np.broadcast_to(high, a.shape)
    if clip:
        return np.clip(a, low, high)
    outside = np.argwhere((a < low) | (a > high))
    if len(outside):
        i = tuple(int(k) for k in outside[0])
        raise ValueError("%s%s = %g lies outside action_bounds [%g, %g] (clip_actions=True clips instead)"
                         % (name, "".join("[%d]" % k for k in i), a[i], low[i], high[i]))
    return a


def _render_args(mode, size, camera):
    """Checks render_mode, render_size and camera as Env and the PettingZoo env take them."""
    if mode not in (None, "rgb_array"):
        raise ValueError("render_mode must be None or 'rgb_array', got %r" % (mode,))
    try:
        width, height = (int(v) for v in size)
    except (TypeError, ValueError):
        raise ValueError("render_size must be (width, height), got %r" % (size,)) from None
    if not (1 <= width <= 8192 and 1 <= height <= 8192 and width * height <= 7680 * 4320):
        raise ValueError("render_size %dx%d: expected a width and a height from 1 to 8192, at most "
                         "7680x4320 pixels in all" % (width, height))
    if camera is not None and not isinstance(camera, dict):
        raise ValueError("camera must be a dict with any of eye, target, fov; got %r" % (camera,))
    return mode, (width, height), camera


class _Episode:
    """The world an environment runs: one rm3d.World with policy=True that reset() brings back to
    its start, by restoring the snapshot taken when it was made (bit-exact), or by making it
    again (recreate=True, or a new seed)."""

    def __init__(self, path, seed, params, threads, record, recreate=False):
        self._args = (path, params, threads, record)
        self._recreate = recreate
        self.world = None
        self._make(seed)

    def _make(self, seed):
        if self.world is not None:
            self.world.close()
        path, params, threads, record = self._args
        self.world = World(path, seed=seed, params=params, threads=threads, policy=True,
                           record=record)
        self.seed = seed
        self._start = None if self._recreate else self.world.snapshot()

    def live(self):
        if self.world is None:
            raise Error("this environment is closed")
        return self.world

    def reset(self, seed=None):
        self.live()
        if self._start is None or (seed is not None and seed != self.seed):
            self._make(self.seed if seed is None else seed)
        else:
            self.world.restore(self._start)
        return self.world

    def close(self):
        if self.world is not None:
            self.world.close()
        self.world = self._start = None


class Env(_EnvBase):
    """One RM3D world as a single-agent environment.

    Env(path, seed=None, params=None, threads=1, record=None, action_bounds=None,
        observation_bounds=None, reset="snapshot", clip_actions=False, render_mode=None,
        render_size=(640, 480), camera=None)

    ``path``, ``seed``, ``params``, ``threads`` and ``record`` are rm3d.World's. Spaces are
    unbounded unless ``action_bounds``/``observation_bounds`` give ``(low, high)`` (scalars or
    arrays of the flat shape). An action outside ``action_bounds`` raises ValueError, or is
    clipped to them with ``clip_actions=True``. ``reset="snapshot"`` (default) restores a snapshot
    taken right after the world was made (fast, bit-exact); ``reset="recreate"`` makes the world
    again. ``reset(seed=S)`` with a seed other than the current one makes the world again with
    seed S, and seeds ``np_random``. ``step()`` after the episode ended (terminated or truncated)
    raises rm3d.Error until ``reset()``. ``render_mode="rgb_array"``: ``render()`` returns the
    world now as a ``(height, width, 3)`` uint8 array (World.render with ``render_size`` =
    (width, height) and ``camera``).
    """

    metadata = {"render_modes": ["rgb_array"]}

    def __init__(self, path, seed=None, params=None, threads=1, record=None,
                 action_bounds=None, observation_bounds=None, reset="snapshot", clip_actions=False,
                 render_mode=None, render_size=(640, 480), camera=None):
        if reset not in ("snapshot", "recreate"):
            raise ValueError("reset must be 'snapshot' or 'recreate', got %r" % (reset,))
        self.render_mode, self._render_size, self._camera = _render_args(render_mode, render_size, camera)
        self._clip = bool(clip_actions)
        self._ended = False
        self._rng = None
        self._episode = _Episode(path, seed, params, threads, record, recreate=reset == "recreate")
        w = self._world
        self._obs_idx = _used_index(w.obs_size, w.obs.shape[1])
        self._act_idx = _used_index(w.act_size, w.act.shape[1])
        lo, hi = _bounds(observation_bounds)
        self.observation_space = make_box(lo, hi, (len(self._obs_idx),))
        lo, hi = _bounds(action_bounds)
        self.action_space = make_box(lo, hi, (len(self._act_idx),))

    @property
    def _world(self):
        return self._episode.world

    def _live(self):
        return self._episode.live()

    @property
    def world(self):
        """The rm3d.World being run (read its summary, metrics, modules...)."""
        return self._world

    @property
    def modules(self):
        return self._world.modules

    def _observation(self):
        return np.asarray(self._world.obs).reshape(-1)[self._obs_idx].astype(np.float64)

    def _info(self):
        w = self._world
        return {"time": w.time, "steps": w.steps, "metrics": dict(w.metrics),
                "reward": np.array(w.reward), "done": np.array(w.done)}

    if _gymnasium is None:
        @property
        def np_random(self):
            """A numpy Generator for the environment's own randomness (as gymnasium.Env's):
            seeded by reset(seed=...), else from fresh entropy."""
            if self._rng is None:
                self._rng = np.random.default_rng()
            return self._rng

    def reset(self, seed=None, options=None):
        self._live()
        if _gymnasium is not None:
            super().reset(seed=seed)
        elif seed is not None:
            self._rng = np.random.default_rng(seed)
        self._episode.reset(seed)
        self._ended = False
        return self._observation(), self._info()

    def step(self, action):
        a = np.asarray(action, dtype=np.float64)
        if a.shape != (len(self._act_idx),):
            raise ValueError("action must have shape (%d,), got %s" % (len(self._act_idx),
                                                                       a.shape))
        if self._ended:
            raise Error("step() after the episode ended (terminated or truncated): call reset() first")
        a = _within(a, self.action_space.low, self.action_space.high, self._clip, "action")
        w = self._live()
        row = np.zeros(w.act.shape, dtype=np.float64)
        row.reshape(-1)[self._act_idx] = a
        w.act[:] = row
        w.step()
        reward = float(np.mean(w.reward)) if len(w.reward) else 0.0
        terminated = bool(np.any(w.done))
        truncated = bool(w.finished)
        self._ended = terminated or truncated
        return self._observation(), reward, terminated, truncated, self._info()

    def render(self):
        """The world now as a (height, width, 3) uint8 array under render_mode="rgb_array";
        None without a render_mode (as gymnasium's)."""
        if self.render_mode is None:
            return None
        return self._live().render(*self._render_size, camera=self._camera)

    def close(self):
        self._episode.close()


class VectorEnv:
    """A batch of RM3D worlds as a vectorised environment (one process, a C++ thread pool).

    VectorEnv(path_or_paths, num_envs=None, seeds=None, params=None, threads=1,
              action_bounds=None, observation_bounds=None, clip_actions=False)

    One path and ``num_envs`` (seeds default 0..num_envs-1), or a list of paths / a list of
    params dicts (worlds may hold different bodies). ``reset()`` -> (obs, info);
    ``step(actions)`` -> (obs, rewards, terminated, truncated, info), arrays over worlds. A world
    that terminates or is truncated is reset in the same call (``Batch.reset(mask)``): the
    returned obs is its first one again, and ``info["final_observation"]`` (an object array,
    None for the others) holds its last one, ``info["_final_observation"]`` the mask. Actions
    outside ``action_bounds`` raise ValueError, or are clipped with ``clip_actions=True`` (as Env).
    """

    metadata = {"render_modes": [], "autoreset_mode": "same-step"}
    render_mode = None

    def __init__(self, path_or_paths, num_envs=None, seeds=None, params=None, threads=1,
                 action_bounds=None, observation_bounds=None, clip_actions=False):
        self._clip = bool(clip_actions)
        many_paths = isinstance(path_or_paths, (list, tuple))
        if seeds is None and not many_paths:
            if num_envs is None:
                num_envs = len(params) if isinstance(params, (list, tuple)) else 1
            seeds = list(range(int(num_envs)))
        self._batch = Batch(path_or_paths, seeds=seeds, params=params, threads=threads,
                            policy=True)
        b = self._batch
        self.num_envs = len(b)
        if num_envs is not None and int(num_envs) != self.num_envs:
            b.close()
            raise ValueError("num_envs=%d but the batch holds %d worlds" % (num_envs,
                                                                          self.num_envs))
        self._obs_shape = (int(np.prod(b.obs.shape[1:])),)
        self._act_shape = (int(np.prod(b.act.shape[1:])),)
        lo, hi = _bounds(observation_bounds)
        self.single_observation_space = make_box(lo, hi, self._obs_shape)
        self.observation_space = make_box(lo, hi, (self.num_envs,) + self._obs_shape)
        lo, hi = _bounds(action_bounds)
        self.single_action_space = make_box(lo, hi, self._act_shape)
        self.action_space = make_box(lo, hi, (self.num_envs,) + self._act_shape)
        self.closed = False

    @property
    def batch(self):
        """The rm3d.Batch being run."""
        return self._batch

    def _observations(self):
        return np.asarray(self._batch.obs, dtype=np.float64).reshape(self.num_envs, -1).copy()

    def _rewards(self):
        b = self._batch
        mask = np.asarray(b.mask, dtype=bool)
        r = np.where(mask, np.asarray(b.reward), 0.0).sum(axis=1)
        n = mask.sum(axis=1)
        return np.divide(r, n, out=np.zeros(self.num_envs), where=n > 0)

    def reset(self, seed=None, options=None):
        self._batch.reset()
        return self._observations(), {"time": np.array(self._batch.time)}

    def step(self, actions):
        b = self._batch
        a = np.asarray(actions, dtype=np.float64)
        if a.shape != (self.num_envs,) + self._act_shape:
            raise ValueError("actions must have shape %s, got %s"
                             % ((self.num_envs,) + self._act_shape, a.shape))
        a = _within(a, self.action_space.low, self.action_space.high, self._clip, "actions")
        b.act[:] = a.reshape(b.act.shape)
        b.step()
        mask = np.asarray(b.mask, dtype=bool)
        obs = self._observations()
        rewards = self._rewards()
        terminated = np.any(np.asarray(b.done, dtype=bool) & mask, axis=1)
        truncated = np.asarray(b.finished, dtype=bool).copy()
        info = {"time": np.array(b.time)}
        ended = terminated | truncated
        if ended.any():
            final_obs = np.empty(self.num_envs, dtype=object)
            final_info = np.empty(self.num_envs, dtype=object)
            metrics = b.metrics
            for i in np.flatnonzero(ended):
                final_obs[i] = obs[i].copy()
                final_info[i] = {"time": float(info["time"][i]), "metrics": dict(metrics[i])}
            info["final_observation"], info["_final_observation"] = final_obs, ended.copy()
            info["final_info"], info["_final_info"] = final_info, ended.copy()
            b.reset(ended)
            obs = self._observations()
        return obs, rewards, terminated, truncated, info

    def close(self):
        if not self.closed:
            self._batch.close()
            self.closed = True

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

