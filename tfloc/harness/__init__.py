"""The scenario harness: datasets, generation, the runner, metrics and the report."""
