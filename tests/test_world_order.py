"""Which world heads the metrics (world_order.py): main, then validation, then the others by name."""

from poseintegrity.world_order import world_order


def test_main_heads_then_validation_then_the_others_by_name():
    assert world_order(["validation", "zeta", "main", "alpha", "main"]) == ["main", "validation", "alpha", "zeta"]
    assert world_order(["recorded"]) == ["recorded"] and world_order(["lab_b", "lab_a", "lab_b"]) == ["lab_a", "lab_b"]
