"""Presets: named configurations defined once (tfloc/presets.toml), accepted wherever a matcher
name is, with parameters on top; a label ``base[key=value,...]`` is its base with those values."""

from __future__ import annotations

import pytest

from tfloc.core.matcher import get_matcher
from tfloc.core.presets import label_params, merge, preset_params, presets, resolve
from tfloc.errors import ConfigError, MatcherError
from tfloc.harness.config import MatcherSpec
from tfloc.harness.preflight import build_matcher


@pytest.mark.parametrize("name", sorted(presets()))
def test_every_preset_builds_with_its_values(name: str) -> None:
    base, params = resolve(name, {})
    assert ":" not in base and base not in presets()
    _, resolved = build_matcher(MatcherSpec.make(name))
    for key, value in params.items():
        if not isinstance(value, dict):
            assert resolved[key] == value, (name, key)


def test_a_preset_takes_parameters_on_top() -> None:
    m = get_matcher("amcl-tuned", seed=7)
    assert m.config.alpha1 == 0.26 and m.config.sigma_hit == 0.1 and m.config.seed == 7
    g = get_matcher("amcl-tuned-global")
    assert g.config.global_localization and g.config.alpha1 == 0.26 and g.config.recovery_alpha_fast == 0.1


def test_a_preset_of_a_preset_and_a_nested_reference_unroll() -> None:
    assert resolve("amcl-global", {})[0] == "amcl"
    assert preset_params("amcl-global")["recovery_alpha_slow"] == 0.001
    base, params = resolve("tf-plus-track-changed", {"local": {"shortlist": 64}})
    assert base == "tf-plus-track"
    assert params["local"] == {**preset_params("tf-plus-changed"), "shortlist": 64}


def test_a_label_with_parameters_is_its_base_with_them() -> None:
    assert label_params("tf-plus[grid=false,refinement.inlier_distance=0.05]") == (
        "tf-plus", {"grid": False, "refinement": {"inlier_distance": 0.05}})
    assert label_params("gicp[gates=[1.0, 0.5],registration_type=ICP]") == (
        "gicp", {"gates": [1.0, 0.5], "registration_type": "ICP"})
    assert label_params("tf-plus") is None
    m = get_matcher("tf-plus-changed[free_distance=0.08]")
    assert m.config.free_distance == 0.08 and m.config.short_refine
    with pytest.raises(MatcherError, match="not KEY=VALUE"):
        resolve("tf-plus[grid]", {})


def test_merge_is_field_by_field_and_copies() -> None:
    base = {"a": {"x": 1, "y": 2}, "b": 1}
    out = merge(base, {"a": {"y": 3}})
    assert out == {"a": {"x": 1, "y": 3}, "b": 1} and base["a"]["y"] == 2


def test_an_unknown_name_says_what_is_close() -> None:
    with pytest.raises(MatcherError, match=r"did you mean 'csm-corr'( or '[a-z-]+')?\?"):
        get_matcher("csm-cor")
    with pytest.raises(MatcherError, match=r"did you mean 'amcl-tuned'"):
        get_matcher("amcl-tunde")


def test_a_preset_that_refers_to_itself_is_one_line(tmp_path, monkeypatch) -> None:
    from tfloc.core import presets as P

    f = tmp_path / "presets.toml"
    f.write_text('[a]\nmatcher = "b"\n[b]\nmatcher = "a"\n')
    read = P.presets.__wrapped__
    monkeypatch.setattr(P, "presets", lambda path=f: read(f))
    with pytest.raises(ConfigError, match="refers to itself"):
        P.resolve("a", {})
