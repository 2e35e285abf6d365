"""The MLP of Windsor et al. IV-E as a flat parameter vector: forward pass and analytic gradient of its MSE (numba).

A 10-neuron net on a few dozen points costs microseconds per evaluation when written as loops; through torch's
autograd the per-operation overhead made each evaluation ~100x dearer (the speed issue of stage 03).

Network: 1 -> (Linear, tanh) x L -> Linear -> 1, L hidden layers of H units (IV-E: L = 3, H = 10), float64.
Parameter layout (torch's ``nn.Sequential(...).parameters()`` order, weights row-major (out, in)):

    W_1 (H, 1), b_1 (H,), W_2 (H, H), b_2 (H,), ..., W_L (H, H), b_L (H,), W_out (1, H), b_out (1,)

Loops are sequential sums without fastmath: the same inputs give bit-identical results on every run and worker.
"""

from __future__ import annotations

import numba
import numpy as np


def n_parameters(hidden_layers: int, hidden_units: int) -> int:
    """Length of the flat parameter vector (251 for 3 x 10)."""
    return 2 * hidden_units + (hidden_layers - 1) * (hidden_units + 1) * hidden_units + hidden_units + 1


@numba.njit(cache=True, error_model="numpy")
def _hidden(x: np.ndarray, u: np.ndarray, hidden_layers: int, hidden_units: int) -> np.ndarray:
    """Activations h_l = tanh(W_l h_(l-1) + b_l), h_0 = u : (L, m, H). x : (n_params,); u : (m,)."""
    m, n_h = u.size, hidden_units
    h = np.empty((hidden_layers, m, n_h))
    for i in range(n_h):  # W_1 (H, 1) at 0, b_1 at H
        for k in range(m):
            h[0, k, i] = np.tanh(u[k] * x[i] + x[n_h + i])
    offset = 2 * n_h
    for layer in range(1, hidden_layers):  # W_l (H, H) at offset, b_l after it
        bias = offset + n_h * n_h
        for k in range(m):
            for i in range(n_h):
                s = 0.0
                for j in range(n_h):
                    s += h[layer - 1, k, j] * x[offset + i * n_h + j]
                h[layer, k, i] = np.tanh(s + x[bias + i])
        offset = bias + n_h
    return h


@numba.njit(cache=True, error_model="numpy")
def _output(x: np.ndarray, h_last: np.ndarray) -> np.ndarray:
    """Network output W_out h_L + b_out : (m,), from the last hidden activations h_L : (m, H)."""
    m, n_h = h_last.shape
    offset = x.size - n_h - 1  # W_out (1, H), then b_out
    out = np.empty(m)
    for k in range(m):
        s = 0.0
        for j in range(n_h):
            s += h_last[k, j] * x[offset + j]
        out[k] = s + x[x.size - 1]
    return out


@numba.njit(cache=True, error_model="numpy")
def forward(x: np.ndarray, u: np.ndarray, hidden_layers: int, hidden_units: int) -> np.ndarray:
    """Network output at scaled inputs u : (m,) -> (m,), parameters x : (n_params,)."""
    return _output(x, _hidden(x, u, hidden_layers, hidden_units)[hidden_layers - 1])


@numba.njit(cache=True, error_model="numpy")
def mse(x: np.ndarray, u: np.ndarray, index: np.ndarray, y: np.ndarray, hidden_layers: int, hidden_units: int) -> float:
    """Mean squared error mean((net(u[index]) - y)^2) of parameters x : (n_params,).

    u : (s,) distinct scaled inputs;  index : (m,) int, the input of each sample;  y : (m,) scaled counts.
    The network runs once per distinct input: the images of a stop share their theta.
    """
    r = forward(x, u, hidden_layers, hidden_units)[index] - y
    return np.sum(r * r) / r.size


@numba.njit(cache=True, error_model="numpy")
def mse_and_gradient(
    x: np.ndarray, u: np.ndarray, index: np.ndarray, y: np.ndarray, hidden_layers: int, hidden_units: int
) -> tuple[float, np.ndarray]:
    """(mean((net(u[index]) - y)^2), its gradient d/dx : (n_params,)) by backpropagation; arguments as :func:`mse`.

    With r = net(u[index]) - y: d loss / d out_k = 2 r_k / m, summed over the samples of each distinct input;
    through a tanh layer delta_(l-1) = (W_l^T delta_l) (1 - h^2).
    """
    m, n_h = u.size, hidden_units  # m: distinct inputs from here on
    h = _hidden(x, u, hidden_layers, hidden_units)
    r = _output(x, h[hidden_layers - 1])[index] - y
    loss = np.sum(r * r) / r.size
    grad = np.empty(x.size)
    d_out = np.zeros(m)  # d loss / d out at each distinct input
    d_sample = (1.0 / r.size) * (2.0 * r)
    for k in range(r.size):
        d_out[index[k]] += d_sample[k]
    offset = x.size - n_h - 1  # W_out, b_out
    s_b = 0.0
    for k in range(m):
        s_b += d_out[k]
    grad[x.size - 1] = s_b
    delta = np.empty((m, n_h))  # d loss / d (pre-activation) of the current hidden layer
    for j in range(n_h):
        s = 0.0
        for k in range(m):
            s += d_out[k] * h[hidden_layers - 1, k, j]
        grad[offset + j] = s
        for k in range(m):
            hk = h[hidden_layers - 1, k, j]
            delta[k, j] = d_out[k] * x[offset + j] * (1.0 - hk * hk)
    for layer in range(hidden_layers - 1, 0, -1):  # W_(layer+1) (H, H) and b: 0-based hidden layer `layer`
        offset -= n_h * n_h + n_h
        bias = offset + n_h * n_h
        for i in range(n_h):
            s_b = 0.0
            for k in range(m):
                s_b += delta[k, i]
            grad[bias + i] = s_b
            for j in range(n_h):
                s = 0.0
                for k in range(m):
                    s += delta[k, i] * h[layer - 1, k, j]
                grad[offset + i * n_h + j] = s
        below = np.empty((m, n_h))
        for k in range(m):
            for j in range(n_h):
                s = 0.0
                for i in range(n_h):
                    s += delta[k, i] * x[offset + i * n_h + j]
                hk = h[layer - 1, k, j]
                below[k, j] = s * (1.0 - hk * hk)
        delta = below
    for i in range(n_h):  # W_1 (H, 1) at 0, b_1 at H
        s, s_b = 0.0, 0.0
        for k in range(m):
            s += delta[k, i] * u[k]
            s_b += delta[k, i]
        grad[i] = s
        grad[n_h + i] = s_b
    return loss, grad
