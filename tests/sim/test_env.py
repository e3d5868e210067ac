"""The Gymnasium environment: API conformance, determinism, the initial turn, actions and bad input."""

from __future__ import annotations

import math
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import more_agent.sim  # noqa: F401  (registers the environment)
from more_agent.sim.env import ACTION_TYPES, ENV_ID, MoreAgentEnv, frame_from_observation, make_action
from more_agent.sim.instantiate import instantiate_in_scene
from more_agent.sim.scene import load_scene
from more_agent.sim.world import World

FIXTURES = Path(__file__).parent.parent / "fixtures"
TINY = str(FIXTURES / "tiny_scene.json")


@pytest.fixture(scope="module")
def env() -> MoreAgentEnv:
    return MoreAgentEnv(scene=TINY)


def test_passes_gymnasium_env_checker():
    env = gym.make(ENV_ID, scene=TINY, render_mode="rgb_array")
    check_env(env.unwrapped)
    env.reset(seed=0)
    assert env.render().shape == (256, 256, 3)


def test_default_env_resets_without_options():
    obs, info = MoreAgentEnv().reset(seed=3)
    assert obs in MoreAgentEnv().observation_space and info["task"] is None and "goal_status" not in info


def test_same_seed_same_frames(env):
    obs_a, info_a = env.reset(seed=7)
    step_a = env.step(make_action("move_forward"))
    obs_b, info_b = env.reset(seed=7)
    step_b = env.step(make_action("move_forward"))
    for key in obs_a:
        assert np.array_equal(obs_a[key], obs_b[key]) and np.array_equal(step_a[0][key], step_b[0][key])
    assert len(info_a["turn_frames"]) == len(info_b["turn_frames"])
    for fa, fb in zip(info_a["turn_frames"], info_b["turn_frames"], strict=True):
        assert np.array_equal(fa["obs"]["depth"], fb["obs"]["depth"]) and fa["instances"] == fb["instances"]
    other, _ = env.reset(seed=8)
    assert not np.array_equal(other["robot_pose"], obs_a["robot_pose"])


def test_episode_starts_with_a_full_turn(env):
    obs, info = env.reset(seed=0)
    frames = info["turn_frames"]
    yaws = np.array([f["obs"]["robot_pose"][2] for f in frames])
    steps = np.diff(np.unwrap(yaws))
    assert len(frames) == 11 and np.allclose(steps, 2 * math.pi / 11) and steps.max() <= math.radians(35)
    assert info["low_level_steps"] == 11 and np.array_equal(obs["rgb"], frames[0]["obs"]["rgb"])
    assert {"label", "category", "open", "held"} <= set(next(iter(info["instances"].values())))


def test_depth_observation_uses_zero_for_invalid(env):
    obs, _ = env.reset(seed=1)
    frame = frame_from_observation(obs)
    invalid = obs["depth"] == 0
    assert np.array_equal(np.isnan(frame.depth), invalid) and np.array_equal(frame.semantic[invalid], np.zeros(invalid.sum()))


@pytest.mark.parametrize("action, reason", [
    (make_action("open", "no such thing"), "unknown_object"),
    ({"type": 99}, "invalid_action"),
    ("forward", "invalid_action"),
    ({"type": ACTION_TYPES.index("turn_left"), "amount": "lots"}, "invalid_action"),
    ({"type": ACTION_TYPES.index("move_forward"), "amount": float("nan")}, "invalid_amount"),
    ({"type": ACTION_TYPES.index("grasp"), "target": 3}, "invalid_action"),
])
def test_bad_input_is_reported_and_the_episode_goes_on(env, action, reason):
    obs, _ = env.reset(seed=2)
    after, reward, terminated, truncated, info = env.step(action)
    assert info["action_ok"] is False and info["reason"] == reason and info["feedback"]
    assert not terminated and not truncated and np.array_equal(after["robot_pose"], obs["robot_pose"])


def test_low_level_moves_done_and_truncation():
    env = MoreAgentEnv(scene=TINY, max_steps=3)
    obs, _ = env.reset(seed=4)
    _, _, _, _, info = env.step(make_action("turn_right", amount=math.radians(90)))
    assert info["action_ok"] and "clipped" in info["feedback"]
    yaw = env.world.robot.yaw
    assert math.isclose(math.remainder(obs["robot_pose"][2] - math.radians(35) - yaw, 2 * math.pi), 0.0, abs_tol=1e-6)
    _, _, terminated, truncated, _ = env.step(make_action("turn_left"))
    assert not terminated and not truncated
    _, _, terminated, truncated, _ = env.step(make_action("turn_left"))
    assert truncated and not terminated
    env.reset(seed=4)
    _, _, terminated, truncated, info = env.step(make_action("done"))
    assert terminated and not truncated and info["action_ok"]


def test_task_episode_reports_goal_progress_and_rewards_it():
    instance = instantiate_in_scene("putting_shopping_away", load_scene(FIXTURES / "tasks_kitchen_scene.json"), seed=0)
    env = MoreAgentEnv(privileged_info=True)
    _, info = env.reset(seed=0, options={"instance": instance})
    assert env.world is instance.world and info["goal_status"].progress == 0.0 and info["task_description"]
    beef = "pack__of__ground_beef_1"  # a world name: its label only exists once the robot has seen it
    rewards = []
    for action in (make_action("open", "fridge A"), make_action("grasp", beef), make_action("place_inside", "fridge_0")):
        _, reward, _, _, info = env.step(action)
        assert info["action_ok"], info["feedback"]
        rewards.append(reward)
    assert rewards == [0.0, 0.0, pytest.approx(0.2)] and info["goal_status"].progress == pytest.approx(0.2)
    assert info["low_level_steps"] > 1 and info["path_frames"] and len(info["path"]) >= 2


def test_goal_state_is_privileged_but_the_reward_is_not():
    instance = instantiate_in_scene("putting_shopping_away", load_scene(FIXTURES / "tasks_kitchen_scene.json"), seed=0)
    env = MoreAgentEnv()
    _, info = env.reset(seed=0, options={"instance": instance})
    rewards = []
    for action in (make_action("open", "fridge A"), make_action("grasp", "pack__of__ground_beef_1"),
                   make_action("place_inside", "fridge_0")):
        _, reward, _, _, info = env.step(action)
        assert "goal_status" not in info
        rewards.append(reward)
    assert rewards == [0.0, 0.0, pytest.approx(0.2)]


def test_without_sensors_an_injected_world_steps_unrendered_and_unturned():
    world = World.from_scene(load_scene(TINY))
    world.set_robot_pose(world.robot.x, world.robot.y, 0.0)
    env = MoreAgentEnv(sensors=False, max_steps=None)
    obs, info = env.reset(options={"world": world})
    assert env.world is world and set(obs) == {"robot_pose", "held"} and obs in env.observation_space
    assert info["turn_frames"] == [] and info["total_low_level_steps"] == 0
    obs, _, _, truncated, info = env.step(make_action("turn_right", amount=0.25))
    assert world.robot.yaw == pytest.approx(-0.25) and obs["robot_pose"][2] == pytest.approx(-0.25)
    assert info["instances"] == {} and info["path_frames"] == [] and not truncated
