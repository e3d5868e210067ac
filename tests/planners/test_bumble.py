"""The BUMBLE planners against a fake OpenAI server speaking the chat API, images included."""

from __future__ import annotations

import io
import json
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

from more_agent.eval.episode import run_episode
from more_agent.eval.episode_folder import STEPS_FILE, VLM_IMAGES_DIR
from more_agent.llm import CacheMode, LLMConfig, make_client
from more_agent.llm.images import LOW_DETAIL_TOKENS
from more_agent.planners.bumble import BUMBLE_CONFIGS, BumblePlanner
from more_agent.planners.bumble_memory import HISTORY_IMAGES, RIGHT, WRONG
from more_agent.planners.set_of_marks import annotate_marks
from more_agent.records import EpisodeRecord, EpisodeSpec
from more_agent.sensing_spec import SensingCadence
from more_agent.skills import INVALID
from tests.fakes.openai_server import request_images, request_text
from tests.planners.brain import BrainServer
from tests.planners.test_llm_episode import GOAL, KITCHEN, TASK
from tests.planners.vlm_brain import RearrangeVLM, kind, step

SPEC = EpisodeSpec(task=TASK, scene=str(KITCHEN), seed=2, planner="bumble", llm="openai:fake-model")  # a seed whose start sees too little to act at once


def _run(server: BrainServer, tmp_path: Path, planner: str = "bumble", **kw: Any) -> tuple[EpisodeRecord, BumblePlanner]:
    base = dict(base_url=server.base_url, api_key="sk-test", timeout_s=2.0, max_retries=0,
                cache_path=tmp_path / "cache.sqlite")
    client = make_client("openai:fake-model", LLMConfig(**{**base, **kw}))
    bumble = BumblePlanner(BUMBLE_CONFIGS[planner], client, "openai:fake-model")
    record = run_episode(SPEC.model_copy(update={"planner": planner}), planner=bumble, out_dir=tmp_path / "ep")
    return record, bumble


def _decode(png: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))


@pytest.fixture(scope="module")
def solved(tmp_path_factory: pytest.TempPathFactory) -> tuple[EpisodeRecord, BumblePlanner, BrainServer, Path]:
    tmp = tmp_path_factory.mktemp("bumble")
    with BrainServer(RearrangeVLM(GOAL)) as server:
        record, planner = _run(server, tmp)
    return record, planner, server, tmp


def test_explore_takes_the_room_its_chosen_frontiers_lie_in(solved: Any) -> None:
    """The skill table's explore(room): the room of most frontiers the picked frame shows, named as the scene
    text names rooms (BUMBLE labels none: unknown_room_<k>)."""
    record = solved[0]
    explores = [a for a in record.actions if a.name == "explore"]
    assert explores and all(re.fullmatch(r"unknown_room_\d+", *a.arguments) for a in explores), explores


def test_the_robot_senses_at_least_as_often_as_the_memory_keeps_frames(solved: Any) -> None:
    """BUMBLE samples its camera continuously: the default 1m/45deg mapper cadence does not thin its buffer."""
    record, planner = solved[0], solved[1]
    assert record.sensing == "1m/45deg"
    assert planner.body.schedule.cadence == planner.config.memory.keep == SensingCadence(distance_m=0.5, angle_deg=30)


def test_scripted_vlm_completes_the_episode(solved: Any) -> None:
    record, _, server, tmp = solved
    assert record.error is None and record.success and record.done_called, record.actions
    names = [a.name for a in record.actions]
    assert "go_to_and_open" in names and "go_to_and_place_inside" in names
    assert record.llm_usage.calls == len(server.requests)
    assert record.llm_usage.images == sum(len(request_images(r.body)) for r in server.requests) > 0
    assert record.llm_usage.image_tokens == LOW_DETAIL_TOKENS * record.llm_usage.images
    steps = [json.loads(line) for line in (tmp / "ep" / STEPS_FILE).read_text().splitlines()]
    assert len(steps) == record.high_level_steps and steps[0]["buffer_frames"] > 5


