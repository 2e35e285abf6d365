"""The numba MLP (mlp_net.py) and L-BFGS (lbfgs.py) against torch: autograd gradients and torch.optim.LBFGS."""

from __future__ import annotations

import numpy as np
import pytest

from artifact_models.test_artifact_mlp import torch_network
from poseintegrity.artifact_models.lbfgs import HISTORY_SIZE, TOLERANCE_GRAD, cubic_interpolate, minimize_mse
from poseintegrity.artifact_models.mlp_net import forward, mse_and_gradient

U = np.repeat(np.linspace(-1.0, 0.1, 8), 5)  # scaled theta of 8 stops x 5 images (torch sees every sample)
Y = np.exp(-3.0 * (U + 1.0)) + 0.02 * np.random.default_rng(3).normal(size=U.size)  # scaled counts
U_STOPS, INDEX = np.unique(U, return_inverse=True)  # the numba net runs once per stop


def torch_reference(seed: int, max_iter: int, y: np.ndarray = Y) -> tuple[np.ndarray, np.ndarray, int]:
    """(initial, trained parameters, closure calls) of torch.optim.LBFGS on the MSE of the torch net at (U, y)."""
    import torch  # here, not at collection (test_artifact_mlp.torch_network)
    from torch import nn

    net = torch_network(torch.Generator().manual_seed(seed))
    x0 = nn.utils.parameters_to_vector(net.parameters()).detach().numpy().copy()
    u, y = torch.as_tensor(U).reshape(-1, 1), torch.as_tensor(y).reshape(-1, 1)
    optimizer = torch.optim.LBFGS(net.parameters(), lr=1.0, max_iter=max_iter, tolerance_grad=TOLERANCE_GRAD,
                                  tolerance_change=1e-12, history_size=HISTORY_SIZE,
                                  line_search_fn="strong_wolfe")  # fmt: skip
    calls = 0

    def closure() -> torch.Tensor:
        nonlocal calls
        calls += 1
        optimizer.zero_grad()
        loss = torch.mean((net(u) - y) ** 2)
        loss.backward()
        return loss

    optimizer.step(closure)
    return x0, nn.utils.parameters_to_vector(net.parameters()).detach().numpy(), calls


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_forward_loss_and_gradient_equal_torch_autograd(seed):
    import torch
    from torch import nn

    net = torch_network(torch.Generator().manual_seed(seed))
    x = nn.utils.parameters_to_vector(net.parameters()).detach().numpy().copy()
    u, y = torch.as_tensor(U).reshape(-1, 1), torch.as_tensor(Y).reshape(-1, 1)
    loss = torch.mean((net(u) - y) ** 2)
    loss.backward()
    reference = torch.cat([p.grad.reshape(-1) for p in net.parameters()]).numpy()
    value, gradient = mse_and_gradient(x, U_STOPS, INDEX, Y, 3, 10)
    np.testing.assert_allclose(forward(x, U, 3, 10), net(u).detach().numpy().ravel(), rtol=0, atol=1e-14)
    assert value == pytest.approx(loss.item(), rel=1e-13)
    np.testing.assert_allclose(gradient, reference, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize(("seed", "max_iter"), [(0, 5), (1, 20), (2, 20)])
def test_lbfgs_takes_the_steps_of_torch_lbfgs(seed, max_iter):
    """Same iterates and closure calls as torch.optim.LBFGS (history 20, strong Wolfe) up to round-off."""
    x0, reference, calls = torch_reference(seed, max_iter)
    x, evaluations = minimize_mse(x0, U_STOPS, INDEX, Y, 3, 10, max_iter, 1e-12)
    assert evaluations == calls
    assert np.abs(reference - x0).max() > 1e-2  # it did move
    np.testing.assert_allclose(x, reference, rtol=0, atol=1e-9)


def test_lbfgs_converges_like_torch_lbfgs():
    """Run to its stopping tests (loss change < 1e-12), both stop at the same evaluation with the same fit."""
    y = np.exp(-3.0 * (U + 1.0))  # noise-free: a smooth minimum reached well within the budget
    x0, reference, calls = torch_reference(0, 300, y)
    x, evaluations = minimize_mse(x0, U_STOPS, INDEX, y, 3, 10, 300, 1e-12)
    assert evaluations == calls < 300 * 5 // 4  # stopped by a tolerance, not the budget
    np.testing.assert_allclose(forward(x, U, 3, 10), forward(reference, U, 3, 10), rtol=0, atol=1e-6)


def test_cubic_interpolation_finds_the_minimum_of_a_cubic():
    """f = x^3 - 3x has its minimum at x = 1; from (0, 0, -3) and (2, 2, 9) the interpolating cubic is f itself."""
    assert cubic_interpolate(0.0, 0.0, -3.0, 2.0, 2.0, 9.0, 0.0, 2.0) == pytest.approx(1.0, abs=1e-15)
    assert cubic_interpolate(2.0, 2.0, 9.0, 0.0, 0.0, -3.0, 0.0, 2.0) == pytest.approx(1.0, abs=1e-15)
    assert cubic_interpolate(0.0, 0.0, -3.0, 2.0, 2.0, 9.0, 1.5, 2.0) == 1.5  # clipped to the bounds
    assert cubic_interpolate(0.0, 0.0, 1.0, 1.0, 2.0 / 3.0, 1.0, 0.0, 1.0) == 0.5  # increasing: the midpoint
