"""``more-agent scene ...`` commands: list, show, generate, render, and clean user errors."""

import json

from typer.testing import CliRunner

from more_agent.cli import app
from more_agent.sim.scene import load_scene

runner = CliRunner()


def test_list_and_show():
    r = runner.invoke(app, ["scene", "list"])
    assert r.exit_code == 0 and "Rs_int" in r.output and "office_large" in r.output
    r = runner.invoke(app, ["scene", "show", "Rs_int", "--seed", "1"])
    assert r.exit_code == 0 and "kitchen_0" in r.output and "doors" in r.output


def test_unknown_scene_exits_2_with_closest_names():
    r = runner.invoke(app, ["scene", "show", "Rs_inr"])
    assert r.exit_code == 2 and "Rs_int" in r.output and "Traceback" not in r.output


def test_generate_writes_loadable_json(tmp_path):
    out = tmp_path / "s.json"
    r = runner.invoke(app, ["scene", "generate", "Rs_int", "--seed", "2", "--out", str(out)])
    assert r.exit_code == 0
    s = load_scene(out)
    assert s.name == "Rs_int" and s.seed == 2


def test_malformed_json_exits_2_naming_field(tmp_path):
    data = json.loads(open("tests/fixtures/tiny_scene.json").read())
    data["doors"][0]["width"] = -1
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(data))
    r = runner.invoke(app, ["scene", "show", str(p)])
    assert r.exit_code == 2 and "doors[0].width" in r.output and "Traceback" not in r.output


def test_render_writes_png(tmp_path):
    out = tmp_path / "plan.png"
    r = runner.invoke(app, ["scene", "render", "Rs_garden", "--out", str(out)])
    assert r.exit_code == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out.stat().st_size > 10_000
    r = runner.invoke(app, ["scene", "render", "tests/fixtures/tiny_scene.json", "--out", str(out)])
    assert r.exit_code == 0
