"""The matcher protocol and the registry: the project's own matchers, declared in their modules
(:mod:`tfloc.core.registry`), and third parties' (entry-point group ``tfloc.matchers``).

A third party adds a matcher with one line in its own ``pyproject.toml``::

    [project.entry-points."tfloc.matchers"]
    my-icp = "my_pkg.icp:MyIcpMatcher"

The entry point names a class (or factory) that takes keyword overrides of its configuration
and returns an object with ``name``, ``localize(problem)`` and ``score(problem, pose)``. A name
registered twice (two modules, a module and an entry point, two entry points) is one line
naming both places.

Two optional declarations tell the harness which kinds of task a matcher takes:

* ``solves_global = True``: it answers *global* problems (``problem.initial is None``: no guess,
  the whole map is searched); a local matcher given one gets an ``invalid:`` row, nothing runs
  (:func:`check_solvable`);
* a *tracker* (:mod:`tfloc.core.tracker`) has ``start``/``step`` instead of ``localize`` (e.g.
  AMCL, a filter with no single-scan mode): it runs on sequence datasets only.
"""

from __future__ import annotations

from functools import cache
from importlib.metadata import entry_points
from typing import Any, Protocol, runtime_checkable

from tfloc.errors import (
    InvalidProblemError,
    LibraryMissingError,
    MatcherError,
    ParameterError,
    RegistryError,
)

from .pose import Pose
from .presets import presets, resolve
from .problem import Estimate, Problem
from .registry import declarations

GROUP = "tfloc.matchers"

@runtime_checkable
class Matcher(Protocol):
    """What the harness needs of a localization method. It must never look at the true pose."""

    name: str

    def localize(self, problem: Problem) -> Estimate:
        """Estimate the robot pose for ``problem``."""
        ...

    def score(self, problem: Problem, pose: Pose) -> float:
        """The matcher's own objective at ``pose`` (lower is better); used to classify failures."""
        ...


def solves_global(matcher: object) -> bool:
    """Whether ``matcher`` declares that it answers global problems (no initial guess)."""
    return bool(getattr(matcher, "solves_global", False))


def check_solvable(matcher: object, problem: Problem) -> None:
    """Raise :class:`InvalidProblemError` when ``problem`` is global and ``matcher`` is local
    (the harness turns it into an ``invalid:`` row; no matcher runs)."""
    if problem.is_global and not solves_global(matcher):
        raise InvalidProblemError(f"{problem.where}: a global problem (no initial pose), and matcher "
                                  f"{getattr(matcher, 'name', type(matcher).__name__)!r} solves local problems only")


@cache
def _registry() -> dict[str, str]:
    """Matcher name → ``module:attr``: the project's own declarations (read from its source, not
    imported), then the installed entry points (read once per process)."""
    where = {d.name: f"in {d.path}" for d in declarations()}
    reg = {d.name: d.target for d in declarations()}
    for ep in entry_points(group=GROUP):
        dist = getattr(ep.dist, "name", None) or "an unknown distribution"
        here = f"by the entry point {ep.name} = {ep.value!r} of {dist}"
        if ep.name in reg:
            stale = " (an install older than the source: make install)" if dist == "tfloc" else ""
            raise RegistryError(f"matcher {ep.name!r} is declared twice: {where[ep.name]} and "
                                f"{here}{stale}")
        reg[ep.name], where[ep.name] = ep.value, here
    return reg


def available_matchers() -> list[str]:
    """Names of all registered matchers (whether or not their optional library is installed)."""
    return sorted(_registry())


def _factory(name: str, target: str, registered: bool) -> Any:
    """The class (or factory) ``target`` (``module:attr``) of matcher ``name``: one import path for
    registered matchers and ``module:Class`` names alike."""
    module, _, attr = target.partition(":")
    try:
        return getattr(__import__(module, fromlist=[attr]), attr)
    except ImportError as exc:
        missing = exc.name or ""
        if not registered:
            raise MatcherError(f"matcher {name!r}: cannot import it ({exc})") from None
        if missing and (module == missing or module.startswith(missing + ".")):
            raise MatcherError(f"matcher {name!r}: its module {module!r} is not part of this installation") from None
        lib = f"the library {missing.partition('.')[0]!r}" if missing else "a library"
        raise LibraryMissingError(
            f"matcher {name!r} needs {lib}, which is not installed or failed to import: {exc} "
            f"(install the project with its dependencies: pip install -e .)") from None
    except AttributeError as exc:
        raise MatcherError(f"matcher {name!r}: cannot import it ({exc})") from None


