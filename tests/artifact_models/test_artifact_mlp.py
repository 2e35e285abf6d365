"""The MLP of IV-E: architecture, seeding, scaling invariants, the two recipes of III-D and their status."""

from __future__ import annotations

import numpy as np
import pytest

from poseintegrity.artifact_models import EMG, emg, fit_mlp
from poseintegrity.artifact_models.fitted import FALLBACK, NEGATIVE_COUNT, NON_PHYSICAL, OK
from poseintegrity.artifact_models.mlp import initial_weights
from poseintegrity.artifact_models.mlp_net import n_parameters

THETA4 = np.repeat(2.25 * np.arange(1, 5), 10)  # first 4 stops of an arc, deg
N4 = np.maximum(np.round(emg(THETA4, 3000.0, 9.0, 1.0) + np.random.default_rng(5).normal(0, 4, THETA4.size)), 0)


@pytest.fixture(scope="module")
def fit(tiny_fit, protocol):
    """fit_mlp with the tiny ``fit.mlp`` (or a variation ``mlp``) on an arc, ending at the protocol's range end."""
    def train(theta=THETA4, n=N4, seed=0, pretrain=True, theta_end=protocol.range_end("arc"), mlp=tiny_fit.mlp):
        return fit_mlp(theta, n, theta_end=theta_end, mlp=mlp, rng=np.random.default_rng(seed), pretrain=pretrain)

    return train


def torch_network(generator: torch.Generator) -> nn.Sequential:
    """Reference: the 3 x 10 tanh net of IV-E as torch layers, initialised by nn.init.uniform_ from ``generator``.
    torch is imported where a test uses it, not when the tests are collected (1.2 s of every worker's start)."""
    import torch
    from torch import nn

    net = nn.Sequential(*[m for i, o in ((1, 10), (10, 10), (10, 10)) for m in (nn.Linear(i, o), nn.Tanh())],
                        nn.Linear(10, 1)).double()  # fmt: skip
    with torch.no_grad():
        for layer in net:
            if isinstance(layer, nn.Linear):
                bound = 1.0 / np.sqrt(layer.in_features)
                nn.init.uniform_(layer.weight, -bound, bound, generator=generator)
                nn.init.uniform_(layer.bias, -bound, bound, generator=generator)
    return net


def test_network_is_three_hidden_layers_of_ten_tanh_neurons_initialised_like_torch_linear_layers():
    import torch
    from torch import nn

    net = torch_network(torch.Generator().manual_seed(7))
    weights = initial_weights(3, 10, 7)
    assert weights.shape == (n_parameters(3, 10),) == (sum(p.numel() for p in net.parameters()),) == (251,)
    np.testing.assert_array_equal(weights, nn.utils.parameters_to_vector(net.parameters()).detach().numpy())


@pytest.mark.parametrize("pretrain", [False, True])
def test_same_seed_same_model_other_seed_other_model(fit, pretrain):
    grid = np.linspace(0.0, 45.0, 50)
    a, b, c = (fit(seed=s, pretrain=pretrain).predict(grid) for s in (0, 0, 1))
    np.testing.assert_array_equal(a, b)
    assert np.abs(a - c).max() > 1e-6


def test_global_torch_rng_is_untouched(fit):
    import torch

    state = torch.random.get_rng_state()
    fit()
    assert torch.equal(state, torch.random.get_rng_state())


# Scaling invariants are checked on the scratch recipe: the EMG starting curve of the other is not
# scale-free (its sigma is 1 theta unit, its first decay length comes from log(1 + n)).
def test_output_scaling_makes_the_model_equivariant_to_count_units(fit):
    grid = np.linspace(0.0, 45.0, 50)  # a power of 2 scales exactly in floating point
    scaled = fit(n=4.0 * N4, pretrain=False).predict(grid)
    np.testing.assert_array_equal(scaled, 4.0 * fit(pretrain=False).predict(grid))


def test_input_scaling_makes_the_model_equivariant_to_theta_units(fit):
    grid = np.linspace(0.0, 45.0, 50)
    scaled = fit(theta=8.0 * THETA4, theta_end=8.0 * 45.0, pretrain=False).predict(8.0 * grid)
    np.testing.assert_array_equal(scaled, fit(pretrain=False).predict(grid))


def test_scratch_recipe_fits_its_training_samples(fit, tiny_fit, protocol):
    longer = tiny_fit.mlp.model_copy(update={"max_iter_scratch": 300})  # variation: enough iterations to fit
    model = fit(pretrain=False, mlp=longer)
    emg_fit = EMG.fit(THETA4, N4, theta_end=protocol.range_end("arc"), max_nfev=tiny_fit.max_nfev)
    assert model.has_curve, model.reason
    rmse = np.sqrt(np.mean((model.predict(THETA4) - N4) ** 2))
    assert rmse < 1.2 * np.sqrt(np.mean((emg_fit.predict(THETA4) - N4) ** 2))


def test_pretrained_recipe_follows_the_artificial_points(fit, protocol):
    model = fit(pretrain=True)
    assert model.status == OK and model.name == "mlp_pretrained"
    end = protocol.range_end("arc")
    assert abs(model.predict(np.array([end]))[0]) < 0.05 * N4.max()  # the artificial samples (45 deg, 0)
    assert model.n_samples == THETA4.size  # the artificial samples are not counted as data


def test_pretraining_reproduces_the_emg_starting_curve(fit, tiny_fit):
    """With no fine-tuning budget beyond one iteration, the network is (nearly) the EMG of p0."""
    pretrain_only = tiny_fit.mlp.model_copy(update={"max_iter_pretrain": 300, "max_iter_finetune": 1})  # variation
    model = fit(pretrain=True, mlp=pretrain_only)
    grid = np.linspace(0.0, 45.0, 100)
    start = EMG.f(grid, *EMG.initial_guess(THETA4, N4)[0])
    assert np.sqrt(np.mean((model.predict(grid) - start) ** 2)) < 0.05 * start.max()


@pytest.mark.parametrize(
    ("theta", "n", "reason"),
    [
        (np.full(10, 4.5), np.arange(10.0), "1 distinct theta"),
        (THETA4, np.full(THETA4.size, np.nan), "no valid samples"),
        (THETA4, -N4, "no valid samples"),
    ],
)
def test_degenerate_samples_give_a_flagged_model_with_a_fallback(fit, theta, n, reason):
    for pretrain in (False, True):
        model = fit(theta=theta, n=n, pretrain=pretrain)
        assert model.status == FALLBACK and reason in model.reason
        assert np.all(np.isfinite(model.predict(np.linspace(0.0, 45.0, 10))))


@pytest.mark.parametrize("pretrain", [False, True])
def test_an_mlp_that_predicts_a_negative_count_is_flagged(fit, protocol, pretrain):
    """Counts falling by 90 per stop, to 30 at the 4th: a net that follows them goes on below zero before 45 deg
    (a finite training loss does not make it a usable artifact model)."""
    theta = np.repeat(2.25 * np.arange(4), 10)
    n = 300.0 - 40.0 * theta
    model = fit(theta=theta, n=n, pretrain=pretrain)
    grid = np.linspace(0.0, protocol.range_end("arc"), 181)
    assert model.predict(grid).min() < NEGATIVE_COUNT  # the known answer: it does go below zero
    assert model.status == NON_PHYSICAL and "negative count" in model.reason
    assert np.isfinite(model.params["loss"])

