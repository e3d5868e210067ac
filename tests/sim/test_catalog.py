"""Catalog: what bddl's generated data says about scenes and categories."""

import pytest

from more_agent.errors import UserError
from more_agent.sim import catalog


def test_51_scenes_with_bddl_rooms():
    names = catalog.scene_names()
    assert len(names) == 51 and "Rs_int" in names and names == sorted(names)
    assert list(catalog.scene_rooms("Rs_int")) == ["living_room_0", "bedroom_0", "bathroom_0", "kitchen_0", "entryway_0"]


def test_unknown_scene_names_closest():
    with pytest.raises(UserError, match="Rs_int"):
        catalog.scene_rooms("Rs_inr")


def test_categories_in_scene_includes_structural_and_furniture():
    cats = catalog.categories_in_scene("Rs_int")
    assert {"fridge", "floors", "bottom_cabinet"} <= set(cats)


def test_category_size_is_metric_and_z_up():
    sx, sy, sz = catalog.category_size("fridge")
    assert 1.4 < sz < 2.2 and 0.4 < min(sx, sy) < 1.0
    assert max(catalog.category_size("apple")) < 0.15  # task objects too
    assert catalog.category_size("car")[0] > 4.0
    with pytest.raises(UserError):
        catalog.category_size("no_such_category")


def test_synsets_both_ways_and_abilities():
    assert catalog.category_synsets("fridge") == ["electric_refrigerator.n.01"]
    assert catalog.category_synsets("no_such_category") == []
    assert "apple" in catalog.synset_categories("apple.n.01")
    assert "apple" in catalog.synset_categories("fruit.n.01")  # descendants count
    assert catalog.synset_categories("not_a_synset.n.01") == []
    assert catalog.is_openable("fridge") and catalog.is_openable("bottom_cabinet") and catalog.is_openable("car")
    assert not catalog.is_openable("breakfast_table")


def test_furniture_roles():
    assert catalog.furniture_role("floors") == "skip"
    assert catalog.furniture_role("openable_window") == "skip"
    assert catalog.furniture_role("apple") == "skip"  # small things are the tasks' business
    assert catalog.furniture_role("carpet") == "carpet"
    assert catalog.furniture_role("top_cabinet") == "wall"
    assert catalog.furniture_role("microwave") == "surface"
    assert catalog.furniture_role("fridge") == "floor"
    assert catalog.furniture_role("breakfast_table") == "free"
