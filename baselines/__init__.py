"""Baseline matchers, one module each, registered through the ``tfloc.matchers`` entry points."""
