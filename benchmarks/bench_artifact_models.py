"""Speed of stage 03 (artifact models), as ratios against references measured in the same run.

    1. one EMG fit (eq. 1) on 4 stops x 10 images          target: median <= 5 ms
       reference: a plain curve_fit of alpha * scipy.stats.exponnorm.pdf(theta - mu, K) (lm, no bounds)
    2. the MLP recipes (pretrain + fine-tune; scratch)      target: pretrained <= 2 s
       reference: the same recipe trained by torch.optim.LBFGS on the torch net (the implementation before the
       numba port of lbfgs.py), from the same initial weights
    3. the whole Fig. 2 experiment at paper scale           target: <= 5 min on 2 cores
       (21 arcs + 4 lines of synthetic eq. 1 data, k = 3 .. all, all models, on the workers of ``parallel``),
       with the fit statuses it reports (fits.json)

Usage: PYTHONPATH=src .venv/bin/python benchmarks/bench_artifact_models.py [--params params.yaml] [--skip-stage]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import torch
from scipy.optimize import curve_fit
from scipy.stats import exponnorm

from poseintegrity.artifact_models import EMG, emg, fig2_rmse, fit_mlp, fits_metrics, status_counts
from poseintegrity.artifact_models.mlp import initial_weights
from poseintegrity.artifact_models.synthetic import synthetic_artifacts
from poseintegrity.config import load_section
from poseintegrity.params.fit import MLPParams
from poseintegrity.workers import Workers, worker_count
from paired_timing import paired_medians  # benchmarks/paired_timing.py


def report(label: str, seconds: float, reference: float, target: float | None = None) -> None:
    verdict = "" if target is None else ("  [meets target]" if seconds <= target else "  [MISSES target]")
    print(f"  {label:<42s} {seconds * 1e3:10.2f} ms   {seconds / reference:8.2f} x reference{verdict}")


def torch_recipe(theta: np.ndarray, n: np.ndarray, theta_end: float, mlp: MLPParams, seed: int, pretrain: bool
                 ) -> torch.nn.Sequential:  # fmt: skip
    """Reference: fit_mlp's training done by torch.optim.LBFGS on an nn.Sequential (the code before lbfgs.py)."""
    widths = [1] + [mlp.hidden_units] * mlp.hidden_layers
    layers = [m for i, o in zip(widths[:-1], widths[1:], strict=True) for m in (torch.nn.Linear(i, o), torch.nn.Tanh())]
    net = torch.nn.Sequential(*layers, torch.nn.Linear(mlp.hidden_units, 1)).double()
    x0 = initial_weights(mlp.hidden_layers, mlp.hidden_units, seed)
    torch.nn.utils.vector_to_parameters(torch.as_tensor(x0), net.parameters())
    n_scale = max(float(n.max()), 1.0)

    def train(t: np.ndarray, counts: np.ndarray, max_iter: int) -> None:
        u = torch.as_tensor(2.0 * t / theta_end - 1.0).reshape(-1, 1)
        y = torch.as_tensor(counts / n_scale).reshape(-1, 1)
        optimizer = torch.optim.LBFGS(net.parameters(), lr=1.0, max_iter=max_iter, tolerance_grad=1e-12,
                                      tolerance_change=mlp.tolerance_change, history_size=20,
                                      line_search_fn="strong_wolfe")  # fmt: skip

        def closure() -> torch.Tensor:
            optimizer.zero_grad()
            loss = torch.mean((net(u) - y) ** 2)
            loss.backward()
            return loss

        optimizer.step(closure)

    if not pretrain:
        train(theta, n, mlp.max_iter_scratch)
        return net
    grid = np.linspace(0.0, theta_end, mlp.n_pretrain_points)
    train(grid, EMG.f(grid, *EMG.initial_guess(theta, n)[0]), mlp.max_iter_pretrain)
    train(np.concatenate([theta, np.full(mlp.n_artificial, theta_end)]),
          np.concatenate([n, np.zeros(mlp.n_artificial)]), mlp.max_iter_finetune)  # fmt: skip
    return net


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--params", type=Path, default=Path("params.yaml"),
                        help="params file (its fit, protocol and parallel sections)")
    parser.add_argument("--skip-stage", action="store_true", help="skip the paper-scale stage run (3)")
    parser.add_argument("--save", type=Path, help="write the table of 3 to this parquet file")
    args = parser.parse_args()
    params, protocol, parallel = (load_section(args.params, s) for s in ("fit", "protocol", "parallel"))
    theta_end = protocol.range_end("arc")
    rng = np.random.default_rng(0)

    theta = np.repeat(2.25 * np.arange(1, 5), 10)  # 4 stops x 10 images, deg
    f = emg(theta, 3000.0, 9.0, 1.0)
    n = np.maximum(np.round(f + rng.normal(0.0, 2.0 + 0.1 * f)), 0.0)
    p0 = EMG.initial_guess(theta, n)[0]

    def scipy_reference() -> None:
        curve_fit(lambda t, alpha, K, mu: alpha * exponnorm.pdf(t - mu, K), theta, n, p0=p0)

    print("1. EMG fit, 4 stops x 10 images")
    reference, seconds = paired_medians(
        scipy_reference, lambda: EMG.fit(theta, n, theta_end=theta_end, max_nfev=params.max_nfev), 200)
    report("reference: curve_fit(alpha * exponnorm.pdf)", reference, reference)
    report("EMG.fit (bounded trf, analytic Jacobian)", seconds, reference, 5e-3)

    print("2. MLP recipes, 4 stops x 10 images (params.fit.mlp)")
    torch.set_num_threads(1)
    for pretrain, target in ((True, 2.0), (False, None)):
        reference, seconds = paired_medians(
            lambda: torch_recipe(theta, n, theta_end, params.mlp, 0, pretrain),
            lambda: fit_mlp(theta, n, theta_end=theta_end, mlp=params.mlp, rng=rng, pretrain=pretrain),
            7,
        )
        report("reference: torch.optim.LBFGS on nn.Sequential", reference, reference)
        report("mlp_pretrained (pretrain + fine-tune)" if pretrain else "mlp_scratch", seconds, reference, target)

    if args.skip_stage:
        return
    workers = worker_count(parallel)
    print(f"3. Fig. 2 experiment at paper scale (21 arcs + 4 lines, {workers} workers)")
    artifacts, _ = synthetic_artifacts(np.random.default_rng(1), n_arcs=21, n_lines=4)
    reference = paired_medians(scipy_reference, scipy_reference, 50)[0]
    # CPU seconds of one arc and one line dataset run serially: a load-independent estimate of the stage
    sample = artifacts[artifacts.dataset.isin(["arc_00", "line_00"])]
    cpu_start = time.process_time()
    with Workers(parallel.model_copy(update={"n_jobs": 1})) as one:  # in this process, where process_time sees it
        sample_table = fig2_rmse(sample, params, protocol, one, progress=False)
    cpu_per_fit = (time.process_time() - cpu_start) / len(sample_table)
    start = time.perf_counter()
    with Workers(parallel) as pool:
        table = fig2_rmse(artifacts, params, protocol, pool, progress=False)
    seconds = time.perf_counter() - start
    estimate = cpu_per_fit * len(table) / workers
    print(f"  {len(table)} fits in {seconds:.1f} s wall = {seconds / reference:.0f} x the curve_fit reference  "
          f"[{'meets' if seconds <= 300 else 'MISSES'} target 300 s]")  # fmt: skip
    print(f"  CPU-time estimate on {workers} free cores: {estimate:.0f} s "
          f"({cpu_per_fit * 1e3:.0f} ms CPU per fit, from a serial run of 2 datasets)")  # fmt: skip
    metrics = fits_metrics(table, params, protocol)
    k = protocol.stops_sampled("arc")
    print(f"  mean RMSE at k = {k} (arcs):", {m: round(v, 1) for m, v in metrics[f"rmse_k{k}"].items()})
    print("  fits per status (fits.json shares them):")
    print(status_counts(table).to_string())
    if args.save:
        table.to_parquet(args.save, index=False)


if __name__ == "__main__":
    main()
