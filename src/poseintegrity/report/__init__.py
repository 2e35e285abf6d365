"""Figure and table helpers shared by the notebooks, and the summary report."""
