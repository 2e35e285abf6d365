"""The MLP artifact model of Windsor et al.: 3 hidden layers of 10 neurons, tanh (IV-E), two recipes (III-D).

    scratch     trained on the samples only (the paper: "failed to generalize beyond the training range")
    pretrained  first trained on the EMG curve of the least squares starting values (eq. 1 with the p0
                of :data:`poseintegrity.artifact_models.base_functions.EMG`), then fine-tuned on the samples
                plus artificial points (theta_end, 0), e.g. (45 deg, 0) for arcs

The paper publishes no training details (docs/references.md, "Camera of the Windsor et al. experiments"); ours, all in params.yaml ``fit.mlp``: inputs scaled to
u = 2 theta / theta_max - 1 in [-1, 1], outputs to y = n / max(n); float64; full batch; L-BFGS with a strong
Wolfe line search, stopped early when the loss changes by less than ``tolerance_change``; the fine-tune
after pretraining is deliberately short (``max_iter_finetune``, e.g. 20 iterations) because a full
re-training on 3-5 distinct theta forgets the pretrained decay beyond the last stop; weights drawn
from a torch generator seeded from the caller's numpy Generator; one CPU thread, deterministic algorithms.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch
from torch import nn
from torch.nn.utils import skip_init

from poseintegrity.artifact_models.base_functions import EMG
from poseintegrity.artifact_models.fitted import FittedModel, too_few_samples, valid_samples
from poseintegrity.artifact_models.params import MLPParams

PARAM_NAMES = ("loss", "evaluations")  # FittedModel.params of an MLP: final scaled MSE, loss evaluations
DISTINCT_THETA = 2  # distinct theta both recipes need (the EMG starting curve of the pretraining needs 2)


def mlp_network(hidden_layers: int, hidden_units: int, generator: torch.Generator) -> nn.Sequential:
    """1 -> (Linear, tanh) x hidden_layers -> Linear -> 1, float64 (IV-E: 3 x 10, tanh).

    Weights and biases ~ U(-1/sqrt(fan_in), 1/sqrt(fan_in)) (torch's default bound), drawn from
    ``generator``; layers are built with skip_init so that the global torch RNG is never touched.
    """
    widths = [1] + [hidden_units] * hidden_layers
    layers: list[nn.Module] = []
    for fan_in, fan_out in zip(widths[:-1], widths[1:], strict=True):
        layers += [skip_init(nn.Linear, fan_in, fan_out, dtype=torch.float64), nn.Tanh()]
    net = nn.Sequential(*layers, skip_init(nn.Linear, hidden_units, 1, dtype=torch.float64))
    with torch.no_grad():
        for layer in net:
            if isinstance(layer, nn.Linear):
                bound = 1.0 / np.sqrt(layer.in_features)
                nn.init.uniform_(layer.weight, -bound, bound, generator=generator)
                nn.init.uniform_(layer.bias, -bound, bound, generator=generator)
    return net


@dataclass(frozen=True, eq=False)
class MLPCurve:
    """A trained network as f: theta (m,) float -> n_inliers (m,) float, with its input/output scaling."""

    net: nn.Sequential
    theta_max: float  # u = 2 theta / theta_max - 1
    n_scale: float  # n = n_scale * y

    def u(self, theta: np.ndarray) -> torch.Tensor:
        """Scaled input, (m, 1) float64 tensor."""
        return torch.as_tensor(2.0 * np.asarray(theta, dtype=float) / self.theta_max - 1.0).reshape(-1, 1)

    def __call__(self, theta: np.ndarray) -> np.ndarray:
        with torch.no_grad():
            return self.n_scale * self.net(self.u(theta)).numpy().ravel()


def train_lbfgs(
    net: nn.Module, u: torch.Tensor, y: torch.Tensor, max_iter: int, tolerance_change: float
) -> tuple[float, int]:
    """Minimise the mean squared error of net(u) vs y, full batch. Returns (final loss, loss evaluations).

    u, y : (m, 1) float64 tensors (scaled theta and counts).
    """
    optimizer = torch.optim.LBFGS(
        net.parameters(), lr=1.0, max_iter=max_iter, tolerance_grad=1e-12, tolerance_change=tolerance_change,
        history_size=20, line_search_fn="strong_wolfe",
    )  # fmt: skip
    evaluations = 0

    def closure() -> torch.Tensor:
        nonlocal evaluations
        evaluations += 1
        optimizer.zero_grad()
        loss = torch.mean((net(u) - y) ** 2)
        loss.backward()
        return loss

    optimizer.step(closure)
    with torch.no_grad():
        return float(torch.mean((net(u) - y) ** 2)), evaluations


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
    The status (fitted.py) is "fallback" with fewer than DISTINCT_THETA distinct theta (the EMG starting curve
    needs 2; the scratch recipe uses the same rule so that both recipes see the same data) or a non-finite loss
    or output, "non_physical" when the trained net predicts a negative count, no decay or an absurd level over
    [first stop, theta_end], else "ok". A finite loss alone says nothing: the short fine-tune always uses its
    whole iteration budget, and a net from scratch that fits 4 stops may predict -5e10 inliers at 45 deg.
    """
    name = "mlp_pretrained" if pretrain else "mlp_scratch"
    theta, n_inliers = valid_samples(theta, n_inliers)
    reason = too_few_samples(theta, DISTINCT_THETA)
    if reason is not None:
        return FittedModel.failed(name, PARAM_NAMES, reason, theta, n_inliers)
    torch.use_deterministic_algorithms(True)
    torch.set_num_threads(1)  # a 10-neuron net is fastest on one thread; the worker processes give the parallelism
    generator = torch.Generator().manual_seed(int(rng.integers(0, 2**63 - 1)))
    curve = MLPCurve(
        mlp_network(mlp.hidden_layers, mlp.hidden_units, generator),
        theta_max=float(theta_end),
        n_scale=max(float(n_inliers.max()), 1.0),
    )
    evaluations, theta_train, n_train, max_iter = 0, theta, n_inliers, mlp.max_iter_scratch
    if pretrain:  # III-D: first fit the EMG curve of the least squares starting values
        theta_grid = np.linspace(0.0, theta_end, mlp.n_pretrain_points)
        emg_start = EMG.f(theta_grid, *EMG.initial_guess(theta, n_inliers)[0])
        _, evaluations = train_lbfgs(
            curve.net, curve.u(theta_grid), torch.as_tensor(emg_start / curve.n_scale).reshape(-1, 1),
            mlp.max_iter_pretrain, mlp.tolerance_change,
        )  # fmt: skip
        # ... then fine-tune on the samples plus artificial points (theta_end, 0)
        theta_train = np.concatenate([theta, np.full(mlp.n_artificial, theta_end)])
        n_train = np.concatenate([n_inliers, np.zeros(mlp.n_artificial)])
        max_iter = mlp.max_iter_finetune
    loss, finetune_evaluations = train_lbfgs(
        curve.net, curve.u(theta_train), torch.as_tensor(n_train / curve.n_scale).reshape(-1, 1),
        max_iter, mlp.tolerance_change,
    )  # fmt: skip
    if not np.isfinite(loss):
        return FittedModel.failed(name, PARAM_NAMES, "non-finite training loss", theta, n_inliers)
    params = {"loss": loss, "evaluations": float(evaluations + finetune_evaluations)}
    return FittedModel.checked(name, params, curve, theta, n_inliers, theta_end)