def test_requests_carry_decodable_pngs_of_the_frame_size_within_the_bound(solved: Any) -> None:
    """Frames and current views at full size (at most max_images frames); earlier steps' views downscaled."""
    _, planner, server, _ = solved
    for r in server.requests:
        current = request_images({"messages": r.body["messages"][-1:]})
        assert len(current) <= planner.config.memory.max_images
        for png in current:
            assert _decode(png).shape == (256, 256, 3)
        remembered = request_images({"messages": r.body["messages"][1:-1]})
        assert len(remembered) <= HISTORY_IMAGES and all(_decode(png).shape == (128, 128, 3) for png in remembered)
        for m in r.body["messages"]:
            if isinstance(m["content"], list):
                assert all(p["image_url"]["detail"] == "low" for p in m["content"] if p["type"] == "image_url")
    kinds = {kind(r.body) for r in server.requests}
    assert {"plan", "landmark", "object"} <= kinds


def test_short_term_memory_sends_every_earlier_step_with_its_view(solved: Any) -> None:
    """BUMBLE's episodic history: step k's plan request holds the k-1 earlier steps, each answered by a verdict."""
    record, _, server, _ = solved
    plans = [r.body for r in server.requests if kind(r.body) == "plan" and "cannot be used" not in request_text(r.body)]
    assert len(plans) == record.high_level_steps >= 3
    for k, body in enumerate(plans):
        steps = [m for m in body["messages"] if m["role"] == "user" and isinstance(m["content"], list)
                 and m["content"][0]["text"].startswith("Step ")]
        assert len(steps) == k and len(request_images({"messages": steps})) == min(k, HISTORY_IMAGES)
        verdicts = [m["content"] for m in body["messages"] if m["role"] == "assistant"]
        assert verdicts == [RIGHT if a.ok else WRONG for a in record.actions[:k]]
        for step_message, action in zip(steps, record.actions, strict=False):
            assert f"skill: {action.name}; success: {'yes' if action.ok else 'no'}" in step_message["content"][0]["text"]
    assert "analyse step by step" in plans[0]["messages"][0]["content"] and "within reach" in plans[0]["messages"][0]["content"]


def test_marks_sent_are_drawn_on_the_listed_objects(solved: Any) -> None:
    """Each object question's image is the picked memory frame with a mark k on the object listed as k."""
    _, planner, server, tmp = solved
    steps = [json.loads(line) for line in (tmp / "ep" / STEPS_FILE).read_text().splitlines()]
    marked_steps = [s for s in steps if s["marks"]]
    questions = [r for r in server.requests if kind(r.body) == "object"]
    assert len(questions) == len(marked_steps) > 0
    objects = planner.graph.objects
    for request, logged in zip(questions, marked_steps, strict=True):
        listed = [line.split(": ", 1) for line in request_text(request.body).splitlines() if line[:1].isdigit()]
        marks = {int(k): o for k, o in logged["marks"].items()}
        assert [int(k) for k, _ in listed] == sorted(marks)
        assert all(d.split(" [")[0] == objects[marks[int(k)]].label for k, d in listed)
        frame = planner.memory.frames[logged["frame"]]
        instance = frame.instance()
        drawn = annotate_marks(frame.rgb(), instance, [objects[marks[k]].instance_id for k in sorted(marks)])
        (png,) = request_images(request.body)
        assert np.array_equal(_decode(png), drawn.rgb)
        for mark in drawn.marks:
            u, v = mark.anchor
            assert instance[v, u] == objects[marks[mark.number]].instance_id


def test_a_mark_sits_on_its_object_and_background_is_never_marked(solved: Any) -> None:
    _, planner, _, _ = solved
    frame = max(planner.memory.frames, key=lambda f: len(f.instance_ids))
    instance = frame.instance()
    drawn = annotate_marks(frame.rgb(), instance, [0, *sorted(frame.instance_ids)])
    assert [m.instance_id for m in drawn.marks] == sorted(frame.instance_ids)  # 0 (floor, walls) gets none
    for mark in drawn.marks:
        u, v = mark.anchor
        assert instance[v, u] == mark.instance_id
        mask = instance == mark.instance_id
        assert (drawn.rgb[mask] != frame.rgb()[mask]).any()  # outline or disc drawn on it


