"""The episode viewer's data and page: what each step holds, for an LLM planner and for the oracle."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

from more_agent.cli import app
from more_agent.eval.episode_folder import STEPS_FILE, TIMELINE_FILE, VIEWER_FILE
from more_agent.eval.viewer import render_viewer, safe_json, scene_segments, step_frame_indices, viewer_data
from tests.eval.conftest import EVIL, Episode


def test_every_llm_request_and_answer_is_in_its_step(llm_episode: Episode) -> None:
    data = viewer_data(llm_episode.dir)
    steps = data["steps"]
    assert [s["action"]["name"] for s in steps] == [a.name for a in llm_episode.record.actions]
    exchanges = [x for s in steps for x in s["exchanges"]]
    # Exactly the requests the server saw, in order: room labels, filter, plan, and the re-ask after the bad answer.
    assert [x["messages"] for x in exchanges] == [r["messages"] for r in llm_episode.requests]
    assert {x["purpose"] for x in exchanges} >= {"room", "filter", "plan"}
    assert any(x["answer"] == EVIL for x in exchanges)  # the unparseable answer is kept as it came
    assert sum(s["tokens"] for s in steps) == llm_episode.record.llm_usage.prompt_tokens + llm_episode.record.llm_usage.completion_tokens
    first = steps[0]
    assert first["filtered"] and any(not kept for line in first["scene"] for _, kept in line)
    assert first["map"] is not None and first["map"]["occupancy"].startswith("data:image/png;base64,")
    assert first["frames"] and first["frames"][-1]["rgb"].startswith("data:image/jpeg;base64,")
    assert steps[-1]["goals"] is not None and len(steps[-1]["goals"]) == len(llm_episode.record.goal_conditions)


def test_files_the_viewer_reads_are_written_per_step(llm_episode: Episode) -> None:
    n = llm_episode.record.high_level_steps
    timeline = [json.loads(x) for x in (llm_episode.dir / TIMELINE_FILE).read_text().splitlines()]
    assert [t["step"] for t in timeline] == list(range(n))
    assert timeline[-1]["path_len"] == len(llm_episode.record.trajectory)
    assert timeline[0]["targets"] == ["kitchen_0", "fridge A"]
    frames = [t["frames"] for t in timeline]
    assert frames == sorted(frames) and frames[0] > 0
    assert len((llm_episode.dir / STEPS_FILE).read_text().splitlines()) == n
    graphs = llm_episode.dir / "graphs"
    assert sorted(p.name for p in graphs.iterdir()) == sorted(
        f"step_{i:03d}{suffix}" for i in range(n) for suffix in (".json", "_occupancy.png")
    )  # --viewer skips the slow per-step matplotlib pictures
    assert (llm_episode.dir / VIEWER_FILE).is_file()


def test_oracle_viewer_has_no_llm_panes(oracle_episode: Episode) -> None:
    data = viewer_data(oracle_episode.dir)
    assert oracle_episode.record.success and len(data["steps"]) == oracle_episode.record.high_level_steps
    assert all("exchanges" not in s and "scene" not in s for s in data["steps"])
    assert all(s["map"] is not None and s["frames"] for s in data["steps"])
    assert data["steps"][-1]["goals"] and all(met for _, met in data["steps"][-1]["goals"])


def test_page_cannot_be_broken_out_of(llm_episode: Episode) -> None:
    html = (llm_episode.dir / VIEWER_FILE).read_text()
    assert html.count("</script>") == 2 and "<script>window" not in html and "<b id" not in html
    embedded = re.search(r'<script type="application/json" id="data">(.*?)</script>', html, re.S)
    assert embedded is not None
    answers = [x["answer"] for s in json.loads(embedded.group(1))["steps"] for x in s["exchanges"]]
    assert EVIL in answers  # the data survives the escaping intact
    text = safe_json({"a": "</script>&<!--"})
    assert "<" not in text and "&" not in text and json.loads(text) == {"a": "</script>&<!--"}
    data = viewer_data(llm_episode.dir)
    title = render_viewer({**data, "record": {**data["record"], "task": "<i>t</i>"}})
    assert "<title><i>" not in title and "&lt;i&gt;t&lt;/i&gt;" in title


def test_scene_segments_grey_out_what_the_filter_removed() -> None:
    full = "kitchen_0: fridge A [open, empty], apple A [inside fridge A], table A\nbedroom_0: bed A\nhall_0 (unexplored)"
    kept = "kitchen_0: fridge A [open, empty], apple A [inside fridge A]\nhall_0 (unexplored)"
    lines = scene_segments(full, kept)
    assert ["".join(t for t, _ in line) for line in lines] == full.splitlines()
    assert [(t, k) for t, k in lines[0]] == [
        ("kitchen_0: ", True), ("fridge A [open, empty], ", True), ("apple A [inside fridge A], ", True), ("table A", False),
    ]
    assert all(not k for _, k in lines[1])
    assert lines[2] == [["hall_0 (unexplored)", True]]


def test_frames_of_a_step_are_spread_and_end_with_its_last() -> None:
    assert step_frame_indices(0, 12) == [0, 6, 11]
    assert step_frame_indices(5, 6) == [5]
    assert step_frame_indices(4, 4) == []


def test_view_command_writes_the_page_and_refuses_other_folders(oracle_episode: Episode, tmp_path: Path) -> None:
    out = tmp_path / "page.html"
    result = CliRunner().invoke(app, ["view", str(oracle_episode.dir), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert out.read_text().startswith("<!DOCTYPE html>")
    bad = CliRunner().invoke(app, ["view", str(tmp_path)])
    assert bad.exit_code == 2 and "episode folder (no episode.json)" in " ".join(bad.output.split())


@pytest.mark.slow
def test_run_and_eval_take_viewer(tmp_path: Path) -> None:
    from tests.eval.conftest import KITCHEN, TASK

    out = tmp_path / "ep"
    result = CliRunner().invoke(app, ["run", TASK, "--scene", str(KITCHEN), "--out", str(out), "--viewer"])
    assert result.exit_code == 0, result.output
    assert (out / VIEWER_FILE).is_file() and (out / "frames").is_dir()
    both = ["eval", "--tasks", TASK, "--planner", "oracle", "--out", str(tmp_path / "r"), "--viewer",
            "--episode-fn", "tests.eval.fake_episodes:deterministic_episode"]
    refused = CliRunner().invoke(app, both)
    assert refused.exit_code == 2 and "--episode-fn" in refused.output


def test_an_episode_folder_with_only_its_record_still_opens(tmp_path: Path) -> None:
    from more_agent.records import ActionRecord, EpisodeRecord

    record = EpisodeRecord(task="t", scene="s", seed=0, planner="oracle", trajectory=[(0.0, 0.0), (1.0, 1.0)],
                           actions=[ActionRecord(step=0, name="navigate", arguments=["x"], ok=False, feedback=EVIL)],
                           high_level_steps=1, termination="step_limit")
    (tmp_path / "episode.json").write_text(record.model_dump_json())
    step = viewer_data(tmp_path)["steps"][0]
    assert step["action"]["feedback"] == EVIL and step["map"] is None and step["frames"] == [] and step["goals"] is None
    assert "<b id" not in render_viewer(viewer_data(tmp_path))


def test_images_of_vlm_requests_become_small_thumbnails(tmp_path: Path) -> None:
    import base64
    import io

    from PIL import Image

    from more_agent.records import ActionRecord, EpisodeRecord

    buf = io.BytesIO()
    Image.new("RGB", (512, 512), (200, 30, 30)).save(buf, format="PNG")
    image = "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode()
    record = EpisodeRecord(task="t", scene="s", seed=0, planner="bumble", llm="openai:m", high_level_steps=1,
                           actions=[ActionRecord(step=0, name="done", ok=True)])
    (tmp_path / "episode.json").write_text(record.model_dump_json())
    content = [{"type": "text", "text": "which object?"}, {"type": "image_url", "image_url": {"url": image}},
               {"type": "image_url", "image_url": {"url": "https://example.com/x.png"}}]
    exchange = {"purpose": "plan", "model": "m", "messages": [{"role": "user", "content": content}], "answer": EVIL,
                "prompt_tokens": 1, "completion_tokens": 1, "latency_s": 0.1, "cached": False}
    (tmp_path / STEPS_FILE).write_text(json.dumps({"step": 0, "exchanges": [exchange]}) + "\n")
    parts = viewer_data(tmp_path)["steps"][0]["exchanges"][0]["messages"][0]["content"]
    assert parts[0] == content[0]
    thumb = parts[1]["image_url"]["url"]
    assert thumb.startswith("data:image/jpeg;base64,")
    with Image.open(io.BytesIO(base64.b64decode(thumb.split(",", 1)[1]))) as im:
        assert im.size == (128, 128)
    assert parts[2]["image_url"]["url"] == ""  # never a remote address in the page


def test_recording_client_is_transparent_and_records_unparseable_answers() -> None:
    from more_agent.llm.completion import Completion, TokenUsage
    from more_agent.llm.errors import Unparseable
    from more_agent.planners.exchanges import CallLog, RecordingClient

    answer = Completion(text="no json", parsed=None, model="m", usage=TokenUsage(3, 4), cost_usd=0.0, cost_known=False,
                        cached=True, latency_s=0.01, attempts=0, purpose="plan")

    class Inner:
        model = "m"
        cache = "the cache"

        def complete(self, messages, *, schema=None, purpose="", attempt=0):  # noqa: ANN001, ANN202
            raise Unparseable("no JSON", completion=answer)

    log = CallLog()
    client = RecordingClient(Inner(), log)
    assert client.model == "m" and client.cache == "the cache"
    with pytest.raises(Unparseable):
        client.complete([{"role": "user", "content": "hi"}], purpose="plan")
    assert [x.to_json()["answer"] for x in log.exchanges] == ["no json"] and log.exchanges[0].to_json()["cached"] is True
    usage = log.usage()  # an unusable answer is still paid for: counted once, as it arrived
    assert (usage.calls, usage.prompt_tokens, usage.completion_tokens, usage.cache_hits) == (1, 3, 4, 1)
    log.new_step()
    assert log.exchanges == [] and log.usage().calls == 1
