"""L-BFGS with a strong Wolfe line search, minimising the MSE of the MLP (mlp_net.py): torch.optim.LBFGS in numba.

A line-by-line port of ``torch.optim.LBFGS.step`` with ``line_search_fn="strong_wolfe"`` (torch 2.x,
torch/optim/lbfgs.py, itself ported from minFunc / torch7 optim lbfgs.lua, lswolfe.lua, polyinterp.lua): the same
two-loop recursion (Nocedal & Wright, Numerical Optimization, 2nd ed., Alg. 7.4) with the same history update
test (y.s > 1e-10), initial Hessian scale y.s / y.y, first step min(1, 1 / |g|_1) * lr, strong Wolfe conditions
c1 = 1e-4, c2 = 0.9 (N&W Alg. 3.5 / 3.6 with cubic interpolation), the line search's own tolerance 1e-9, the
evaluation budget max_eval = max_iter * 5 // 4 and the same stopping tests, in the same order. It differs from
torch only by round-off (sums in another order); tests/artifact_models/test_lbfgs.py runs both side by side.
Calling torch per operation on 251 parameters cost ~1 ms per iteration; this costs microseconds.
"""

from __future__ import annotations

import numba
import numpy as np

from poseintegrity.artifact_models.mlp_net import mse_and_gradient

HISTORY_SIZE = 20  # curvature pairs kept
TOLERANCE_GRAD = 1e-12  # stop when max |gradient| is at most this
LINE_SEARCH_TOLERANCE = 1e-9  # torch's _strong_wolfe default (LBFGS does not pass its tolerance_change on)
C1, C2 = 1e-4, 0.9  # sufficient decrease and curvature constants of the strong Wolfe conditions


@numba.njit(cache=True, error_model="numpy")
def _max(a: float, b: float) -> float:
    """Python's max(a, b), NaN handling included (the first argument unless the second is larger)."""
    return b if b > a else a


@numba.njit(cache=True, error_model="numpy")
def _min(a: float, b: float) -> float:
    """Python's min(a, b): the first argument unless the second is smaller."""
    return b if b < a else a


@numba.njit(cache=True, error_model="numpy")
def _dot(a: np.ndarray, b: np.ndarray) -> float:
    s = 0.0
    for i in range(a.size):
        s += a[i] * b[i]
    return s


@numba.njit(cache=True, error_model="numpy")
def _abs_max(a: np.ndarray) -> float:
    return np.max(np.abs(a))


@numba.njit(cache=True, error_model="numpy")
def cubic_interpolate(
    x1: float, f1: float, g1: float, x2: float, f2: float, g2: float, xmin_bound: float, xmax_bound: float
) -> float:
    """Minimiser of the cubic through (x1, f1, g1), (x2, f2, g2), clipped to [xmin_bound, xmax_bound] (N&W eq. 3.59);
    the bounds' midpoint when the cubic has no minimiser."""
    d1 = g1 + g2 - 3 * (f1 - f2) / (x1 - x2)
    d2_square = d1**2 - g1 * g2
    if d2_square >= 0:
        d2 = np.sqrt(d2_square)
        if x1 <= x2:
            min_pos = x2 - (x2 - x1) * ((g2 + d2 - d1) / (g2 - g1 + 2 * d2))
        else:
            min_pos = x1 - (x1 - x2) * ((g1 + d2 - d1) / (g1 - g2 + 2 * d2))
        return _min(_max(min_pos, xmin_bound), xmax_bound)
    return (xmin_bound + xmax_bound) / 2.0


@numba.njit(cache=True, error_model="numpy")
def _interpolate_between(x1: float, f1: float, g1: float, x2: float, f2: float, g2: float) -> float:
    return cubic_interpolate(x1, f1, g1, x2, f2, g2, _min(x1, x2), _max(x1, x2))


