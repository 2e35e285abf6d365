"""Artifact models f: theta -> n_inliers (Windsor et al. III-D, Fig. 2), fitted to the first stops of a dataset.

    series.py          Series: one dataset's samples (theta, n_inliers per image, in stop order)
    fitted.py          FittedModel: what every fitter returns (status ok / at_bound / non_physical / fallback, reason)
    base_functions.py  eq. 1 (scaled EMG), four other decays and the free-width EMG (ours), by bounded least squares
    mlp.py             the 3 x 10 tanh MLP (IV-E), from scratch or EMG-pretrained + fine-tuned (III-D)
    mlp_net.py         the MLP as a flat parameter vector: forward pass and analytic gradient of its MSE (numba)
    lbfgs.py           L-BFGS with a strong Wolfe line search on the MLP's MSE: torch.optim.LBFGS in numba
    models.py          fit_model(name, ...): one entry point for all of them
    fig2.py            the Fig. 2 experiment on the stage-02 artifacts table
    synthetic.py       a synthetic artifacts table drawn from eq. 1 + noise, with stage 02's schema
"""

import lazy_loader

# Names resolve on first use, so that importing one module of the package (its params schema, say) does not
# import all of them: the stage runner and every worker process import only what they run.
__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submod_attrs={
        "base_functions": [
            "BASE_FUNCTIONS", "EMG", "EMG_FREE_WIDTH", "LEAST_SQUARES", "BaseFunction", "emg", "emg_free_width",
            "emg_pdf",
        ],
        "fig2": ["at_sampled_stops", "fig2_rmse", "fit_first_stops", "fits_metrics", "mean_rmse", "status_counts"],
        "fitted": ["FIT_STATUSES", "FallbackLine", "FittedModel"],
        "mlp": ["fit_mlp"],
        "models": ["fit_model"],
        "series": ["Series", "dataset_series"],
    },
)