def close_names(name: str, names: list[str], n: int = 3) -> list[str]:
    """The names of ``names`` closest to ``name`` (a misspelling's "did you mean")."""
    import difflib

    return difflib.get_close_matches(name, names, n=n, cutoff=0.6)


def unknown_matcher(name: str) -> str:
    """One line for an unknown matcher name: the closest registered names or presets."""
    known = sorted({*_registry(), *presets()})
    close = close_names(name, known)
    hint = f"did you mean {' or '.join(repr(c) for c in close)}? " if close else ""
    return f"unknown matcher {name!r}; {hint}(tfloc matchers lists them: {', '.join(known)})"


def get_matcher(name: str, **params: Any) -> Matcher:
    """Instantiate the registered matcher ``name`` (a preset or a label ``base[key=value,...]``
    stands for its matcher and parameters, :mod:`tfloc.core.presets`; ``module:Class`` imports
    that module, so its code runs; the command line allows that only with ``--allow-import``)
    with configuration overrides ``params``.

    Raises :class:`MatcherError` for an unknown name or a missing optional library, and its
    subclass :class:`ParameterError` for an unknown parameter or a bad value.
    """
    given = name
    name, params = resolve(name, params)
    if ":" in name:
        factory = _factory(name, name, registered=False)
    else:
        reg = _registry()
        if name not in reg:
            raise MatcherError(unknown_matcher(given if name == given else name))
        factory = _factory(name, reg[name], registered=True)
    name = given
    try:
        return factory(**params)
    except ParameterError as exc:
        raise ParameterError(f"matcher {name!r}: {exc}", exc.names) from None
    except (TypeError, ValueError) as exc:  # a third-party factory that rejects a value the Python way
        raise ParameterError(f"matcher {name!r}: bad parameters {params}: {type(exc).__name__}: {exc}") from None


#: what a matcher solves: one scan from a guess, a sequence (a tracker: start/step, no single-scan
#: mode), or one scan without a guess (a global matcher also answers a scan with a guess)
SINGLE_SCAN, TRACKER, GLOBAL = "single-scan", "tracker", "global"


def kind_of(obj: object) -> str:
    """:data:`SINGLE_SCAN`, :data:`TRACKER` or :data:`GLOBAL` for a matcher, or for its class
    (a class may declare its ``kind``: ``odometry`` answers a single scan with its guess, but is
    meant for sequences)."""
    declared = getattr(obj, "kind", None)
    if declared in (SINGLE_SCAN, TRACKER, GLOBAL):
        return declared
    if solves_global(obj):
        return GLOBAL
    if callable(getattr(obj, "start", None)) and callable(getattr(obj, "step", None)):
        return TRACKER
    return SINGLE_SCAN


def factory_of(name: str) -> Any:
    """The class (or factory) behind a registered name or preset, imported but not built (raises
    :class:`MatcherError` for an unknown name, :class:`LibraryMissingError` for a missing library)."""
    base, _ = resolve(name, {})
    if ":" in base:
        return _factory(base, base, registered=False)
    reg = _registry()
    if base not in reg:
        raise MatcherError(unknown_matcher(name))
    return _factory(base, reg[base], registered=True)


def default_matchers(modes: set[str]) -> list[str]:
    """The registered matchers that solve datasets of ``modes`` (:data:`tfloc.io.scenario.MODES`:
    ``single`` and ``scan-to-scan`` take single-scan matchers, ``sequence`` trackers and
    single-scan matchers, ``global`` global matchers); a matcher whose library is missing is
    listed (the run leaves it out with one line)."""
    want: set[str] = set()
    for mode in modes:
        want |= {"global": {GLOBAL}, "sequence": {TRACKER, SINGLE_SCAN}}.get(mode, {SINGLE_SCAN})
    out = []
    for name in available_matchers():
        try:
            kind = kind_of(factory_of(name))
        except LibraryMissingError:
            kind = SINGLE_SCAN
        if kind in want:
            out.append(name)
    return out
