"""exotwin.ExoEnv: the Gymnasium environment interface over exotwin.Twin, without the gymnasium
package (Debian ships none). The API is Gymnasium's (reset / step / spaces / close); Box is a minimal
stand-in for gymnasium.spaces.Box (shape, dtype, low, high, contains, sample, seed), so that an agent
written for Gymnasium runs unchanged and gymnasium.spaces.Box(env.observation_space.low, ...) rebuilds
the real one where Gymnasium is installed.
"""
import numpy as np

from ._api import Twin


class Box:
    """A box in R^n: low <= x <= high elementwise (gymnasium.spaces.Box's fields and methods)."""

    def __init__(self, low, high, shape=None, dtype=np.float64, seed=None):
        self.dtype = np.dtype(dtype)
        if shape is None:
            shape = np.shape(low)
        self.shape = tuple(int(n) for n in shape)
        self.low = np.broadcast_to(np.asarray(low, dtype=self.dtype), self.shape).copy()
        self.high = np.broadcast_to(np.asarray(high, dtype=self.dtype), self.shape).copy()
        if np.any(self.low > self.high):
            raise ValueError(f"Box: low > high in {np.flatnonzero(self.low > self.high).tolist()}")
        self.np_random = np.random.default_rng(seed)

    def seed(self, seed=None):
        self.np_random = np.random.default_rng(seed)
        return [seed]

    def contains(self, x):
        x = np.asarray(x)
        return (x.shape == self.shape and np.can_cast(x.dtype, self.dtype)
                and bool(np.all(x >= self.low)) and bool(np.all(x <= self.high)))

    __contains__ = contains

    def sample(self):
        """Uniform in the box's bounded dimensions; normal where a bound is infinite (as Gymnasium)."""
        low, high = self.low.astype(np.float64), self.high.astype(np.float64)
        x = self.np_random.normal(size=self.shape)
        both = np.isfinite(low) & np.isfinite(high)
        x[both] = self.np_random.uniform(low[both], high[both])
        lo = np.isfinite(low) & ~np.isfinite(high)
        x[lo] = low[lo] + self.np_random.exponential(size=int(lo.sum()))
        hi = ~np.isfinite(low) & np.isfinite(high)
        x[hi] = high[hi] - self.np_random.exponential(size=int(hi.sum()))
        return x.astype(self.dtype)

    def __repr__(self):
        return f"Box({self.low.min()}, {self.high.max()}, {self.shape}, {self.dtype})"

    def __eq__(self, other):
        return (isinstance(other, Box) and self.shape == other.shape and self.dtype == other.dtype
                and np.array_equal(self.low, other.low) and np.array_equal(self.high, other.high))


class ExoEnv:
    """The EXOwheel twin as a Gymnasium environment: one step = one controller period.

    ExoEnv(scenario, seed=None, tracking_weight=1.0, torque_weight=1e-4)
    observation: measured.csv's row at the period's end without t (q_hip, q_knee, tau_hip, tau_knee,
        cmd_hip, cmd_knee, ref_hip, ref_knee, state[, emg_*]; observation_columns), float64; a reading
        that is not valid yet or any more (NaN: no torque frame, a sensor fault) is 0 there and named
        in info["invalid"].
    action: the joint torque commands (N m; cmd_hip, cmd_knee) in [-limit, limit], the limit being the
        safety supervisor's (controller.torque_limit), which still vetoes and limits them.
    reward: -(tracking_weight * sum((ref - q)^2) [rad^2] + torque_weight * sum(cmd^2) [(N m)^2]), on
        the period's end (the scenario's reference, the torque the supervisor let through).
    terminated: the safety supervisor left its running state (a trip: state 1 damping, 2 torque off).
    truncated: the scenario's duration (all trials) ran out.
    info: t (s), trial, safety_state, invalid; at the episode's end, the run's metrics and checks.
    Same seed, same bits: reset(seed=s) replays the same episode for the same actions.
    """

    metadata = {"render_modes": []}
    render_mode = None
    spec = None
    reward_range = (-float("inf"), 0.0)

    def __init__(self, scenario, seed=None, tracking_weight=1.0, torque_weight=1e-4):
        self.twin = Twin(scenario, seed=seed)
        self.tracking_weight = float(tracking_weight)
        self.torque_weight = float(torque_weight)
        columns = self.twin.observation_columns
        self.observation_columns = [c for c in columns if c != "t"]
        self._index = {c: i for i, c in enumerate(self.observation_columns)}
        n = len(self.observation_columns)
        low = np.full(n, -np.inf)
        high = np.full(n, np.inf)
        low[self._index["state"]], high[self._index["state"]] = 0.0, 2.0
        self.observation_space = Box(low, high, (n,), np.float64)
        limit = self.twin.command_limit
        self.action_space = Box(-limit, limit, (2,), np.float64)
        self.np_random = np.random.default_rng(seed)
        self._obs = None

    @property
    def unwrapped(self):
        return self

    def _observe(self, row):
        obs = np.array([row[c] for c in self.observation_columns], dtype=np.float64)
        bad = ~np.isfinite(obs)
        obs[bad] = 0.0
        info = {"t": row["t"], "trial": self.twin.trial, "safety_state": int(row["state"]),
                "invalid": [self.observation_columns[i] for i in np.flatnonzero(bad)]}
        return obs, info

    def reset(self, seed=None, options=None):
        if seed is not None:
            self.np_random = np.random.default_rng(seed)
        row = self.twin.reset(seed)
        self._obs, info = self._observe(row)
        return self._obs.copy(), info

    def step(self, action):
        if self._obs is None:
            raise RuntimeError("ExoEnv.step: reset() first")
        row = self.twin.step(np.asarray(action))
        obs, info = self._observe(row)
        i = self._index
        err = np.array([row["ref_hip"] - row["q_hip"], row["ref_knee"] - row["q_knee"]])
        cmd = np.array([row["cmd_hip"], row["cmd_knee"]])
        err[~np.isfinite(err)] = 0.0
        reward = -(self.tracking_weight * float(err @ err) + self.torque_weight * float(cmd @ cmd))
        terminated = obs[i["state"]] != 0.0
        truncated = self.twin.done and not terminated
        if self.twin.done:
            info["metrics"] = self.twin.result.metrics
            info["checks"] = self.twin.result.checks
        self._obs = obs
        return obs, float(reward), bool(terminated), bool(truncated), info

    def render(self):
        return None

    def close(self):
        pass
