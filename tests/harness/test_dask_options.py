"""``--scheduler`` errors: bad addresses and a missing ``distributed`` are one-line messages."""

from __future__ import annotations

import subprocess
import sys

import pytest
from _paths import ROOT

from tfloc.errors import ConfigError
from tfloc.harness.dask_executor import execute_dask, parse_scheduler


@pytest.mark.parametrize("address, parsed", [("local:3", ("local", 3)),
                                             ("tcp://10.0.0.5:8786", ("remote", "tcp://10.0.0.5:8786")),
                                             ("tls://sched.lab:8786", ("remote", "tls://sched.lab:8786"))])
def test_scheduler_addresses(address, parsed):
    assert parse_scheduler(address) == parsed


@pytest.mark.parametrize("address", ["local:0", "local", "10.0.0.5:8786", "local:two"])
def test_bad_scheduler_is_a_one_line_cli_error(address, tmp_path):
    r = subprocess.run([sys.executable, "-m", "tfloc.cli", "bench", "data/scenarios/detail-1",
                        "--matchers", "tf", "--out", str(tmp_path / "r"), "--scheduler", address],
                       cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "--scheduler" in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "r" / "estimates.csv").exists()


def test_missing_distributed_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed -> ImportError
    with pytest.raises(ConfigError, match=r"pip install tfloc\[dask\]"):
        execute_dask("local:2")


def test_tls_certificates_from_options_or_the_dask_config(tmp_path, capsys):
    pytest.importorskip("distributed")
    import dask

    from tfloc.harness.dask_executor import security

    for name in ("ca.pem", "c.pem", "c.key"):
        (tmp_path / name).write_text("-----BEGIN CERTIFICATE-----\n")
    sec = security("tls://sched.lab:8786", str(tmp_path / "ca.pem"), str(tmp_path / "c.pem"), str(tmp_path / "c.key"))
    assert sec.tls_ca_file == str(tmp_path / "ca.pem") and sec.require_encryption
    with dask.config.set({"distributed.comm.tls.ca-file": str(tmp_path / "ca.pem"),
                          "distributed.comm.tls.client.cert": str(tmp_path / "c.pem")}):
        assert security("tls://sched.lab:8786").tls_client_cert == str(tmp_path / "c.pem")
    with pytest.raises(ConfigError, match="TLS needs a CA file"):
        security("tls://sched.lab:8786")
    with pytest.raises(ConfigError, match=r"--tls-cert .*nope.pem: cannot read"):
        security("tls://sched.lab:8786", str(tmp_path / "ca.pem"), str(tmp_path / "nope.pem"))
    with pytest.raises(ConfigError, match="need a tls:// scheduler"):
        security("tcp://sched.lab:8786", str(tmp_path / "ca.pem"))
    assert security("tcp://127.0.0.1:8786") is None and "warning" not in capsys.readouterr().err
    assert security("tcp://sched.lab:8786") is None
    err = capsys.readouterr().err
    assert "warning: tcp://sched.lab:8786 is plain TCP" in err and "anyone who can reach it can run code" in err
