"""Sweeps in chunks and on a Dask LocalCluster of worker processes: same numbers as the serial run,
a killed worker does not stop the sweep, and a clear error without Dask.
"""

from __future__ import annotations

import math
import os
import signal
import sys
import threading
import time
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from pathlib import Path

import pytest

import pamsim
from pamsim.cli import main as cli_main
from pamsim.sweep import dask_cluster, sweep_from_dict
from pamsim.sweep.run import UNCERTAINTY_TABLES, auto_chunk_size
from conftest import run_main as _cli
from conftest import slow_study, start_until_progress

distributed = pytest.importorskip("distributed", reason="Dask is the optional extra pamsim[dask] (in [test])")

ROOT = Path(__file__).resolve().parents[1]
FIG4 = str(ROOT / "scenarios" / "acra2012_fig4.toml")
SWEEP = {"base_scenario": FIG4, "friction_models": ["load_dependent", "constant"],
         "axes": {"pressure_bar": [2.8, 3.6], "weight_N": [12.74, 32.74]},
         "uncertainty": {"samples": 3, "seed": 11, "parameters": {
             "valve_C_m3_per_s_Pa": {"distribution": "uniform", "relative": True, "lower": 0.9, "upper": 1.1}}}}


def _same(a, b) -> bool:
    """Equal bit for bit, NaN equal to NaN."""
    if isinstance(a, float) and isinstance(b, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    return a == b


def _assert_identical(result, reference):
    assert [r.keys() for r in result.rows] == [r.keys() for r in reference.rows]
    for row, ref in zip(result.rows, reference.rows):
        assert all(_same(row[k], ref[k]) for k in ref), (row, ref)
    for row, ref in zip(result.uncertainty.sample_rows(), reference.uncertainty.sample_rows(), strict=True):
        assert all(_same(row[k], ref[k]) for k in ref), (row, ref)


@pytest.fixture(scope="module")
def spec():
    return sweep_from_dict(SWEEP)


@pytest.fixture(scope="module")
def serial(spec):
    return pamsim.sweep(spec)


@pytest.fixture(scope="module")
def client():
    """The LocalCluster that ``--dask-local 2`` starts (pamsim's settings; workers from the fork server)."""
    with dask_cluster.local_client(2) as c:
        c.wait_for_workers(2, timeout=60)  # local_client does not wait: the tests below count them
        yield c


def test_dask_local_cluster_gives_the_serial_numbers_bit_for_bit(spec, serial, client):
    assert serial.failures == [] and len(serial.rows) == 4
    for chunk_size in (None, 3):  # automatic (1 run per task here) and 3 runs per task
        result = pamsim.sweep(spec, client.get_executor(pure=False), chunk_size=chunk_size)
        _assert_identical(result, serial)


def test_chunked_process_pool_gives_the_serial_numbers(spec, serial):
    with ProcessPoolExecutor(max_workers=2) as pool:
        _assert_identical(pamsim.sweep(spec, pool, chunk_size=4), serial)


def test_automatic_chunk_size_amortises_large_sweeps():
    assert auto_chunk_size(14) == 1
    assert auto_chunk_size(156) == 5           # the grid: 32 tasks
    assert auto_chunk_size(10_000) == 50       # capped: 200 tasks
    assert auto_chunk_size(10_000, "native") == 313  # runs of a millisecond: 32 tasks
    assert auto_chunk_size(100_000, "native") == 1000
    assert auto_chunk_size(10_000, "fmu-cs") == 50
    with pytest.raises(pamsim.errors.InputError, match="chunk_size = 0"):
        pamsim.sweep(sweep_from_dict(SWEEP), ThreadPoolExecutor(1), chunk_size=0)


def test_a_worker_killed_mid_sweep_is_retried_and_the_sweep_completes(spec, serial, client):
    pids = set(client.run(os.getpid).values())
    with ThreadPoolExecutor(1) as outer:  # bound the wait: a hung sweep fails the test, not the session
        running = outer.submit(pamsim.sweep, spec, client.get_executor(pure=False), chunk_size=1,
                               allow_incomplete=True)
        deadline = time.monotonic() + 60
        busy = []
        while not busy and time.monotonic() < deadline:
            busy = [w for w, keys in client.processing().items() if keys]
            time.sleep(0.01)
        pid = client.run(os.getpid, workers=[busy[0]])[busy[0]]
        os.kill(pid, signal.SIGKILL)
        killed_mid_sweep = not running.done()
        result = running.result(timeout=240)
    assert pid in pids and killed_mid_sweep
    # The scheduler re-ran the dead worker's chunk elsewhere (or reported it failed): every row is there,
    # and every row that did not fail carries the serial numbers.
    assert len(result.rows) == len(serial.rows)
    failed = [r for r in result.rows if r["failure"] or r["constant_failure"]]
    ok = [(r, s) for r, s in zip(result.rows, serial.rows) if r not in failed]
    for row, ref in ok:
        assert all(_same(row[k], ref[k]) for k in ref)
    for r in failed:
        assert "lost: KilledWorker" in r["failure"] + r["constant_failure"]
    client.wait_for_workers(2, timeout=60)  # the nanny restarts it for the tests that follow


def _sweep_killing_a_pool_worker(spec, pool, **options):
    """``pamsim.sweep(spec, pool, chunk_size=1, **options)`` with one of the pool's workers killed at once."""
    with ThreadPoolExecutor(1) as outer:
        running = outer.submit(pamsim.sweep, spec, pool, chunk_size=1, **options)
        deadline = time.monotonic() + 60
        while not pool._processes and time.monotonic() < deadline:  # CPython's pool keeps {pid: process}
            time.sleep(0.02)
        # Killed at once: the 14 runs take about 0.2 s on 2 workers, and a worker that dies at any
        # moment before the last result breaks the pool (an earlier 0.2 s wait sometimes missed it).
        os.kill(next(iter(pool._processes)), signal.SIGKILL)
        return running.result(timeout=240)


def test_a_process_pool_worker_killed_mid_sweep_stops_the_sweep(spec):
    """Runs lost to the executor stop the sweep (it used to complete, its lost runs failed rows and its
    quantiles taken from the runs that were left)."""
    with ProcessPoolExecutor(max_workers=2) as pool:
        with pytest.raises(pamsim.errors.RunFailure, match=r"runs lost to the executor \(BrokenProcessPool.*the "
                                                          r"sweep stopped after \d+ of 14 runs"):
            _sweep_killing_a_pool_worker(spec, pool)


def test_a_process_pool_worker_killed_mid_sweep_fails_its_chunks_when_incomplete_is_allowed(spec, serial, tmp_path):
    with ProcessPoolExecutor(max_workers=2) as pool:
        result = _sweep_killing_a_pool_worker(spec, pool, allow_incomplete=True)
        # The broken pool cannot draw the figures either: they are drawn here, and everything is written.
        names = result.write(tmp_path / "out", pool)
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == sorted(names)
    assert all((tmp_path / "out" / n).stat().st_size > 0 for n in names)
    assert len(result.rows) == len(serial.rows)
    errors = [r["failure"] + r["constant_failure"] for r in result.rows]
    assert any("lost: BrokenProcessPool" in e for e in errors)
    for row, ref, e in zip(result.rows, serial.rows, errors):
        if not e:
            assert all(_same(row[k], ref[k]) for k in ref)
    # The uncertainty study says that its sample is incomplete, in the report and in the summary table.
    lost = result.uncertainty.lost()
    if lost:
        assert f"Incomplete sample: {lost} of 6 runs were lost" in (tmp_path / "out" / "uncertainty.md").read_text()
    summary = (tmp_path / "out" / "uncertainty_summary.csv").read_text().splitlines()
    assert summary[0].startswith("friction_model,quantity,runs,failed,lost,")


@pytest.mark.parametrize("preload", [None, "/nonexistent/pamsim_test_preload.py", "hang"],
                         ids=["no worker", "failed start", "hung start"])
def test_a_local_cluster_whose_workers_never_start_fails_the_runs_instead_of_waiting(spec, monkeypatch, tmp_path,
                                                                                   preload):
    """local_client returns before its workers have started; should none start (none asked for, a
    worker whose start fails, one whose start hangs), the runs fail after
    distributed.scheduler.no-workers-timeout (30 s; 2 s here), the sweep completes, and the cluster
    closes (a hung worker gives up after WORKER_START_TIMEOUT_S: 30 s; 3 s here)."""
    import dask

    monkeypatch.setitem(dask_cluster.LOCAL_CLUSTER_CONFIG, "distributed.scheduler.no-workers-timeout", "2s")
    monkeypatch.setattr(dask_cluster, "WORKER_START_TIMEOUT_S", 3.0)
    if preload == "hang":
        preload = tmp_path / "hang.py"
        preload.write_text("import time\ntime.sleep(600)\n")
        preload = str(preload)
    out = {}

    def sweep():
        with dask.config.set({"distributed.worker.preload": [preload] if preload else []}):
            with dask_cluster.local_client(0 if preload is None else 2) as c:
                out["result"] = pamsim.sweep(spec, c.get_executor(pure=False), allow_incomplete=True)
        out["closed"] = True

    # In a daemon thread, so that a hang fails this test instead of stopping the suite.
    thread = threading.Thread(target=sweep, daemon=True)
    thread.start()
    thread.join(timeout=30)
    assert out.get("closed"), "the sweep or the cluster's close hung"
    errors = [r["failure"] + r["constant_failure"] for r in out["result"].rows]
    assert len(errors) == 4 and all("NoWorkerError" in e for e in errors), errors


def test_dask_without_the_extra_is_one_line_naming_it(tmp_path, monkeypatch, capsys):
    (tmp_path / "s.toml").write_text(f'base_scenario = "{FIG4}"\n[axes]\npressure_bar = [3.6]\nweight_N = [22.74]\n')
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed now raises ImportError
    code = cli_main(["sweep", str(tmp_path / "s.toml"), "-o", str(tmp_path / "out"), "--dask", "tcp://h:8786"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "pamsim[dask]" in err[0]
    assert not (tmp_path / "out").exists()


def test_dask_local_without_the_extra_is_one_line_and_starts_nothing(tmp_path, monkeypatch, capsys):
    import multiprocessing.forkserver

    (tmp_path / "s.toml").write_text(f'base_scenario = "{FIG4}"\n[axes]\npressure_bar = [3.6]\nweight_N = [22.74]\n')
    monkeypatch.setitem(sys.modules, "distributed", None)
    monkeypatch.setattr(multiprocessing.forkserver, "ensure_running", lambda: pytest.fail("fork server started"))
    code = cli_main(["sweep", str(tmp_path / "s.toml"), "-o", str(tmp_path / "out"), "--dask-local", "2"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "pamsim[dask]" in err[0]
    assert not (tmp_path / "out").exists()


def test_unreachable_scheduler_is_one_line_exit_2(tmp_path, monkeypatch, capsys):
    (tmp_path / "s.toml").write_text(f'base_scenario = "{FIG4}"\n[axes]\npressure_bar = [3.6]\nweight_N = [22.74]\n')
    monkeypatch.setattr(dask_cluster, "CONNECT_TIMEOUT_S", 1.0)
    code = cli_main(["sweep", str(tmp_path / "s.toml"), "-o", str(tmp_path / "out"), "--dask", "tcp://127.0.0.1:9"])
    lines = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and "--dask tcp://127.0.0.1:9" in lines[0], lines
    assert not (tmp_path / "out").exists()


def test_cli_dask_local_writes_the_same_tables_as_the_serial_api(tmp_path):
    (tmp_path / "s.toml").write_text(
        f'base_scenario = "{FIG4}"\n[axes]\npressure_bar = [3.6]\nweight_N = [12.74, 22.74]\n'
        '[uncertainty]\nsamples = 2\nseed = 5\n[uncertainty.parameters.N0_N_per_bar]\n'
        'distribution = "normal"\nmean = 6.87\nstd = 0.3\nlower = 6.0\nupper = 7.5\n')
    # The reference: the serial run's tables, written by the same writers as SweepResult.write (its
    # figures are not compared, so not drawn).
    one = pamsim.sweep(tmp_path / "s.toml")
    (tmp_path / "one").mkdir()
    one.to_csv(tmp_path / "one" / "summary.csv")
    one.uncertainty.write_tables(*(tmp_path / "one" / n for n in UNCERTAINTY_TABLES))
    dask = _cli("sweep", tmp_path / "s.toml", "-o", tmp_path / "dask", "--dask-local", "2", "--chunk-size", "2",
                "--no-progress")
    assert dask.returncode == 0, dask.stderr
    assert "Dask LocalCluster of 2 worker process(es)" in dask.stdout
    for name in ("summary.csv", *UNCERTAINTY_TABLES):
        assert (tmp_path / "dask" / name).read_bytes() == (tmp_path / "one" / name).read_bytes(), name


def _worker_state():
    """(MALLOC_TRIM_THRESHOLD_ in the worker, pamsim.native imported, the environment its parent
    process, the fork server, started with, (objects frozen out of the garbage collector, collector on))."""
    import gc

    with open(f"/proc/{os.getppid()}/environ", "rb") as fh:
        parent = dict(v.decode().split("=", 1) for v in fh.read().split(b"\0") if b"=" in v)
    return (os.environ.get("MALLOC_TRIM_THRESHOLD_"), "pamsim.native" in sys.modules, parent,
            (gc.get_freeze_count(), gc.isenabled()))


def test_local_workers_keep_the_malloc_defaults_and_use_the_preloaded_fork_server(client):
    """Dask starts its workers with MALLOC_TRIM_THRESHOLD_ (which also turns off glibc's adaptive heap
    threshold, costing the native backend's millisecond runs a quarter of their time); the clusters
    pamsim starts leave it out, fork their workers (a restarted one too: this runs after the
    killed-worker test) from a server that has imported pamsim, frozen those imports out of the
    workers' garbage collection and started with one BLAS thread per worker (numpy's BLAS reads that
    when the server loads it), and give Dask's configuration and this process's environment back as
    they were."""
    import dask

    states = client.run(_worker_state)
    assert len(states) == 2
    for trim, preloaded, server, (frozen, collecting) in states.values():
        assert trim is None and preloaded
        # The server's imports are frozen out of the worker's garbage collection, which is on.
        assert frozen > 10_000 and collecting
        assert "MALLOC_TRIM_THRESHOLD_" not in server
        assert all(server.get(k) == v for k, v in dask_cluster.FORKSERVER_ENVIRON.items()), server
    key = "distributed.nanny.pre-spawn-environ"
    before = {k: dask.config.get(k) for k in (*dask_cluster.LOCAL_CLUSTER_CONFIG, key)}
    environ = dict(os.environ)
    with dask_cluster._local_cluster_settings():
        pre_spawn = dask.config.get(key)
        assert "MALLOC_TRIM_THRESHOLD_" not in pre_spawn
        assert pre_spawn.get("OMP_NUM_THREADS") == 1  # the rest of Dask's worker environment stays
        for k, v in dask_cluster.LOCAL_CLUSTER_CONFIG.items():
            assert dask.config.get(k) == v, k
        os.environ.update({k: "changed" for k in (*pre_spawn, "PYTHONHASHSEED")})  # as Dask's nanny does
        os.environ["PAMSIM_TEST_OTHER"] = "kept"  # a variable Dask does not write is not undone
    assert {k: dask.config.get(k) for k in before} == before
    assert dict(os.environ) == {**environ, "PAMSIM_TEST_OTHER": "kept"}
    del os.environ["PAMSIM_TEST_OTHER"]


def test_local_cluster_serves_no_dashboard_and_leaves_port_8787_alone(client):
    """``--dask-local`` starts a cluster for one sweep: no dashboard (Dask's default serves one on 8787, and
    warns when another program holds that port).  Dask always starts the scheduler's HTTP server: it
    listens on a free local port and answers every page with 404."""
    import urllib.error
    import urllib.request

    link = client.dashboard_link
    assert ":8787/" not in link and link.startswith("http://127.0.0.1:"), link
    for page in ("/status", "/health", "/"):
        with pytest.raises(urllib.error.HTTPError, match="404"):
            urllib.request.urlopen(link.replace("/status", page), timeout=10)


def test_chunk_size_zero_names_the_option_and_the_value(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        cli_main(["sweep", "x.toml", "-o", str(tmp_path / "out"), "--chunk-size", "0"])
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert exc.value.code == 2 and "--chunk-size" in err and "'0'" in err and "worker" not in err, err


def _cli_in_thread(argv, timeout_s=30.0):
    """(exit code, seconds taken) of ``pamsim ARGV`` run in a daemon thread, so that a hang fails the test
    instead of stopping the suite."""
    out = {}

    def target():
        t0 = time.perf_counter()
        out["code"] = cli_main([str(a) for a in argv])
        out["s"] = time.perf_counter() - t0

    thread = threading.Thread(target=target, daemon=True)
    thread.start()
    thread.join(timeout_s)
    assert "code" in out, f"pamsim {' '.join(map(str, argv))} still running after {timeout_s} s"
    return out["code"], out["s"]


def _free_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def tiny_sweep(tmp_path):
    (tmp_path / "s.toml").write_text(f'base_scenario = "{FIG4}"\n[axes]\npressure_bar = [3.6]\nweight_N = [22.74]\n')
    return tmp_path / "s.toml"


def test_a_refused_connection_is_reported_at_once(tiny_sweep, tmp_path, capsys):
    code, took_s = _cli_in_thread(["sweep", tiny_sweep, "-o", tmp_path / "out", "--dask",
                                   f"tcp://127.0.0.1:{_free_port()}"])
    lines = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and "refused" in lines[0], lines
    assert took_s < 3.0, took_s
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("server", ["http", "replies at once"])
def test_a_port_that_is_not_a_dask_scheduler_is_one_line_within_seconds(tiny_sweep, tmp_path, capsys, server):
    """An HTTP server waits for a request, which Dask's client never sends (the sweep hung); a server that
    speaks first had its reply read as the length of a message (a 3 EiB allocation and a traceback)."""
    import http.server
    import socketserver

    class SpeaksFirst(socketserver.BaseRequestHandler):
        def handle(self):
            self.request.sendall(b"HTTP/1.0 400 Bad request\r\n\r\n")

    if server == "http":
        srv = http.server.ThreadingHTTPServer(("127.0.0.1", 0), http.server.SimpleHTTPRequestHandler)
    else:
        srv = socketserver.ThreadingTCPServer(("127.0.0.1", 0), SpeaksFirst)
    threading.Thread(target=srv.serve_forever, daemon=True).start()
    try:
        address = f"tcp://127.0.0.1:{srv.server_address[1]}"
        code, took_s = _cli_in_thread(["sweep", tiny_sweep, "-o", tmp_path / "out", "--dask", address])
    finally:
        srv.shutdown()
        srv.server_close()
    lines = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and "not a Dask scheduler" in lines[0] and address in lines[0], lines
    assert took_s < dask_cluster.HANDSHAKE_TIMEOUT_S + 3.0, took_s
    assert not (tmp_path / "out").exists()


def test_a_running_scheduler_passes_the_handshake_check(client):
    dask_cluster.check_scheduler(client.scheduler.address)  # raises if the real thing is refused


@pytest.fixture
def own_cluster(tmp_path):
    """A scheduler and one worker without a nanny, each a process of its own (as on a cluster of your
    own): ``(address, {"scheduler": Popen, "worker": Popen})``; a test kills one of them."""
    import subprocess

    file = tmp_path / "scheduler.json"
    dask_cli = [sys.executable, "-m", "dask"]
    procs = {"scheduler": subprocess.Popen([*dask_cli, "scheduler", "--port", "0", "--no-dashboard",
                                            "--scheduler-file", str(file)], stderr=subprocess.DEVNULL)}
    try:
        deadline = time.monotonic() + 60
        while not file.exists() and time.monotonic() < deadline:
            time.sleep(0.05)
        procs["worker"] = subprocess.Popen([*dask_cli, "worker", "--scheduler-file", str(file), "--nthreads", "1",
                                            "--no-nanny", "--no-dashboard"], stderr=subprocess.DEVNULL)
        with distributed.Client(scheduler_file=str(file), timeout=60) as c:
            c.wait_for_workers(1, timeout=60)
            address = c.scheduler.address
        yield address, procs
    finally:
        for p in procs.values():
            p.kill()
            p.wait(timeout=30)


def test_a_scheduler_that_dies_mid_sweep_stops_it_with_one_line_and_writes_nothing(own_cluster, tmp_path):
    """It used to exit 0 with a CancelledError line per lost run and quantiles from part of the sample."""
    address, procs = own_cluster
    sweep, seen = start_until_progress("sweep", slow_study(tmp_path), "-o", tmp_path / "out", "--dask", address,
                                       "--chunk-size", "10")
    try:
        procs["scheduler"].kill()
        killed = time.monotonic()
        out, err = sweep.communicate(timeout=60)
    finally:
        sweep.kill()
    took_s = time.monotonic() - killed
    last = [line for line in (seen + err).replace("\r", "\n").splitlines() if line.strip()][-1]
    assert sweep.returncode == 3, seen + err
    assert last.startswith("pamsim: error: ") and "scheduler" in last and "of 2000 runs" in last, last
    assert err.count("CancelledError") <= 1 and "Traceback" not in err, err
    assert took_s < dask_cluster.SCHEDULER_LOST_S + dask_cluster.CLOSE_TIMEOUT_S + 2, took_s
    assert not (tmp_path / "out").exists()


def test_losing_the_last_worker_stops_the_sweep_within_seconds(own_cluster, tmp_path, monkeypatch):
    """A scheduler of your own holds the tasks for ever once its last worker is gone: the sweep hung."""
    monkeypatch.setattr(dask_cluster, "LAST_WORKER_LOST_S", 1.0)
    address, procs = own_cluster
    spec = pamsim.sweep.load_sweep(slow_study(tmp_path))
    with distributed.Client(address, timeout=30) as c, ThreadPoolExecutor(1) as outer:
        running = outer.submit(pamsim.sweep, spec, c.get_executor(pure=False), chunk_size=10)
        while not c.processing() or not any(c.processing().values()):
            time.sleep(0.05)
        procs["worker"].kill()
        killed = time.monotonic()
        with pytest.raises(pamsim.errors.RunFailure, match="lost its last worker for 1 s; the sweep stopped"):
            running.result(timeout=60)
    # The client hears of the workers every 2 s, then the sweep waits LAST_WORKER_LOST_S.
    assert time.monotonic() - killed < 2 + 1 + 3


def test_a_dask_sweep_keeps_four_chunks_out_per_worker_of_the_cluster(client):
    """The chunks sent ahead follow the cluster's workers as the scheduler reports them (at least 8)."""
    from pamsim.sweep.dask_cluster import executor_workers
    from pamsim.sweep.run import chunks_in_flight

    executor = client.get_executor(pure=False)
    deadline = time.monotonic() + 10  # the client hears from the scheduler every 2 s
    while executor_workers(executor) != 2 and time.monotonic() < deadline:
        time.sleep(0.1)
    assert executor_workers(executor) == 2
    assert chunks_in_flight(executor) == 8
