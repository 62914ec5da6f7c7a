"""Real laser logs: building the scenario datasets from ``data/real/`` and settling log quirks."""