@numba.njit(cache=True, error_model="numpy")
def strong_wolfe(
    x: np.ndarray, t: float, d: np.ndarray, f: float, g: np.ndarray, gtd: float, max_ls: int,
    u: np.ndarray, index: np.ndarray, y: np.ndarray, hidden_layers: int, hidden_units: int,
) -> tuple[float, np.ndarray, float, int]:  # fmt: skip
    """Step t along d from x meeting the strong Wolfe conditions (bracketing, then zoom; N&W Alg. 3.5, 3.6).

    x, d, g : (n,) point, direction, gradient at x;  f, gtd : loss at x and g.d (< 0);  max_ls : evaluation budget
    Returns (loss, gradient : (n,), t, loss evaluations) at the accepted step.
    """
    d_norm = _abs_max(d)
    f_new, g_new = mse_and_gradient(x + t * d, u, index, y, hidden_layers, hidden_units)
    ls_func_evals = 1
    gtd_new = _dot(g_new, d)

    # bracket an interval containing a point satisfying the Wolfe criteria
    t_prev, f_prev, g_prev, gtd_prev = 0.0, f, g, gtd
    bracket = np.zeros(2)
    bracket_f = np.zeros(2)
    bracket_gtd = np.zeros(2)
    bracket_g = np.empty((2, x.size))
    done = False
    ls_iter = 0
    while ls_iter < max_ls:
        armijo_fails = f_new > (f + C1 * t * gtd) or (ls_iter > 1 and f_new >= f_prev)
        if not armijo_fails and abs(gtd_new) <= -C2 * gtd:  # strong Wolfe conditions met: a one-point bracket
            bracket[0], bracket[1] = t, t
            bracket_f[0], bracket_f[1] = f_new, f_new
            bracket_g[0], bracket_g[1] = g_new, g_new
            done = True
            break
        if armijo_fails or gtd_new >= 0:  # a minimiser lies between t_prev and t
            bracket[0], bracket[1] = t_prev, t
            bracket_f[0], bracket_f[1] = f_prev, f_new
            bracket_g[0], bracket_g[1] = g_prev, g_new
            bracket_gtd[0], bracket_gtd[1] = gtd_prev, gtd_new
            break
        # interpolate (extrapolation between 1.01 t and 10 t)
        min_step = t + 0.01 * (t - t_prev)
        max_step = t * 10
        tmp = t
        t = cubic_interpolate(t_prev, f_prev, gtd_prev, t, f_new, gtd_new, min_step, max_step)
        t_prev, f_prev, g_prev, gtd_prev = tmp, f_new, g_new, gtd_new
        f_new, g_new = mse_and_gradient(x + t * d, u, index, y, hidden_layers, hidden_units)
        ls_func_evals += 1
        gtd_new = _dot(g_new, d)
        ls_iter += 1

    if ls_iter == max_ls:  # reached the evaluation budget while bracketing
        bracket[0], bracket[1] = 0.0, t
        bracket_f[0], bracket_f[1] = f, f_new
        bracket_g[0], bracket_g[1] = g, g_new

    # zoom: refine the bracket until a point satisfies the criteria
    insuf_progress = False
    low_pos, high_pos = (0, 1) if bracket_f[0] <= bracket_f[1] else (1, 0)
    while not done and ls_iter < max_ls:
        if abs(bracket[1] - bracket[0]) * d_norm < LINE_SEARCH_TOLERANCE:  # bracket too small
            break
        t = _interpolate_between(bracket[0], bracket_f[0], bracket_gtd[0], bracket[1], bracket_f[1], bracket_gtd[1])
        # insufficient progress: t too close to a bracket end twice in a row, or outside, moves 0.1 x its length in
        high, low = _max(bracket[0], bracket[1]), _min(bracket[0], bracket[1])
        eps = 0.1 * (high - low)
        if _min(high - t, t - low) < eps:
            if insuf_progress or t >= high or t <= low:
                t = high - eps if abs(t - high) < abs(t - low) else low + eps
                insuf_progress = False
            else:
                insuf_progress = True
        else:
            insuf_progress = False
        f_new, g_new = mse_and_gradient(x + t * d, u, index, y, hidden_layers, hidden_units)
        ls_func_evals += 1
        gtd_new = _dot(g_new, d)
        ls_iter += 1
        if f_new > (f + C1 * t * gtd) or f_new >= bracket_f[low_pos]:
            # Armijo condition not satisfied or not lower than the lowest point
            bracket[high_pos], bracket_f[high_pos], bracket_gtd[high_pos] = t, f_new, gtd_new
            bracket_g[high_pos] = g_new
            low_pos, high_pos = (0, 1) if bracket_f[0] <= bracket_f[1] else (1, 0)
        else:
            if abs(gtd_new) <= -C2 * gtd:
                done = True  # Wolfe conditions satisfied
            elif gtd_new * (bracket[high_pos] - bracket[low_pos]) >= 0:
                # old high becomes new low
                bracket[high_pos], bracket_f[high_pos] = bracket[low_pos], bracket_f[low_pos]
                bracket_g[high_pos], bracket_gtd[high_pos] = bracket_g[low_pos], bracket_gtd[low_pos]
            # new point becomes new low
            bracket[low_pos], bracket_f[low_pos], bracket_gtd[low_pos] = t, f_new, gtd_new
            bracket_g[low_pos] = g_new
    return bracket_f[low_pos], bracket_g[low_pos].copy(), bracket[low_pos], ls_func_evals


