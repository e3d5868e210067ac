"""Metric definitions on hand-made records: SR, TTC, TP, rTP, intervals, grouping."""

from __future__ import annotations

import json

import pytest

from more_agent.eval.metrics import (
    bootstrap_interval,
    by_system,
    by_task,
    estimate,
    paired_sr,
    rtp,
    sr,
    summarize,
    system_label,
    tp,
    ttc,
    wilson_interval,
)
from more_agent.records import EpisodeRecord, GoalCondition


def rec(task: str = "t", *, conds: list[tuple[bool, list[str]]] = (), observed: list[str] = (), **kw) -> EpisodeRecord:
    goal = [GoalCondition(text=f"c{i}", satisfied=s, objects=o) for i, (s, o) in enumerate(conds)]
    met = sum(c.satisfied for c in goal)
    defaults = dict(
        task=task,
        scene="Rs_int",
        seed=0,
        planner="more",
        goal_conditions=goal,
        observed_objects=list(observed),
        task_progress=met / len(goal) if goal else 0.0,
        all_goals_met=bool(goal) and met == len(goal),
    )
    return EpisodeRecord(**{**defaults, **kw})


def test_sr_needs_done_but_ttc_does_not() -> None:
    all_met_no_done = rec(conds=[(True, ["a"])], done_called=False, success=False)
    all_met_done = rec(conds=[(True, ["a"])], done_called=True, success=True)
    assert (sr(all_met_no_done), ttc(all_met_no_done)) == (0.0, 1.0)
    assert (sr(all_met_done), ttc(all_met_done)) == (1.0, 1.0)


def test_tp_is_share_of_conditions_met() -> None:
    r = rec(conds=[(True, ["a"]), (False, ["b"]), (True, ["c"]), (False, ["d"])])
    assert tp(r) == pytest.approx(0.5)


def test_rtp_counts_the_conditions_that_include_an_observed_task_object() -> None:
    r = rec(
        conds=[(True, ["a", "floor"]), (False, ["b", "table"]), (False, ["c", "shelf"]), (True, ["d", "shelf"])],
        observed=["a", "b", "d"],  # 'c' and 'shelf' unseen -> condition 2 excluded; a floor is never "seen"
    )
    assert rtp(r) == pytest.approx(2 / 3)
    assert tp(r) == pytest.approx(2 / 4)


def test_rtp_is_none_when_nothing_observed_and_condition_without_objects_counts() -> None:
    assert rtp(rec(conds=[(True, ["a"]), (True, ["b"])], observed=[])) is None
    assert rtp(rec(conds=[], observed=["a"])) is None
    assert rtp(rec(conds=[(True, []), (False, ["x"])], observed=[])) == 1.0


def test_an_episode_without_rtp_leaves_the_mean_instead_of_counting_zero() -> None:
    """Why rTP came out below TP: an episode that saw none of its task objects counted rTP 0 while its
    TP kept the conditions that hold without the robot (a fridge left closed: 'not open')."""
    blind = rec(conds=[(True, ["fridge"]), (False, ["apple", "fridge"])], observed=[])
    found = rec(conds=[(True, ["a", "shelf"]), (True, ["b", "shelf"]), (False, ["c", "shelf"])], observed=["a", "b"])
    s = summarize([blind, found])
    assert s.TP.mean == pytest.approx((1 / 2 + 2 / 3) / 2)
    assert s.rTP is not None and (s.rTP.mean, s.rTP.n) == (pytest.approx(1.0), 1) and s.rTP.mean > s.TP.mean
    assert summarize([blind]).rTP is None and summarize([blind]).TP.n == 1


def test_records_of_older_versions_get_the_same_rtp_from_their_conditions() -> None:
    """rTP is never stored: a record as version 2 wrote it is scored by the rule of today."""
    old = rec(conds=[(True, ["a", "fridge"]), (False, ["b", "fridge"])], observed=["a"], llm="openai:gpt-4o")
    data = old.model_dump(mode="json", exclude={"history"}) | {"schema_version": 2}
    again = EpisodeRecord.model_validate_json(json.dumps(data))
    assert rtp(again) == rtp(old) == 1.0 and again.history == "lasting"  # what version 2 showed an LLM planner
    assert EpisodeRecord.model_validate({**data, "llm": None}).history == "paper"


