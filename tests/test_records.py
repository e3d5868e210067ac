"""Episode records: typed endings and reasons, and records of older schema versions read as today's."""

from __future__ import annotations

from more_agent.records import RECORD_SCHEMA_VERSION, EpisodeRecord, FailureReason

BASE = {"task": "t", "scene": "s", "seed": 0, "planner": "more"}


def _v2(**fields: object) -> EpisodeRecord:
    return EpisodeRecord.model_validate({"schema_version": 2, **BASE, **fields})


def test_version_2_endings_become_typed() -> None:
    limit = _v2(error="step limit of 50 high-level steps reached")
    assert (limit.termination, limit.error, limit.schema_version) == ("step_limit", None, RECORD_SCHEMA_VERSION)
    after = _v2(error="acted for more than 5 steps after all goal conditions held, without done()")
    assert (after.termination, after.error) == ("steps_after_goal", None)
    gave_up = _v2(done_called=True, error="no free surface")
    assert (gave_up.termination, gave_up.gave_up, gave_up.error) == ("done", "no free surface", None)


def test_version_2_system_errors_keep_their_text_and_get_a_kind() -> None:
    llm = _v2(error="LLM error (LLMTimeout): slow", retryable=True)
    assert (llm.error, llm.error_kind, llm.termination) == ("LLM error (LLMTimeout): slow", "llm", None)
    assert _v2(error="ValueError: x", traceback="...").error_kind == "crash"
    assert _v2(error="unknown task 'x'").error_kind == "input"


def test_version_2_actions_read_without_reasons() -> None:
    record = _v2(actions=[{"step": 0, "name": "explore", "arguments": ["kitchen_0"], "ok": False, "feedback": "no"}])
    assert record.actions[0].reason is None


def test_today_s_records_round_trip_their_types() -> None:
    record = EpisodeRecord.model_validate({
        **BASE, "termination": "step_limit",
        "actions": [{"step": 0, "name": "navigate", "ok": False, "reason": "path_blocked_by_door"}],
    })
    again = EpisodeRecord.model_validate_json(record.model_dump_json())
    assert again == record and again.actions[0].reason is FailureReason.PATH_BLOCKED_BY_DOOR
    assert again.error is None and again.termination == "step_limit"
