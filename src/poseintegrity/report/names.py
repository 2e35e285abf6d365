"""The predictors' names as the report writes them."""

NAMES = {"static": "static", "long_range": "long range", "next_step": "next step", "mlp": "MLP",
         "error_long_range": "error long range", "error_next_step": "error next step",
         "error_next_step_observed": "observed error next step", "error_combined": "error combined",
         "hazard_next_step": "hazard next step", "hazard_long_range": "hazard long range"}