@numba.njit(cache=True, error_model="numpy")
def minimize_mse(
    x0: np.ndarray, u: np.ndarray, index: np.ndarray, y: np.ndarray, hidden_layers: int, hidden_units: int, max_iter: int,
    tolerance_change: float, lr: float = 1.0,
) -> tuple[np.ndarray, int]:  # fmt: skip
    """L-BFGS from x0 : (n,) on the MLP's mean squared error mlp_net.mse(x, u, index, y): torch.optim.LBFGS(lr, max_iter,
    tolerance_grad=TOLERANCE_GRAD, tolerance_change, history_size=HISTORY_SIZE, line_search_fn="strong_wolfe").step.

    Returns (parameters : (n,), loss evaluations).
    """
    max_eval = max_iter * 5 // 4
    x = x0.copy()
    loss, g = mse_and_gradient(x, u, index, y, hidden_layers, hidden_units)
    current_evals = 1
    if _abs_max(g) <= TOLERANCE_GRAD:
        return x, current_evals
    n = x.size
    old_dirs = np.empty((HISTORY_SIZE, n))  # y_i = g_(i+1) - g_i, oldest first
    old_stps = np.empty((HISTORY_SIZE, n))  # s_i = x_(i+1) - x_i
    ro = np.empty(HISTORY_SIZE)  # 1 / (y_i . s_i)
    al = np.empty(HISTORY_SIZE)
    num_old = 0
    h_diag = 1.0
    d = -g
    t = 0.0
    prev_g = g.copy()
    n_iter = 0
    while n_iter < max_iter:
        n_iter += 1
        if n_iter == 1:
            d = -g
        else:  # Alg. 7.4 of N&W: two-loop recursion for d = -H g
            y_k = g - prev_g
            s_k = d * t
            ys = _dot(y_k, s_k)
            if ys > 1e-10:
                if num_old == HISTORY_SIZE:  # drop the oldest pair
                    old_dirs[:-1] = old_dirs[1:].copy()
                    old_stps[:-1] = old_stps[1:].copy()
                    ro[:-1] = ro[1:].copy()
                    num_old -= 1
                old_dirs[num_old], old_stps[num_old], ro[num_old] = y_k, s_k, 1.0 / ys
                num_old += 1
                h_diag = ys / _dot(y_k, y_k)  # scale of the initial inverse Hessian
            q = -g
            for i in range(num_old - 1, -1, -1):
                al[i] = _dot(old_stps[i], q) * ro[i]
                q += -al[i] * old_dirs[i]
            d = q * h_diag
            for i in range(num_old):
                be_i = _dot(old_dirs[i], d) * ro[i]
                d += (al[i] - be_i) * old_stps[i]
        prev_g[:] = g
        prev_loss = loss
        t = _min(1.0, 1.0 / np.sum(np.abs(g))) * lr if n_iter == 1 else lr
        gtd = _dot(g, d)
        if gtd > -tolerance_change:  # directional derivative below tolerance
            break
        loss, g, t, ls_func_evals = strong_wolfe(
            x, t, d, loss, g, gtd, max_eval - current_evals, u, index, y, hidden_layers, hidden_units
        )
        x = x + t * d
        current_evals += ls_func_evals
        if n_iter == max_iter or current_evals >= max_eval or _abs_max(g) <= TOLERANCE_GRAD:
            break
        if _abs_max(d * t) <= tolerance_change or abs(loss - prev_loss) < tolerance_change:  # lack of progress
            break
    return x, current_evals
