"""The artifact models by name (Windsor et al. III-D, Fig. 2): the least-squares base functions of
:mod:`base_functions` and the two MLP recipes of :mod:`mlp`, with the fewest stops each can be fitted to.

Both the ``fit`` / ``predict`` schemas and the fitters read these, so they live apart from either.
"""

from __future__ import annotations

from poseintegrity.artifact_models.base_functions import LEAST_SQUARES

MLP_RECIPES = {"mlp_scratch": False, "mlp_pretrained": True}  # name -> pretrain on the EMG curve?
MLP_DISTINCT_THETA = 2  # distinct theta both recipes need (the EMG starting curve of the pretraining needs 2)
MODEL_NAMES: tuple[str, ...] = (*LEAST_SQUARES, *MLP_RECIPES)


def distinct_theta_needed(name: str) -> int:
    """Fewest distinct theta (stops) model ``name`` can be fitted to: its parameter count for a base function
    (eq. 1 has 3, the free-width EMG 4), 2 for the MLP recipes; with fewer its fit is a "fallback" (fitted.py)."""
    return len(LEAST_SQUARES[name].param_names) if name in LEAST_SQUARES else MLP_DISTINCT_THETA
