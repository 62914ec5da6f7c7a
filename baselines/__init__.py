"""Baseline matchers, one module each, each declared in its module's ``REGISTRY`` literal
(:mod:`tfloc.core.registry`)."""
