"""The MLP artifact model of Windsor et al.: 3 hidden layers of 10 neurons, tanh (IV-E), two recipes (III-D).

    scratch     trained on the samples only (the paper: "failed to generalize beyond the training range")
    pretrained  first trained on the EMG curve of the least squares starting values (eq. 1 with the p0
                of :data:`poseintegrity.artifact_models.base_functions.EMG`), then fine-tuned on the samples
                plus artificial points (theta_end, 0), e.g. (45 deg, 0) for arcs

The paper publishes no training details (docs/references.md, "Camera of the Windsor et al. experiments"); ours, all in params.yaml ``fit.mlp``: inputs scaled to
u = 2 theta / theta_max - 1 in [-1, 1], outputs to y = n / max(n); float64; full batch; L-BFGS with a strong
Wolfe line search (torch.optim.LBFGS, history 20, ported to numba in lbfgs.py on the network of mlp_net.py),
stopped early when the loss changes by less than ``tolerance_change``; the fine-tune after pretraining is
deliberately short (``max_iter_finetune``, e.g. 20 iterations) because a full re-training on 3-5 distinct theta
forgets the pretrained decay beyond the last stop; weights drawn from a torch generator seeded from the caller's
numpy Generator (torch's nn.Linear initialisation).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from poseintegrity.artifact_models.base_functions import EMG
from poseintegrity.artifact_models.fitted import FittedModel, too_few_samples, valid_samples
from poseintegrity.artifact_models.lbfgs import minimize_mse
from poseintegrity.artifact_models.mlp_net import forward, mse
from poseintegrity.params.model_names import MLP_DISTINCT_THETA
from poseintegrity.params.fit import MLPParams

PARAM_NAMES = ("loss", "evaluations")  # FittedModel.params of an MLP: final scaled MSE, loss evaluations


def initial_weights(hidden_layers: int, hidden_units: int, seed: int) -> np.ndarray:
    """Initial parameters of 1 -> (Linear, tanh) x hidden_layers -> Linear -> 1 (IV-E: 3 x 10, tanh), flat float64
    in the layout of mlp_net.py: (n_params,).

    Weights and biases ~ U(-1/sqrt(fan_in), 1/sqrt(fan_in)) (torch's default bound of nn.Linear), drawn from
    a torch generator seeded with ``seed``, in the order of nn.init.uniform_ on each layer's weight then bias (hence
    the same numbers as those layers would get); the global torch RNG is never touched.
    """
    import torch  # only here: the 2 s import is not paid by every process that reads the fit params

    generator = torch.Generator().manual_seed(seed)
    widths = [1] + [hidden_units] * hidden_layers + [1]
    parts = []
    for fan_in, fan_out in zip(widths[:-1], widths[1:], strict=True):
        bound = 1.0 / np.sqrt(fan_in)
        for shape in ((fan_out, fan_in), (fan_out,)):
            parts.append(torch.empty(shape, dtype=torch.float64).uniform_(-bound, bound, generator=generator))
    return torch.cat([p.reshape(-1) for p in parts]).numpy()


@dataclass(frozen=True, eq=False)
class MLPCurve:
    """A trained network as f: theta (m,) float -> n_inliers (m,) float, with its input/output scaling."""

    weights: np.ndarray  # (n_params,) float64, layout of mlp_net.py
    hidden_layers: int
    hidden_units: int
    theta_max: float  # u = 2 theta / theta_max - 1
    n_scale: float  # n = n_scale * y

    def u(self, theta: np.ndarray) -> np.ndarray:
        """Scaled input, (m,) float64."""
        return 2.0 * np.asarray(theta, dtype=float).ravel() / self.theta_max - 1.0

    def __call__(self, theta: np.ndarray) -> np.ndarray:
        return self.n_scale * forward(self.weights, self.u(theta), self.hidden_layers, self.hidden_units)

    def trained(self, theta: np.ndarray, n_inliers: np.ndarray, max_iter: int, tolerance_change: float
                ) -> tuple[MLPCurve, float, int]:  # fmt: skip
        """This network trained on (theta, n_inliers) : (m,), (m,) by L-BFGS (lbfgs.py: torch.optim.LBFGS with
        history 20 and a strong Wolfe line search), minimising the mean squared error in scaled units, full batch.

        Returns (the trained curve, final scaled MSE, loss evaluations).
        """
        u, index = np.unique(self.u(theta), return_inverse=True)  # a stop's images share their theta
        y = np.asarray(n_inliers, dtype=float).ravel() / self.n_scale
        layers, units = self.hidden_layers, self.hidden_units
        weights, evaluations = minimize_mse(self.weights, u, index, y, layers, units, max_iter, tolerance_change)
        loss = mse(weights, u, index, y, layers, units)
        return replace(self, weights=weights), float(loss), int(evaluations)


def fit_mlp(
    theta: np.ndarray,
    n_inliers: np.ndarray,
    *,
    theta_end: float,
    mlp: MLPParams,
    rng: np.random.Generator,
    pretrain: bool,
) -> FittedModel:
    """Train the MLP artifact model by the paper's recipe (``pretrain=True``) or from scratch. Never raises.

    theta : (m,) float, deg or mm;  n_inliers : (m,) counts (NaN and negative samples are dropped)
    theta_end : end of the range (deg or mm): input scaling, pretraining grid, artificial points (theta_end, 0)
    rng : draws the seed of the initial weights (same rng state -> bit-identical model)
    The status (fitted.py) is "fallback" with fewer than MLP_DISTINCT_THETA distinct theta (the EMG starting curve
    needs 2; the scratch recipe uses the same rule so that both recipes see the same data) or a non-finite loss
    or output, "non_physical" when the trained net predicts a negative count, no decay or an absurd level over
    [first stop, theta_end], else "ok". A finite loss alone says nothing: the short fine-tune always uses its
    whole iteration budget, and a net from scratch that fits 4 stops may predict -5e10 inliers at 45 deg.
    """
    name = "mlp_pretrained" if pretrain else "mlp_scratch"
    theta, n_inliers = valid_samples(theta, n_inliers, theta_end)
    reason = too_few_samples(theta, MLP_DISTINCT_THETA)
    if reason is not None:
        return FittedModel.failed(name, PARAM_NAMES, reason, theta, n_inliers)
    curve = MLPCurve(
        initial_weights(mlp.hidden_layers, mlp.hidden_units, int(rng.integers(0, 2**63 - 1))),
        hidden_layers=mlp.hidden_layers,
        hidden_units=mlp.hidden_units,
        theta_max=float(theta_end),
        n_scale=max(float(n_inliers.max()), 1.0),
    )
    evaluations, theta_train, n_train, max_iter = 0, theta, n_inliers, mlp.max_iter_scratch
    if pretrain:  # III-D: first fit the EMG curve of the least squares starting values
        theta_grid = np.linspace(0.0, theta_end, mlp.n_pretrain_points)
        emg_start = EMG.f(theta_grid, *EMG.initial_guess(theta, n_inliers)[0])
        curve, _, evaluations = curve.trained(theta_grid, emg_start, mlp.max_iter_pretrain, mlp.tolerance_change)
        # ... then fine-tune on the samples plus artificial points (theta_end, 0)
        theta_train = np.concatenate([theta, np.full(mlp.n_artificial, theta_end)])
        n_train = np.concatenate([n_inliers, np.zeros(mlp.n_artificial)])
        max_iter = mlp.max_iter_finetune
    curve, loss, finetune_evaluations = curve.trained(theta_train, n_train, max_iter, mlp.tolerance_change)
    if not np.isfinite(loss):
        return FittedModel.failed(name, PARAM_NAMES, "non-finite training loss", theta, n_inliers)
    params = {"loss": loss, "evaluations": float(evaluations + finetune_evaluations)}
    return FittedModel.checked(name, params, curve, theta, n_inliers, theta_end)
