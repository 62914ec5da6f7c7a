"""Range noise of a simulated LMS200 scan: Gaussian range error, dropouts, spurious short returns."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.errors import ConfigError


@dataclass(frozen=True)
class NoiseModel:
    """Noise applied to ideal (raycast) ranges.

    Attributes:
        sigma_m: standard deviation of the Gaussian range error (metres). The LMS200's data
            sheet gives a systematic error of about ±15 mm and a statistical error (1σ) of
            about 5 mm at short range; 1 cm is a realistic overall default.
        dropout_prob: probability that a beam with a return reports none (``inf``).
        spurious_prob: probability that a beam reports a spurious short return, uniform in
            ``[min_range_m, true range)`` (dust, people's legs, glass).
        min_range_m: smallest range the scanner reports (metres).
    """

    sigma_m: float = 0.01
    dropout_prob: float = 0.0
    spurious_prob: float = 0.0
    min_range_m: float = 0.05

    def __post_init__(self) -> None:
        if not self.sigma_m >= 0:
            raise ConfigError(f"noise sigma_m must be ≥ 0, got {self.sigma_m}")
        for name in ("dropout_prob", "spurious_prob"):
            p = getattr(self, name)
            if not 0.0 <= p <= 1.0:
                raise ConfigError(f"noise {name} must be in [0, 1], got {p}")

    def record(self) -> dict[str, float]:
        """The noise as a dataset's ``generator`` record states it (``sigma_m``, ``dropout_prob``,
        ``spurious_prob``, in this order: the bundled datasets' bytes depend on it)."""
        return {"sigma_m": self.sigma_m, "dropout_prob": self.dropout_prob,
                "spurious_prob": self.spurious_prob}

    def apply(self, ranges: np.ndarray, laser: LaserSpec, rng: np.random.Generator) -> np.ndarray:
        """Noisy copy of ``ranges`` (metres, ``inf`` = no return). Always draws the same number of
        random values for a given beam count, so results depend only on the generator state."""
        r = np.asarray(ranges, dtype=float).copy()
        n = r.size
        gauss = rng.normal(0.0, 1.0, n) * self.sigma_m
        u_drop, u_spur, u_where = rng.random(n), rng.random(n), rng.random(n)
        hit = laser.valid(r)
        out = np.where(hit, r + gauss, np.inf)
        spur = hit & (u_spur < self.spurious_prob)
        out[spur] = self.min_range_m + u_where[spur] * np.maximum(r[spur] - self.min_range_m, 0.0)
        out[hit & (u_drop < self.dropout_prob)] = np.inf
        out = np.where(np.isfinite(out), np.maximum(out, self.min_range_m), np.inf)
        out[out >= laser.max_range] = np.inf
        return out
