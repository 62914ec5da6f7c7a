"""Run a benchmark's tasks on a Dask cluster: ``tfloc bench ... --scheduler ADDRESS``.

``ADDRESS`` is a running scheduler (``tls://HOST:8786``, or ``tcp://…``) or ``local:N``, a
:class:`distributed.LocalCluster` of N single-threaded worker processes on 127.0.0.1.

Who may run code: anyone who can reach a scheduler can run arbitrary code on its workers. A
``tls://`` scheduler is reached with Dask's :class:`~distributed.security.Security`: certificates
from ``--tls-ca-file/--tls-cert/--tls-key`` or from the Dask configuration
(``distributed.comm.tls.*``), and with ``require_encryption``; a plain ``tcp://`` scheduler that
is not on this machine gets a warning (use TLS or an SSH tunnel). Dask does the
scheduling; tfloc only submits its (scan, matcher) tasks, which carry a dataset path, a scan id
and a matcher spec (never a map), and writes each row to ``estimates.csv`` as its task finishes.
The client is the only writer, so every task ends in exactly one row: when a worker dies, Dask
runs its tasks again elsewhere; a task that kills workers repeatedly (``KilledWorker``) becomes an
``error:worker died`` row. The per-task time limit and the per-worker data caches are those of
:mod:`tfloc.harness.dask_worker`. Resume after a crash of the client is the runner's (finished
keys are skipped). ``distributed`` is an optional dependency (``pip install tfloc[dask]``).
"""

from __future__ import annotations

import contextlib
import re
import sys
import uuid
from collections.abc import Callable, Iterator

from tfloc.core.result import ResultRow
from tfloc.errors import ConfigError

from .runner import Executor, worker_died
from .task import Task, error_status, failure_row

INSTALL_HINT = "pip install tfloc[dask]"
_LOCAL = re.compile(r"local:(\d+)")


def parse_scheduler(address: str) -> tuple[str, int | str]:
    """``("local", N)`` for ``local:N``, ``("remote", address)`` for ``proto://host:port``."""
    m = _LOCAL.fullmatch(address)
    if m:
        n = int(m.group(1))
        if n < 1:
            raise ConfigError(f"--scheduler {address}: local:N needs N ≥ 1 workers")
        return "local", n
    if re.fullmatch(r"[a-z+]+://\S+", address):
        return "remote", address
    raise ConfigError(f"--scheduler {address!r}: expected local:N or a scheduler address like "
                      "tls://HOST:8786")


def security(address: str, tls_ca_file: str | None = None, tls_cert: str | None = None,
             tls_key: str | None = None):
    """The :class:`distributed.security.Security` to reach ``address`` with: for ``tls://``, the
    given certificate files, else those of the Dask configuration (an error if there are none);
    ``None`` for other addresses (a warning for plain ``tcp://`` to another machine)."""
    options = (("--tls-ca-file", "tls_ca_file", tls_ca_file), ("--tls-cert", "tls_client_cert", tls_cert),
               ("--tls-key", "tls_client_key", tls_key))
    given = {kw: v for _, kw, v in options if v}
    if not address.startswith("tls://"):
        if given:
            raise ConfigError(f"--scheduler {address}: --tls-* options need a tls:// scheduler address")
        host = address.partition("://")[2].rpartition(":")[0].strip("[]")
        if address.startswith("tcp://") and host not in ("127.0.0.1", "localhost", "::1"):
            print(f"tfloc bench: warning: {address} is plain TCP: no encryption, no authentication; anyone "
                  "who can reach it can run code on the workers. Use tls:// (docs/dask.md: Running on a Dask "
                  "cluster) or an SSH tunnel", file=sys.stderr)
        return None
    _require_distributed()
    from distributed.security import Security

    for option, _, v in options:
        try:
            if v:
                open(v, "rb").close()
        except OSError as exc:
            raise ConfigError(f"{option} {v}: cannot read ({exc.strerror or exc})") from None
    sec = Security(require_encryption=True, **given)
    if not (sec.tls_ca_file and sec.tls_client_cert):
        raise ConfigError(f"--scheduler {address}: TLS needs a CA file and a client certificate: give "
                          "--tls-ca-file and --tls-cert (and --tls-key), or set distributed.comm.tls.ca-file "
                          "and distributed.comm.tls.client.cert in the Dask configuration")
    return sec


