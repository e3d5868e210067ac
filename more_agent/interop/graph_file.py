"""``read_graph``: a scene graph from a file or a request body, ours (versioned JSON with
``schema_version``) or Spark-DSG's (its JSON, or its binary ``.sparkdsg`` / ``.bson`` files)."""

from __future__ import annotations

import json
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from more_agent.errors import UserError
from more_agent.interop.spark_dsg import load_spark_dsg
from more_agent.scene_graph import SceneGraph
from more_agent.scene_graph.export import load_scene_graph


class GraphFileError(UserError):
    """A file or body that is no scene graph MORE reads (the message says why)."""


def read_graph(path: Path, label_map: Mapping[int, str] | None = None) -> SceneGraph:
    """The scene graph in ``path``: ours when its JSON has ``schema_version``, else Spark-DSG's."""
    path = Path(path)
    if not path.is_file():
        raise GraphFileError(f"no graph file at {path}")
    if path.suffix != ".json":
        return load_spark_dsg(path, label_map)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise GraphFileError(f"{path} is not JSON: {e}") from None
    return graph_from_json(data, label_map, source=str(path))


def graph_from_json(data: Any, label_map: Mapping[int, str] | None = None, *, source: str = "graph") -> SceneGraph:
    """A scene graph from parsed JSON: ours (``schema_version``) or a Spark-DSG JSON object."""
    if not isinstance(data, dict):
        raise GraphFileError(f"{source}: a scene graph is a JSON object, not {type(data).__name__}")
    if "schema_version" in data:
        try:
            return load_scene_graph(json.dumps(data))
        except (ValueError, ValidationError) as e:
            raise GraphFileError(f"{source}: not a valid MORE scene graph: {_first_line(e)}") from None
    with tempfile.TemporaryDirectory() as tmp:  # spark-dsg loads JSON from files only
        file = Path(tmp) / "graph.json"
        file.write_text(json.dumps(data), encoding="utf-8")
        return load_spark_dsg(file, label_map)


def read_label_map(path: Path) -> dict[int, str]:
    """A label map file: JSON ``{"<semantic label>": "<class name>"}``."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
        return {int(k): str(v) for k, v in data.items()}
    except (OSError, ValueError, AttributeError) as e:
        raise UserError(f"--label-map {path}: expected a JSON object of semantic label -> class name ({e})") from None


def _first_line(e: Exception) -> str:
    return " ".join(str(e).splitlines()[:3])
