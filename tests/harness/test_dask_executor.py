"""The runner on dask.distributed: same results as the local runner, time limits, failed tasks,
a worker killed mid-run and a client killed mid-run (loopback clusters only)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
from _paths import ROOT

distributed = pytest.importorskip("distributed")

import dask  # noqa: E402
from test_runner import make_dataset  # noqa: E402

from tfloc.errors import ConfigError  # noqa: E402
from tfloc.harness.config import MatcherSpec, RunConfig  # noqa: E402
from tfloc.harness.dask_executor import execute_dask  # noqa: E402
from tfloc.harness.runner import run  # noqa: E402
from tfloc.io.estimates import read_estimates  # noqa: E402

TESTS = Path(__file__).resolve().parents[1]
ENV = {**os.environ, "PYTHONPATH": os.pathsep.join([str(TESTS), str(ROOT)])}
KEY = ["dataset", "scan_id", "matcher"]


@pytest.fixture(scope="module")
def cluster():
    """A 2-worker LocalCluster on loopback, reached like a remote one (by its tcp:// address)."""
    with dask.config.set({"distributed.worker.daemon": False}), \
            distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                     host="127.0.0.1", dashboard_address=None) as c:
        yield c


def sorted_rows(df: pd.DataFrame) -> pd.DataFrame:
    return df.drop(columns=["runtime_s", "cpu_s"]).sort_values(KEY).reset_index(drop=True)


#: a small bench through the CLI: the local pool's rows are what every cluster must give
BENCH = ["data/scenarios/detail-1", "--limit-per-group", "1", "--no-progress", "--allow-import",
         "--matchers", "csm-corr,toy_matchers:ThreadsInfo,toy_matchers:TwoMinima"]


def bench(out: Path, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "tfloc.cli", "bench", *BENCH, "--out", str(out), *extra],
                          cwd=ROOT, env=ENV, capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module")
def local_rows(tmp_path_factory) -> pd.DataFrame:
    """:data:`BENCH` on the local process pool (made once for the tests that compare with it)."""
    out = tmp_path_factory.mktemp("local") / "run"
    r = bench(out)
    assert r.returncode == 0, r.stderr
    return read_estimates(out)


def test_local_cluster_gives_the_local_runners_estimates(tmp_path, local_rows):
    """CLI --scheduler local:2 vs the local process pool: identical rows but for runtime_s, cpu_s."""
    r = bench(tmp_path / "dask", "--scheduler", "local:2")
    assert r.returncode == 0, r.stderr
    dask_ = read_estimates(tmp_path / "dask")
    assert len(dask_) == 27 and not dask_.duplicated(KEY).any()
    assert (dask_.status == "ok").all() and set(dask_.outcome) >= {"success"}
    pd.testing.assert_frame_equal(sorted_rows(dask_), sorted_rows(local_rows))
    assert dask_[dask_.matcher == "toy_matchers:ThreadsInfo"]["info"].str.contains('"omp_threads":"').all()


def test_failing_and_hanging_tasks_are_rows_not_crashes(tmp_path, test_room, lms200, cluster):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=6)
    cfg = RunConfig(name="t", out=tmp_path / "run", datasets=(ds,), timeout_s=3.0, matchers=(
        MatcherSpec.make("toy_matchers:Raises", label="raises"),
        MatcherSpec.make("toy_matchers:Hangs", {"hang_every": 2}, label="hangs"),
        MatcherSpec.make("toy_matchers:Stay", label="stay")))
    t0 = time.perf_counter()
    df = read_estimates(run(cfg, progress=False, executor=execute_dask(cluster.scheduler_address)))
    assert time.perf_counter() - t0 < 180  # the hanging tasks were stopped at their limit (a shared machine: slack)
    assert len(df) == 18 and not df.duplicated(KEY).any()
    assert df[df.matcher == "raises"].status.str.startswith("error:ValueError: toy failure").any()
    assert (df[df.matcher == "hangs"].status == "timeout").any()
    assert (df[df.matcher == "stay"].status == "ok").all()
    assert (df[df.status != "ok"].outcome == "no-answer").all()


def _busy(dask_worker) -> tuple[int, int]:
    """(pid, number of tasks executing) of a Dask worker (run on the worker)."""
    return os.getpid(), len(dask_worker.state.executing)


