"""A PettingZoo-style parallel environment: one agent per module of an RM3D world.

``ParallelEnv(path, ...)`` runs one :class:`rm3d.World` with ``policy=True``. Agents are the
module names (``World.modules``, in module order); each agent's observation is its module's
observation row (its ``obs_size`` used columns) and its action its action row (``act_size``
columns). ``step(actions)`` takes a dict agent -> action (a missing agent keeps action zeros)
and returns dicts of observations, rewards (the module's ``reward``), terminations (its
``done``), truncations (the world finished) and infos. An agent that terminated or was
truncated leaves ``agents``; once none is left, ``reset()`` starts the episode again (from a
snapshot taken right after the world was made).

When pettingzoo is installed, ``ParallelEnv`` subclasses ``pettingzoo.ParallelEnv``; the spaces
are gymnasium Boxes when gymnasium is installed, else :class:`rm3d.gym.Box`.
"""

import numpy as np

from .gym import _bounds, _Episode, _render_args, _within, make_box

try:
    import pettingzoo as _pettingzoo
except ImportError:  # pettingzoo is optional
    _pettingzoo = None

__all__ = ["ParallelEnv"]

_Base = _pettingzoo.ParallelEnv if _pettingzoo is not None else object


class ParallelEnv(_Base):
    """ParallelEnv(path, seed=None, params=None, threads=1, record=None, action_bounds=None,
    observation_bounds=None, clip_actions=False, render_mode=None, render_size=(640, 480),
    camera=None): every module of the world is an agent (see the module's doc). An action outside
    ``action_bounds`` raises ValueError naming the agent, or is clipped with
    ``clip_actions=True``. ``render_mode="rgb_array"``: ``render()`` returns the world now as a
    (height, width, 3) uint8 array (World.render)."""

    metadata = {"render_modes": ["rgb_array"], "name": "rm3d_parallel_v0", "is_parallelizable": True}

    def __init__(self, path, seed=None, params=None, threads=1, record=None,
                 action_bounds=None, observation_bounds=None, clip_actions=False, render_mode=None,
                 render_size=(640, 480), camera=None):
        self._clip = bool(clip_actions)
        self.render_mode, self._render_size, self._camera = _render_args(render_mode, render_size, camera)
        self._episode = _Episode(path, seed, params, threads, record)
        w = self._world
        self.possible_agents = list(w.modules)
        self.agents = list(self.possible_agents)
        self._index = {a: i for i, a in enumerate(self.possible_agents)}
        self._obs_size = [int(n) for n in w.obs_size]
        self._act_size = [int(n) for n in w.act_size]
        olo, ohi = _bounds(observation_bounds)
        alo, ahi = _bounds(action_bounds)
        self.observation_spaces = {a: make_box(olo, ohi, (self._obs_size[i],))
                                   for a, i in self._index.items()}
        self.action_spaces = {a: make_box(alo, ahi, (self._act_size[i],))
                              for a, i in self._index.items()}

    @property
    def _world(self):
        return self._episode.world

    def _live(self):
        return self._episode.live()

    @property
    def world(self):
        """The rm3d.World being run."""
        return self._world

    @property
    def num_agents(self):
        return len(self.agents)

    @property
    def max_num_agents(self):
        return len(self.possible_agents)

    def observation_space(self, agent):
        return self.observation_spaces[agent]

    def action_space(self, agent):
        return self.action_spaces[agent]

    def _observations(self, agents):
        obs = np.asarray(self._world.obs)
        return {a: obs[self._index[a], :self._obs_size[self._index[a]]].astype(np.float64)
                for a in agents}

    def reset(self, seed=None, options=None):
        self._episode.reset(seed)
        self.agents = list(self.possible_agents)
        w = self._world
        infos = {a: {"time": w.time} for a in self.agents}
        return self._observations(self.agents), infos

    def step(self, actions):
        w = self._live()
        unknown = [a for a in actions if a not in self._index]
        if unknown:
            raise ValueError("unknown agent(s) %s; the agents are %s" % (unknown,
                                                                        self.possible_agents))
        rows = np.zeros(w.act.shape, dtype=np.float64)
        for agent, action in actions.items():
            i = self._index[agent]
            a = np.asarray(action, dtype=np.float64).reshape(-1)
            if a.shape != (self._act_size[i],):
                raise ValueError("action of agent %r must have %d numbers, got shape %s"
                                 % (agent, self._act_size[i], np.shape(action)))
            space = self.action_spaces[agent]
            rows[i, :self._act_size[i]] = _within(a, space.low, space.high, self._clip,
                                                 "action of agent %r: action" % agent)
        w.act[:] = rows
        w.step()
        live = list(self.agents)
        reward, done, finished = np.asarray(w.reward), np.asarray(w.done), bool(w.finished)
        observations = self._observations(live)
        rewards = {a: float(reward[self._index[a]]) for a in live}
        terminations = {a: bool(done[self._index[a]]) for a in live}
        truncations = {a: finished for a in live}
        infos = {a: {"time": w.time} for a in live}
        self.agents = [a for a in live if not (terminations[a] or truncations[a])]
        return observations, rewards, terminations, truncations, infos

    def state(self):
        """Every module's observation row (padded), flattened: a global state for critics."""
        return np.asarray(self._world.obs, dtype=np.float64).reshape(-1).copy()

    def render(self):
        """The world now as a (height, width, 3) uint8 array under render_mode="rgb_array"; None
        without one."""
        if self.render_mode is None:
            return None
        return self._live().render(*self._render_size, camera=self._camera)

    def close(self):
        self._episode.close()