def _require_distributed() -> None:
    try:
        import distributed  # noqa: F401
    except ImportError:
        raise ConfigError(f"--scheduler needs dask.distributed, which is not installed: "
                          f"{INSTALL_HINT}") from None


@contextlib.contextmanager
def connect(address: str, sec=None) -> Iterator:
    """A :class:`distributed.Client` for ``address`` (starting and closing a LocalCluster for
    ``local:N``), with the :class:`~distributed.security.Security` ``sec`` if given. Worker
    processes are started non-daemonic, so that they can run task processes."""
    import dask
    from distributed import Client, LocalCluster

    kind, where = parse_scheduler(address)
    with dask.config.set({"distributed.worker.daemon": False}):  # also for workers restarted later
        if kind == "local":
            with LocalCluster(n_workers=where, threads_per_worker=1, processes=True,
                              host="127.0.0.1", dashboard_address=None) as cluster, \
                    Client(cluster) as client:
                client.wait_for_workers(where, timeout=120)
                yield client
            return
        try:
            client = Client(where, timeout=30, **({"security": sec} if sec is not None else {}))
        except (OSError, TimeoutError, ValueError) as exc:
            raise ConfigError(f"--scheduler {where}: cannot connect ({exc})") from None
        with client:
            yield client


def check_workers(client, tasks: list[Task]) -> None:
    """Fail at once, naming the worker, if a worker cannot run tasks (missing data, daemonic)."""
    from .dask_worker import preflight

    datasets = sorted({t.dataset for t in tasks})
    bad = {w: p for w, p in client.run(preflight, datasets).items() if p}
    if bad:
        w, problems = next(iter(bad.items()))
        more = f" (and {len(bad) - 1} more workers)" if len(bad) > 1 else ""
        raise ConfigError(f"Dask worker {w} {'; '.join(problems)}{more}")


def execute_dask(address: str, sec=None) -> Executor:
    """An :data:`~tfloc.harness.runner.Executor` running tasks on the Dask cluster at ``address``
    (``local:N``, ``tls://HOST:PORT`` with the :class:`~distributed.security.Security` ``sec``, or
    ``tcp://HOST:PORT``); ``jobs`` is ignored (the workers set the parallelism)."""
    parse_scheduler(address)
    _require_distributed()

    def execute(tasks: list[Task], jobs: int, timeout_s: float,
                on_row: Callable[[ResultRow | list[ResultRow]], None]) -> None:
        from distributed import as_completed
        from distributed.scheduler import KilledWorker

        from .dask_worker import PLUGIN_NAME, TaskPool, run_on_worker

        with connect(address, sec) as client:
            check_workers(client, tasks)
            client.register_plugin(TaskPool(), name=PLUGIN_NAME)
            run_id = uuid.uuid4().hex[:12]  # keys never collide with an earlier client's
            futures = client.map(run_on_worker, tasks, timeout_s=timeout_s, pure=False,
                                 key=[f"tfloc-{run_id}-{i}" for i in range(len(tasks))])
            by_key = {f.key: t for f, t in zip(futures, tasks, strict=True)}
            finished = as_completed(futures)
            del futures  # as_completed holds each future until it is done, then we release it
            for fut in finished:
                t = by_key[fut.key]
                try:
                    row = fut.result()
                except KilledWorker as exc:
                    row = failure_row(t, worker_died(exc))
                except Exception as exc:  # noqa: BLE001 - a failed task is a row, not a crash
                    row = failure_row(t, error_status(exc))
                on_row(row)
                fut.release()

    return execute