def test_a_worker_killed_mid_run_loses_and_repeats_nothing(tmp_path, test_room, lms200, cluster):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=12)
    cfg = RunConfig(name="t", out=tmp_path / "run", datasets=(ds,), timeout_s=30.0, matchers=(
        MatcherSpec.make("toy_matchers:SlowStay", {"sleep_s": 0.5}, label="slow"),))
    dask_run = execute_dask(cluster.scheduler_address)
    victims = []

    def killing_executor(tasks, jobs, timeout_s, on_row):
        def on_row_and_kill(row):
            on_row(row)
            if not victims:  # kill a worker in the middle of a 0.5 s task
                with distributed.Client(cluster) as client:
                    busy = [pid for pid, n in client.run(_busy).values() if n]
                if busy:
                    victims.append(busy[0])
                    os.kill(busy[0], signal.SIGKILL)
        dask_run(tasks, jobs, timeout_s, on_row_and_kill)

    df = read_estimates(run(cfg, progress=False, executor=killing_executor))
    assert victims and len(df) == 12 and not df.duplicated(KEY).any()
    assert set(df.scan_id) == {f"s{i}" for i in range(12)}
    assert (df.status == "ok").all(), df.status.value_counts()
    story = [(k, start, finish) for k, start, finish, *_ in cluster.scheduler.transition_log
             if str(k).startswith("tfloc-")]
    rerun = {k for k, start, finish in story if start == "processing" and finish == "released"}
    assert rerun  # at least one task was running on the killed worker and ran again elsewhere
    with distributed.Client(cluster) as client:
        client.wait_for_workers(2, timeout=60)
        pids_after = set(client.run(os.getpid).values())
    assert victims[0] not in pids_after  # the worker really died (and the nanny replaced it)


def test_resume_after_the_client_is_killed(tmp_path, test_room, lms200):
    ds = make_dataset(tmp_path / "ds", test_room, lms200, n=12)
    out = tmp_path / "run"
    cmd = [sys.executable, "-m", "tfloc.cli", "bench", str(ds), "--out", str(out), "--no-progress",
           "--allow-import", "--matchers", "toy_matchers:SlowStay,toy_matchers:TwoMinima", "--scheduler", "local:2"]
    proc = subprocess.Popen(cmd, env=ENV, start_new_session=True, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    est = out / "estimates.csv"
    deadline = time.time() + 120
    while time.time() < deadline and not (est.exists() and est.read_text().count("\n") >= 5):
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)  # client, LocalCluster and its workers
    proc.wait()
    n_before = est.read_text().count("\n") - 1
    r = subprocess.run(cmd, env=ENV, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    df = read_estimates(out)
    assert 4 <= n_before < 24
    assert len(df) == 24 and not df.duplicated(KEY).any()


def test_workers_without_the_data_are_named(tmp_path, cluster):
    cfg = RunConfig(name="t", out=tmp_path / "run", datasets=(ROOT / "data/scenarios/detail-1",),
                    limit_per_group=1, matchers=(MatcherSpec.make("toy_matchers:Stay"),))
    executor = execute_dask(cluster.scheduler_address)

    def elsewhere(tasks, jobs, timeout_s, on_row):  # the workers look for the data at another path
        from dataclasses import replace
        executor([replace(t, dataset="no/such/dataset") for t in tasks], jobs, timeout_s, on_row)

    with pytest.raises(ConfigError, match=r"Dask worker tcp://127\.0\.0\.1:\d+ has no dataset "
                                          r"no/such/dataset"):
        run(cfg, progress=False, executor=elsewhere)


def test_a_tls_cluster_gives_the_local_pools_rows(tmp_path, local_rows):
    """A LocalCluster that speaks only TLS (throw-away certificates), reached like a remote one by
    its tls:// address with --tls-* certificate files: the same rows as the local process pool."""
    pytest.importorskip("cryptography")
    from distributed.security import Security

    sec = Security.temporary()
    pem = {"ca.pem": sec.tls_ca_file, "client.pem": sec.tls_client_cert, "client.key": sec.tls_client_key}
    for name, text in pem.items():
        (tmp_path / name).write_text(text)
    with dask.config.set({"distributed.worker.daemon": False}), \
            distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                     protocol="tls://", security=sec, dashboard_address=None) as c:
        assert c.scheduler_address.startswith("tls://127.0.0.1:")
        r = bench(tmp_path / "tls", "--scheduler", c.scheduler_address, "--tls-ca-file", str(tmp_path / "ca.pem"),
                  "--tls-cert", str(tmp_path / "client.pem"), "--tls-key", str(tmp_path / "client.key"))
        assert r.returncode == 0, r.stderr
        r = bench(tmp_path / "no", "--scheduler", c.scheduler_address)
        assert r.returncode == 2 and "TLS needs a CA file and a client certificate" in r.stderr
        assert not (tmp_path / "no").exists()
    tls_ = read_estimates(tmp_path / "tls")
    assert len(tls_) == 27 and (tls_.status == "ok").all()
    pd.testing.assert_frame_equal(sorted_rows(tls_), sorted_rows(local_rows))
