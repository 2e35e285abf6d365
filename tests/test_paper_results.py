"""The papers' figures (paper_results.py) against the tables Windsor et al. printed."""

import re

import pytest

from poseintegrity import paper_results as paper

# Rows of Windsor et al.'s tables as printed (system, 2mm/3deg, 4mm/10deg, mean, relative improvement)
TABLE_I = """Static Baseline	7.0	7.0	7.0	84.1%
MLP	11.5	12.5	12.0	7.4%
Predictor (Ours)	12.3	13.5	12.9	-"""
TABLE_II = """Baseline	7.0	7.0	7.0	102.1%
Predictor (Ours)	13.9	14.4	14.2	-"""
TABLE_III = """Long Range Predictor	23	28
Next-Step Predictor	12	15"""


def numbers(row: str) -> list[float]:
    return [float(v) for v in re.findall(r"\d+\.?\d*", row)]


def test_paper_table_holds_the_printed_numbers_per_tolerance():
    static, mlp, ours = (numbers(row) for row in TABLE_I.splitlines())
    for name, row in (("static", static), ("mlp", mlp), ("long_range", ours)):
        assert [paper.WINDSOR_SPL_ZERO_INCURSION[name][t] for t in paper.TOLERANCES] == row[:2]
        assert paper.mean_spl(name) == pytest.approx(row[2], abs=0.05)  # the table's "Mean" column, rounded
    assert paper.WINDSOR_IMPROVEMENTS["long_range_vs_static"] == pytest.approx(static[3] / 100)
    assert paper.WINDSOR_IMPROVEMENTS["long_range_vs_mlp"] == pytest.approx(mlp[3] / 100)
    baseline, next_step = (numbers(row) for row in TABLE_II.splitlines())
    assert [paper.WINDSOR_SPL_ZERO_INCURSION["next_step"][t] for t in paper.TOLERANCES] == next_step[:2]
    assert paper.WINDSOR_IMPROVEMENTS["next_step_vs_static"] == pytest.approx(baseline[3] / 100)
    long_range, step = (numbers(row) for row in TABLE_III.splitlines())
    assert [paper.WINDSOR_THRESHOLDS["long_range"][t] for t in paper.TOLERANCES] == long_range
    assert [paper.WINDSOR_THRESHOLDS["next_step"][t] for t in paper.TOLERANCES] == step