def test_wilson_interval_known_values() -> None:
    assert wilson_interval(0, 10) == pytest.approx((0.0, 0.27753), abs=1e-4)
    assert wilson_interval(5, 10) == pytest.approx((0.23659, 0.76341), abs=1e-4)
    assert wilson_interval(10, 10)[1] == pytest.approx(1.0)
    assert wilson_interval(0, 0) == (0.0, 1.0)


def test_bootstrap_interval_deterministic_and_brackets_mean() -> None:
    values = [0.0, 0.25, 0.5, 1.0, 1.0, 0.75, 0.0, 0.5]
    lo, hi = bootstrap_interval(values)
    assert (lo, hi) == bootstrap_interval(values)
    assert lo < sum(values) / len(values) < hi
    assert bootstrap_interval([0.4, 0.4, 0.4]) == pytest.approx((0.4, 0.4))


def test_estimate_methods_and_counts() -> None:
    records = [rec(conds=[(True, ["a"])], success=True), rec(conds=[(False, ["a"])]), rec(conds=[(True, ["a"])])]
    e = estimate(records, "SR")
    assert (e.mean, e.n, e.method) == (pytest.approx(1 / 3), 3, "wilson")
    assert estimate(records, "TP").method == "bootstrap"
    assert estimate(records, "TTC").mean == pytest.approx(2 / 3)


def test_summaries_per_system_and_task_count_errors() -> None:
    records = [
        rec("t1", conds=[(True, ["a"])], success=True, planner="more", llm="openai:gpt-4o"),
        rec("t2", conds=[(False, ["a"])], planner="more", llm="openai:gpt-4o", error="RuntimeError: boom"),
        rec("t1", conds=[(True, ["a"])], planner="oracle"),
    ]
    systems = by_system(records)
    assert list(systems) == ["more (openai:gpt-4o)", "oracle"]
    more = systems["more (openai:gpt-4o)"]
    assert (more.n, more.n_tasks, more.n_errors, more.SR.mean) == (2, 2, 1, 0.5)
    assert set(by_task(records)) == {("more (openai:gpt-4o)", "t1"), ("more (openai:gpt-4o)", "t2"), ("oracle", "t1")}
    assert system_label(records[2]) == "oracle"
    assert summarize([]).n == 0


def test_estimates_do_not_depend_on_record_order() -> None:
    records = [rec(f"t{i}", conds=[(i % 3 == 0, ["a"]), (i % 2 == 0, ["b"])], observed=["a"]) for i in range(9)]
    assert summarize(records) == summarize(records[::-1])


def test_paired_sr_counts_the_episodes_one_system_solves_and_the_other_does_not() -> None:
    a = [rec(f"t{i}", success=i < 12) for i in range(20)]  # solves t0-t11
    b = [rec(f"t{i}", success=2 <= i < 12 or i >= 18, planner="oracle") for i in range(20)]  # t2-t11, t18, t19
    b.append(rec("only_b_ran", success=True))  # no pair: left out
    paired = paired_sr(a, b)
    assert (paired.n, paired.both, paired.only_a, paired.only_b, paired.neither) == (20, 10, 2, 2, 6)
    assert paired.p_value == pytest.approx(1.0)  # two flips each way: no evidence either way
    far = paired_sr([rec(f"t{i}", success=True) for i in range(20)], [rec(f"t{i}", success=i < 8) for i in range(20)])
    assert far.only_a == 12 and far.p_value == pytest.approx(2 * 0.5**12)  # 12 to 0: a real difference
    assert paired_sr(a, [rec("t0", seed=1, success=False)]).n == 0  # another seed is another episode
