# exotwin.ExoEnv and Box (python/exotwin/env.py): what Gymnasium's environment checker
# (gymnasium.utils.env_checker.check_env) checks, without the gymnasium package: the spaces' shape,
# dtype and bounds; reset -> (obs, info) and step -> (obs, reward, terminated, truncated, info) with the
# right types and the observations in their space; same seed, same bits (reset and step); options;
# termination on a safety-supervisor trip; truncation at the scenario's end.
import numpy as np
import pytest

import exotwin
from conftest import same_bits, short_gait


@pytest.fixture
def env(tmp):
    e = exotwin.ExoEnv(short_gait(tmp, duration=0.3), seed=1)
    yield e
    e.close()


def test_spaces(env):
    for space in (env.observation_space, env.action_space):
        assert isinstance(space.shape, tuple) and all(isinstance(n, int) for n in space.shape)
        assert space.low.shape == space.high.shape == space.shape
        assert space.low.dtype == space.high.dtype == space.dtype == np.float64
        assert np.all(space.low <= space.high)
    assert env.action_space.shape == (2,)
    assert np.all(np.isfinite(env.action_space.low)) and np.all(np.isfinite(env.action_space.high))
    assert env.action_space.high[0] == env.twin.command_limit == 100.0
    assert env.observation_space.shape == (len(env.observation_columns),)
    assert env.observation_columns[:2] == ["q_hip", "q_knee"] and "t" not in env.observation_columns
    assert env.action_space.contains(env.action_space.sample())
    assert not env.action_space.contains(np.array([1e9, 0.0]))
    assert not env.action_space.contains(np.zeros(3))
    assert env.metadata["render_modes"] == [] and env.render_mode is None and env.unwrapped is env


def test_reset_and_step_types(env):
    obs, info = env.reset(seed=123)
    assert isinstance(info, dict) and obs.dtype == env.observation_space.dtype
    assert env.observation_space.contains(obs)
    env.action_space.seed(0)
    for _ in range(20):
        out = env.step(env.action_space.sample())
        assert isinstance(out, tuple) and len(out) == 5
        obs, reward, terminated, truncated, info = out
        assert env.observation_space.contains(obs) and obs.dtype == np.float64
        assert isinstance(reward, float) and reward <= 0.0
        assert isinstance(terminated, bool) and isinstance(truncated, bool)
        assert isinstance(info, dict) and "t" in info
    assert env.reset(options={})[0].shape == env.observation_space.shape
    assert env.reset(seed=1, options={"anything": 1})[0].shape == env.observation_space.shape


def test_same_seed_same_bits(env):
    def episode(seed):
        obs0, _ = env.reset(seed=seed)
        env.action_space.seed(seed)
        obs, rewards = [obs0], []
        for _ in range(50):
            o, r, *_ = env.step(env.action_space.sample() * 0.05)
            obs.append(o)
            rewards.append(r)
        return np.array(obs), np.array(rewards)

    a, b, c = episode(123), episode(123), episode(456)
    assert same_bits(a[0], b[0]) and same_bits(a[1], b[1])
    assert not same_bits(a[0], c[0])
    rng = np.random.default_rng(123)
    env.reset(seed=123)
    assert env.np_random.random() == rng.random()


def test_truncated_at_the_end_with_the_runs_metrics(env):
    obs, _ = env.reset(seed=2)
    done, n = False, 0
    while not done:
        q, ref = obs[[0, 1]], obs[[6, 7]]
        assert env.observation_columns[6:8] == ["ref_hip", "ref_knee"]
        obs, reward, terminated, truncated, info = env.step(np.array([600.0, 400.0]) * (ref - q))
        done, n = terminated or truncated, n + 1
    assert truncated and not terminated and n == 300
    assert info["metrics"]["safe_state_entered"] == 0.0


def test_terminated_on_a_supervisor_trip(env):
    env.reset(seed=1)
    terminated = False
    for _ in range(300):  # full torque on the knee drives it into its limit: the supervisor trips
        obs, reward, terminated, truncated, info = env.step(np.array([0.0, env.action_space.high[1]]))
        if terminated or truncated:
            break
    assert terminated and info["safety_state"] in (1, 2)
    assert obs[env.observation_columns.index("state")] == info["safety_state"]


def test_bad_actions(env):
    env.reset()
    with pytest.raises(exotwin.InputError, match="shape"):
        env.step(np.zeros(3))
    with pytest.raises(exotwin.InputError, match="finite"):
        env.step(np.array([np.nan, 0]))


def test_box():
    b = exotwin.Box(-1.0, 2.0, (3,), np.float32, seed=4)
    assert b.low.dtype == np.float32 and b.shape == (3,)
    s = b.sample()
    assert s.dtype == np.float32 and b.contains(s)
    assert same_bits(exotwin.Box(-1.0, 2.0, (3,), seed=4).sample(), exotwin.Box(-1.0, 2.0, (3,), seed=4).sample())
    with pytest.raises(ValueError, match="low > high"):
        exotwin.Box(1.0, 0.0, (2,))
    u = exotwin.Box(-np.inf, np.inf, (4,), seed=1)
    assert np.all(np.isfinite(u.sample()))
