"""The artifact models by name (Windsor et al. III-D, Fig. 2): the least-squares base functions of
:mod:`poseintegrity.artifact_models.base_functions` with their parameters, and the two MLP recipes of
:mod:`poseintegrity.artifact_models.mlp`, with the fewest stops each can be fitted to.

Both the ``fit`` / ``predict`` schemas and the fitters read these, so they live here, below either.
"""

from __future__ import annotations

# least squares model -> its parameters, amplitude first (base_functions.py fits them in this order): eq. 1, the
# decays Fig. 2 compares it with, and ours beside eq. 1 (its Gaussian width fitted)
LEAST_SQUARES_PARAMETERS: dict[str, tuple[str, ...]] = {
    "emg": ("alpha", "K", "mu"),
    "exponential": ("a", "tau"),
    "gaussian": ("a", "m", "s"),
    "logistic": ("a", "t50", "s"),
    "power_law": ("a", "t50", "p"),
    "emg_free_width": ("alpha", "K", "mu", "sigma"),
}
MLP_RECIPES = {"mlp_scratch": False, "mlp_pretrained": True}  # name -> pretrain on the EMG curve?
MLP_DISTINCT_THETA = 2  # distinct theta both recipes need (the EMG starting curve of the pretraining needs 2)
MODEL_NAMES: tuple[str, ...] = (*LEAST_SQUARES_PARAMETERS, *MLP_RECIPES)


def distinct_theta_needed(name: str) -> int:
    """Fewest distinct theta (stops) model ``name`` can be fitted to: its parameter count for a base function
    (eq. 1 has 3, the free-width EMG 4), 2 for the MLP recipes; with fewer its fit is a "fallback" (fitted.py)."""
    return len(LEAST_SQUARES_PARAMETERS.get(name, ())) or MLP_DISTINCT_THETA
