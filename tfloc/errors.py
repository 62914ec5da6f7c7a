"""Every error tfloc raises on purpose derives from :class:`TflocError`.

The CLI catches ``TflocError`` and prints its message as one line (no traceback), so each
message must name the file, row or field at fault and say what is wrong with it.
"""

from __future__ import annotations


class TflocError(Exception):
    """Base class of all deliberate tfloc errors."""


class MapFormatError(TflocError):
    """A map file (GeoJSON, ROS YAML/PGM) is malformed."""


class DatasetError(TflocError):
    """A scenario dataset (scenario.json / scans.csv) is malformed."""


class LogFormatError(TflocError):
    """A CARMEN log or relations file is malformed."""


class InvalidProblemError(TflocError):
    """A localization problem cannot be posed: bad ranges, empty scan, pose outside the map."""


class MatcherError(TflocError):
    """A matcher is unknown, misconfigured or its optional library is missing."""


class LibraryMissingError(MatcherError):
    """A matcher's library is not installed (or fails to import); a run leaves that matcher out."""


class RegistryError(MatcherError):
    """A matcher's declaration is malformed (a module's ``REGISTRY``), or a name is declared twice."""


class ParameterError(MatcherError):
    """A matcher parameter is unknown or has a bad value.

    ``names`` are the parameters at fault (so that a run configuration can name its key)."""

    def __init__(self, message: str, names: tuple[str, ...] = ()) -> None:
        super().__init__(message)
        self.names = tuple(names)


class ResultsError(TflocError):
    """A run's results (estimates.csv, run.json) are malformed, or cannot be written."""


class ConfigError(TflocError):
    """A run configuration (TOML) or a command-line option is invalid."""


class BagError(TflocError):
    """A ROS bag cannot be read or imported: unreadable file, missing topic, bad message."""
