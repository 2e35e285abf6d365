"""Stage 02's envelope figures on synthetic tables: arcs (deg) and lines (mm) never share an axis, every cause is
counted, the 1 and 2 sigma lines are named and the share within 2 sigma is that of the frames drawn."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest

from figure_checks import assert_readable, legend_texts
from poseintegrity.localization.envelope_figures import envelope_causes_figure, error_calibration_figure
from poseintegrity.localization.error_calibration import calibration_frames, calibration_metrics

TOLERANCES = ("2mm_3deg", "4mm_10deg")
BEYOND_MM = 1000.0  # the measured error after theta_a: a stop that must not be drawn


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def causes_table() -> pd.DataFrame:
    """Envelope causes of two worlds: per tolerance 5 arcs (theta_a 10-40 deg) and 3 lines (60-140 mm)."""
    rng = np.random.default_rng(3)
    rows = []
    for world in ("main", "validation"):
        for tolerance in TOLERANCES:
            for i, cause in enumerate(("estimate", "estimate", "no_pose", "ground_truth", "censored")):
                theta_a = float(rng.uniform(10, 40))
                rows.append(dict(world=world, dataset=f"arc_{i}", trajectory="arc", tolerance=tolerance,
                                 theta_a=theta_a, theta_a_exact=theta_a + rng.normal(0, 1), cause=cause,
                                 limit={"no_pose": "no_pose", "censored": "censored"}.get(cause, "translation")))
            for i, cause in enumerate(("estimate", "censored", "censored")):
                x_a = float(rng.uniform(60, 140))
                rows.append(dict(world=world, dataset=f"line_{i}", trajectory="line", tolerance=tolerance,
                                 theta_a=x_a, theta_a_exact=np.nan if i == 2 else x_a + 2.0, cause=cause,
                                 limit="censored" if cause == "censored" else "rotation"))
    return pd.DataFrame(rows)


def test_envelope_causes_put_arcs_and_lines_in_panels_of_their_own_with_units_and_counts():
    causes = causes_table()
    fig = envelope_causes_figure(causes)
    assert_readable(fig)
    assert len(fig.axes) == 2 * len(TOLERANCES) * 2  # a row per world, a column per tolerance and trajectory type
    for ax in fig.axes:
        unit = "deg" if "(deg)" in ax.get_xlabel() else "mm"
        assert f"({unit})" in ax.get_ylabel() and ("arcs" if unit == "deg" else "lines") in ax.get_title()
        drawn = np.concatenate([c.get_offsets()[:, 0] for c in ax.collections if len(c.get_offsets())])
        world, tolerance = ax.get_title().split(", ")[:2]
        panel = causes[(causes.world == world) & (causes.tolerance == tolerance)
                       & (causes.trajectory == ("arc" if unit == "deg" else "line"))]
        assert sorted(drawn) == pytest.approx(sorted(panel.theta_a))  # this panel's envelopes, no other
        counts = panel.cause.value_counts()
        assert sorted(legend_texts(ax)) == sorted(f"{cause}: {n}" for cause, n in counts.items())


def test_envelope_causes_without_envelopes_says_so():
    fig = envelope_causes_figure(causes_table().iloc[:0])
    assert fig.axes[0].get_title() == "no envelope to explain"


def calibration_rows() -> tuple[pd.DataFrame, pd.DataFrame]:
    """(artifacts, envelopes): per world an arc (stops every 4 deg to 40) and a line (every 20 mm to 140), 3 frames per
    stop, the measured error about the predicted one before theta_a (22 deg, 90 mm) and :data:`BEYOND_MM` after."""
    rng = np.random.default_rng(5)
    rows, envelopes = [], []
    for world in ("main", "validation"):
        for dataset, trajectory, positions, theta_a in ((f"{world}_arc", "arc", np.arange(0, 41, 4.0), 22.0),
                                                        (f"{world}_line", "line", np.arange(0, 141, 20.0), 90.0)):
            envelopes += [dict(dataset=dataset, tolerance=t, method="usac", theta_a=theta_a) for t in TOLERANCES]
            for stop, position in enumerate(positions):
                for image in range(3):
                    sigma = 0.1 + 0.05 * stop
                    E_t = BEYOND_MM if position > theta_a else abs(rng.normal(0, sigma))
                    rows.append(dict(world=world, dataset=dataset, trajectory=trajectory, stop=stop, image=image,
                                     method="usac", covariance_status="ok",
                                     theta_deg=position if trajectory == "arc" else 0.0,
                                     x_mm=position if trajectory == "line" else 0.0, E_t_mm=E_t,
                                     sigma_t_pred_mm=sigma, sigma_t_unconditioned_mm=2 * sigma,
                                     E_r_deg=E_t / 10, sigma_r_pred_deg=sigma / 10, E_t_exact_mm=E_t,
                                     n_inliers=100 - 5 * stop, model_pixel_noise_px=0.3))
    return pd.DataFrame(rows), pd.DataFrame(envelopes)


def test_error_calibration_names_its_sigma_lines_and_states_the_share_of_the_frames_drawn():
    artifacts, envelopes = calibration_rows()
    frames = calibration_frames(artifacts, envelopes, "usac")
    calibration = calibration_metrics(frames)
    fig = error_calibration_figure(frames, calibration)
    assert_readable(fig)
    assert len(fig.axes) == len(TOLERANCES) * 2  # a row per tolerance: inlier-conditioned, unconditioned
    for ax in fig.axes:
        assert any("1 sigma" in text for text in legend_texts(ax))
        assert any("2 sigma" in text for text in legend_texts(ax))
        measured = np.concatenate([c.get_offsets()[:, 1] for c in ax.collections])
        assert measured.max() < BEYOND_MM  # no stop after the first failing one
        tolerance = ax.get_title().split(",")[0]
        stated = "\n".join(text.get_text() for text in ax.texts)
        for world in ("main", "validation"):
            entry = calibration[world][tolerance]
            share = (entry if "inlier-conditioned" in ax.get_title() else entry["unconditioned"])["within_2sigma_t"]
            assert f"{world}: {share:.0%} of {entry['n_frames']} frames" in stated


def test_error_calibration_without_frames_says_so():
    artifacts, envelopes = calibration_rows()
    fig = error_calibration_figure(calibration_frames(artifacts.iloc[:0], envelopes, "usac"), {})
    assert "no frame" in fig.axes[0].get_title()
