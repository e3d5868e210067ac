"""The package imports downward only: a module never imports one of a higher layer, and no files
import each other in a circle. Lazy imports inside functions count too."""

from __future__ import annotations

import ast
from functools import cache
from pathlib import Path

import more_agent

ROOT = Path(more_agent.__file__).parent

LAYERS = (
    ("__init__", "errors", "redaction", "interrupts", "records", "record_validation", "safe_files", "skills",
     "robot_spec", "vocabulary", "robot", "goal", "perception_spec", "sensing_spec"),
    ("sim",),
    ("perception",),
    ("mapping",),
    ("scene_graph",),
    ("interop",),
    ("llm",),
    ("viz",),
    ("planners",),
    ("eval", "service"),
    ("commands", "cli"),
)
"""Bottom to top: each part may import its own layer's parts and those below."""


def _module(path: Path) -> str:
    return ".".join(("more_agent", *path.relative_to(ROOT).with_suffix("").parts)).removesuffix(".__init__")


def _imports(path: Path, module: str, modules: set[str]) -> set[str]:
    """The more_agent modules that ``module`` (at ``path``) imports: the longest existing module of each
    name, its own ancestor packages left out (a submodule may use its package's exports)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module and not node.level:
            names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        else:
            continue
        for name in names:
            while name and name not in modules:
                name = name.rpartition(".")[0]
            if name and name != module and not module.startswith(name + "."):
                found.add(name)
    return found


@cache
def _graph() -> dict[str, set[str]]:
    """Module -> the more_agent modules it imports; parsed once for the tests below (neither changes it)."""
    paths = {_module(p): p for p in ROOT.rglob("*.py")}
    return {m: _imports(p, m, set(paths)) for m, p in paths.items()}


def _layer(module: str) -> int:
    part = module.split(".")[1] if "." in module else "__init__"
    return next(i for i, names in enumerate(LAYERS) if part in names)


def test_no_module_imports_a_higher_layer() -> None:
    upward = sorted(f"{m} -> {t}" for m, targets in _graph().items() for t in targets if _layer(t) > _layer(m))
    assert not upward, "\n".join(upward)


def test_no_file_cycles() -> None:
    graph = _graph()
    state: dict[str, int] = {}
    cycles: list[str] = []

    def visit(m: str, stack: list[str]) -> None:
        state[m] = 1
        for t in sorted(graph.get(m, ())):
            if state.get(t) == 1:
                cycles.append(" -> ".join(stack[stack.index(t):] + [m, t]) if t in stack else f"{m} -> {t}")
            elif t not in state:
                visit(t, stack + [m])
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m, [])
    assert not cycles, "\n".join(cycles)


def test_the_checks_see_an_upward_import(tmp_path: Path) -> None:
    bad = tmp_path / "bad.py"
    bad.write_text("def f():\n    from more_agent.eval.episode import run_episode\n", encoding="utf-8")
    modules = set(_graph())
    assert _imports(bad, "more_agent.sim.bad", modules) == {"more_agent.eval.episode"}
    assert _layer("more_agent.eval.episode") > _layer("more_agent.sim.world")