class Short:
    """``RearrangeVLM`` that ends the episode at its third step decision; with ``question``, it first
    answers that question (landmark or object) ``bad`` times with an out-of-range number."""

    def __init__(self, question: str = "", bad: int = 0) -> None:
        self.question, self.bad = question, bad
        self.inner = RearrangeVLM(GOAL)
        self.plans = 0

    def __call__(self, body: dict[str, Any]) -> str:
        if kind(body) == "plan":
            self.plans += 1
            if self.plans == 3:
                return step("done", "stop here")
        if kind(body) == self.question and self.bad > 0:
            self.bad -= 1
            return json.dumps({"reasoning": "", "frame" if self.question == "landmark" else "mark": 99})
        return self.inner(body)


@pytest.mark.parametrize("question", ["landmark", "object"])
def test_invalid_index_is_reasked_then_an_invalid_action(tmp_path: Path, question: str) -> None:
    with BrainServer(Short(question, bad=1)) as server:
        record, _ = _run(server, tmp_path / "once")
    assert record.error is None and INVALID not in [a.name for a in record.actions]  # one re-ask fixed it
    reasks = [r for r in server.requests if "cannot be used" in request_text(r.body)]
    assert reasks and "99" in request_text(reasks[0].body)

    brain = Short(question, bad=3)  # the first ask and both re-asks are wrong
    with BrainServer(brain) as server:
        record, _ = _run(server, tmp_path / "thrice")
    assert record.error is None and record.traceback is None
    acted = next(a for a in record.actions if a.name != "explore")
    assert acted.name == INVALID and not acted.ok
    assert "invalid answer" in acted.feedback and "99" in acted.feedback


def test_replay_from_the_cache_gives_the_same_episode(tmp_path: Path) -> None:
    with BrainServer(Short()) as server:
        first, _ = _run(server, tmp_path)
        replayed, _ = _run(server, tmp_path, cache_mode=CacheMode.REPLAY)
    assert first.error is None and replayed.error is None and first.llm_usage.images > 0
    assert [(a.name, a.arguments, a.ok) for a in replayed.actions] == [(a.name, a.arguments, a.ok) for a in first.actions]
    assert replayed.trajectory == first.trajectory
    assert replayed.llm_usage.cache_hits == replayed.llm_usage.calls == first.llm_usage.calls
    assert replayed.llm_usage.images == first.llm_usage.images


def test_filtering_marks_only_task_objects_and_their_containers(tmp_path: Path) -> None:
    with BrainServer(Short()) as server:
        record, _ = _run(server, tmp_path, planner="bumble-filter")
    assert record.error is None and any(kind(r.body) == "filter" for r in server.requests)
    task_objects = set(GOAL) | set(GOAL.values())
    listed = 0
    for r in server.requests:
        if kind(r.body) == "plan":  # the current view's annotations are filtered, memory frames are not
            marks = (re.match(r"\d+: (.*)", line) for line in request_text(r.body).splitlines())
            entries = [m.group(1) for m in marks if m]
            holders = {m for e in entries for m in re.findall(r"\[inside ([^\]]+)\]", e)}
            assert {re.split(r" \[|, ", e)[0] for e in entries} <= task_objects | holders, entries
            listed += len(entries)
    assert listed > 0


def test_cli_runs_bumble_filter_against_a_local_server(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from typer.testing import CliRunner

    from more_agent.cli import app

    with BrainServer(Short()) as server:
        env = {"OPENAI_BASE_URL": server.base_url, "OPENAI_API_KEY": "sk-test", "MORE_AGENT_LLM": "",
               "MORE_AGENT_LLM_CONFIG": "", "MORE_AGENT_LLM_CACHE": str(tmp_path / "cache.sqlite")}
        for name, value in env.items():
            monkeypatch.setenv(name, value)
        result = CliRunner().invoke(app, ["run", TASK, "--scene", str(KITCHEN), "--planner", "bumble-filter",
                                          "--llm", "openai:fake-model", "--out", str(tmp_path / "ep"), "--save-frames"])
    assert result.exit_code == 0, result.output
    record = json.loads((tmp_path / "ep" / "episode.json").read_text())
    assert record["planner"] == "bumble-filter" and record["error"] is None and record["done_called"]
    assert record["llm_usage"]["images"] == sum(len(request_images(r.body)) for r in server.requests) > 0
    views = sorted((tmp_path / "ep" / VLM_IMAGES_DIR).glob("step_*_view.png"))
    assert len(views) == record["high_level_steps"]  # the annotated view of every step decision
    first_plan = next(r for r in server.requests if kind(r.body) == "plan")
    assert request_images(first_plan.body) == [views[0].read_bytes()]
