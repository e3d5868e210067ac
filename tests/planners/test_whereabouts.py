"""Where items are kept, read from bddl's activity corpus (``planners.whereabouts``)."""

from __future__ import annotations

import pytest

from more_agent.planners.whereabouts import (
    container_prior,
    container_share,
    corpus,
    evidence,
    never_inside,
    room_prior,
)


def test_an_item_s_prior_points_to_the_rooms_the_corpus_keeps_it_in() -> None:
    """Plates are set out in kitchens and dining rooms across the activities, not in garages or lawns."""
    prior = room_prior("plate.n.04")
    assert max(prior, key=lambda kind: prior[kind]) == "kitchen"
    assert prior["kitchen"] + prior.get("dining_room", 0.0) > 0.8
    assert prior.get("garden", 0.0) < 0.05
    assert abs(sum(prior.values()) - 1.0) < 1e-9


def test_leave_one_out_removes_the_activity_s_own_evidence() -> None:
    """The allen wrench is placed in one activity only (outfit_a_basic_toolbox, in its utility room): left
    out, the wrench borrows its siblings' evidence (hand tools kept in garages), never its own task's init."""
    assert {e.activity for e in evidence("allen_wrench.n.01")} == {"outfit_a_basic_toolbox"}
    assert room_prior("allen_wrench.n.01") == {"utility_room": 1.0}
    left_out = evidence("allen_wrench.n.01", leave_out="outfit_a_basic_toolbox")
    assert left_out and all(e.activity != "outfit_a_basic_toolbox" for e in left_out)
    assert "utility_room" not in room_prior("allen_wrench.n.01", leave_out="outfit_a_basic_toolbox")


def test_a_synset_the_corpus_never_places_has_no_prior() -> None:
    """No evidence, no opinion: the search ranks as it would without a prior."""
    assert room_prior("no_such_thing.n.01") == {}
    assert container_prior("no_such_thing.n.01") == {} and not never_inside("no_such_thing.n.01")


def test_the_container_prior_names_containers_by_what_they_descend_from() -> None:
    """Plates are sometimes kept in cabinets: a bottom cabinet counts as one; a car never holds them."""
    prior = container_prior("plate.n.04")
    assert not never_inside("plate.n.04")
    assert container_share("bottom_cabinet", prior) > 0
    assert container_share("car", prior) == 0


def test_an_item_many_activities_place_and_none_inside_is_kept_in_no_container() -> None:
    """Cars stand in gardens and garages in several activities, never inside anything."""
    assert never_inside("car.n.01")
    assert set(room_prior("car.n.01")) <= {"garden", "garage"}


def test_reading_the_corpus_prints_nothing(capsys: pytest.CaptureFixture[str]) -> None:
    """bddl prints what its parser skips (a stray backslash in wash_a_baseball_cap) to stdout: reading the
    corpus once put that line into the output of every episode, ``--json`` included."""
    corpus.cache_clear()
    assert corpus()
    assert capsys.readouterr().out == ""
