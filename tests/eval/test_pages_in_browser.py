"""The viewer and the report in a real headless Chromium: no console errors, arrow keys move between
steps, the panes hold the recorded prompts, LLM markup stays text. CI installs Debian's chromium."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from more_agent.eval.episode_folder import VIEWER_FILE
from more_agent.eval.report import SourcedRecord
from more_agent.eval.report_writer import write_reports
from more_agent.eval.store import EPISODE_DIRS, EpisodeWriter, episode_dirname
from tests.eval.chromium import Chromium, chromium_or_skip
from tests.eval.conftest import EVIL, Episode

ARROW_RIGHT, ARROW_LEFT = ("ArrowRight", 39), ("ArrowLeft", 37)


@pytest.fixture(scope="module")
def browser() -> Chromium:
    with Chromium(chromium_or_skip()) as b:
        yield b


def test_viewer_steps_with_the_arrow_keys_and_shows_llm_text_as_text(browser: Chromium, llm_episode: Episode) -> None:
    page = browser.page
    page.goto(llm_episode.dir / VIEWER_FILE)
    n = llm_episode.record.high_level_steps
    assert page.js("document.getElementById('counter').textContent") == f"step 1 / {n}"
    first_prompt = llm_episode.requests[0]["messages"][-1]["content"]
    assert first_prompt in page.js("document.getElementById('exchanges').textContent")
    page.press(*ARROW_RIGHT)
    assert page.js("document.getElementById('counter').textContent") == f"step 2 / {n}"
    assert "plan (re-ask 1)" in page.js("document.getElementById('exchanges').textContent")  # after the unparseable answer
    page.press(*ARROW_LEFT)
    page.press(*ARROW_LEFT)  # stays on the first step
    assert page.js("document.getElementById('counter').textContent") == f"step 1 / {n}"
    for _ in range(n):
        page.press(*ARROW_RIGHT)
    assert page.js("document.getElementById('counter').textContent") == f"step {n} / {n}"
    # The last steps' answers hold <script> and <b>: shown as text, never run or rendered.
    shown = page.js("Array.from(document.querySelectorAll('#exchanges pre')).map(e => e.textContent)")
    assert EVIL in shown
    assert page.js("window.__pwned === undefined && document.getElementById('bold') === null")
    assert page.js("document.scripts.length") == 2
    assert page.js("document.querySelectorAll('#map line').length") > 0
    assert page.errors == []


def test_oracle_viewer_and_report_load_without_errors(browser: Chromium, llm_episode: Episode, oracle_episode: Episode,
                                                      tmp_path: Path, pictures_on: None) -> None:
    page = browser.page
    page.goto(oracle_episode.dir / VIEWER_FILE)
    assert page.js("document.getElementById('llmdetail').style.display") == "none"
    assert page.js("document.querySelectorAll('#frames img').length") > 0
    assert page.errors == []

    run = tmp_path / "run"
    (run / EPISODE_DIRS).mkdir(parents=True)
    with EpisodeWriter(run / "episodes.jsonl") as w:
        for ep in (llm_episode, oracle_episode):
            r = ep.record
            shutil.copytree(ep.dir, run / EPISODE_DIRS / episode_dirname(r.task, r.scene, r.seed, r.planner))
            w.append(r)
    paths = write_reports([SourcedRecord(e.record, run) for e in (llm_episode, oracle_episode)], run)
    page.goto(paths[2])
    assert page.js("document.querySelectorAll('img.plot').length") == 4
    assert page.js("Array.from(document.querySelectorAll('img.plot')).every(i => i.complete && i.naturalWidth > 0)")
    assert page.js("document.querySelectorAll('a[href$=\"viewer.html\"]').length") == 2
    assert page.errors == []
