"""The rows of ``pnp.json`` (stage 05, Windsor et al. V-A, Fig. 6): per PnP variant the mean n_i at the first stop,
the share of frames without a pose, the RANSAC iteration cap and the mean theta_a on the arcs (deg)."""

from __future__ import annotations

from poseintegrity.report.headlines.sections import Headline

PNP_ROWS: list[Headline] = [
    Headline("pnp", "methods.usac_magsac.mean_n_inliers_first_stop", "USAC (P3P + MAGSAC): mean n_i, first stop"),
    Headline("pnp", "methods.epnp.mean_n_inliers_first_stop", "EPnP: mean n_i, first stop"),
    Headline("pnp", "methods.p3p.mean_n_inliers_first_stop", "P3P: mean n_i, first stop"),
    Headline("pnp", "methods.ap3p.mean_n_inliers_first_stop", "AP3P: mean n_i, first stop"),
    Headline("pnp", "methods.sqpnp.mean_n_inliers_first_stop", "SQPnP: mean n_i, first stop"),
    *[Headline("pnp", f"methods.{method}.failure_rate", f"{name}: share of frames without a pose (every status)",
               fmt="{:.1%}") for method, name in (("usac_magsac", "USAC"), ("epnp", "EPnP"), ("p3p", "P3P"),
                                                  ("ap3p", "AP3P"), ("sqpnp", "SQPnP"), ("iterative", "iterative"))],
    *[Headline("pnp", f"iteration_caps.{method}", f"{name}: classic RANSAC iteration cap (w = 0.4, p = 0.999)",
               "OpenCV's default: 100") for method, name in (("epnp", "EPnP"), ("p3p", "P3P"))],
    Headline("pnp", "methods.usac_magsac.mean_theta_a_arc_2mm_3deg", "USAC: mean theta_a, arcs, 2 mm/3 deg (deg)"),
    Headline("pnp", "methods.epnp.mean_theta_a_arc_2mm_3deg", "EPnP: mean theta_a, arcs, 2 mm/3 deg (deg)"),
    Headline("pnp", "methods.sqpnp.mean_theta_a_arc_2mm_3deg", "SQPnP: mean theta_a, arcs, 2 mm/3 deg (deg)"),
]
