"""The comparison of regenerated files with committed ones (tests/_committed.py) can fail."""

from __future__ import annotations

import pytest
from _committed import assert_same_file


@pytest.mark.parametrize(("made", "committed"), [
    ("a,1.2345,7\n", "a,1.2345,7\n"),
    ("a,1.2346,7\n", "a,1.2345,7\n"),              # one unit of the last digit
    ("r,0.5 2.125e-03\n", "r,0.5 2.126e-03\n"),
    ("x,-0.0001\n", "x,0.0000\n"),
])
def test_equal_within_the_last_written_digit(tmp_path, made, committed) -> None:
    (tmp_path / "a").write_text(made), (tmp_path / "b").write_text(committed)
    assert_same_file(tmp_path / "a", tmp_path / "b")


@pytest.mark.parametrize(("made", "committed", "why"), [
    ("a,1.2347,7\n", "a,1.2345,7\n", "more than one unit"),
    ("a,1.2345,8\n", "a,1.2345,7\n", "number 8 != 7"),     # integers exactly
    ("b,1.2345,7\n", "a,1.2345,7\n", "text"),
    ("a,1.2345,7\na\n", "a,1.2345,7\n", "2 lines regenerated"),
    ("a,1.2345\n", "a,1.2345,7\n", "number of fields"),
])
def test_a_real_difference_fails_naming_the_line(tmp_path, made, committed, why) -> None:
    (tmp_path / "a").write_text(made), (tmp_path / "b").write_text(committed)
    with pytest.raises(AssertionError, match=why):
        assert_same_file(tmp_path / "a", tmp_path / "b")


def test_binary_files_must_be_equal(tmp_path) -> None:
    (tmp_path / "a").write_bytes(b"P5\xff\x00"), (tmp_path / "b").write_bytes(b"P5\xff\x01")
    with pytest.raises(AssertionError, match="binary"):
        assert_same_file(tmp_path / "a", tmp_path / "b")
