"""Shared fixtures: the paper scenarios, simulated once per session."""

from __future__ import annotations

import contextlib
import io
import os
import subprocess
import sys
from pathlib import Path

import pytest

import pamsim

try:
    import fcntl
except ImportError:  # not on Windows: each test process then builds its own FMUs
    fcntl = None

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / "scenarios"
PAPER_SCENARIOS = {  # name: (supply bar, weight N), from the issue / paper Figs 3-6
    "acra2012_fig3": (4.0, 22.74),
    "acra2012_fig4": (3.6, 22.74),
    "acra2012_fig5": (3.6, 12.74),
    "acra2012_fig6a": (2.8, 12.74),
    "acra2012_fig6b": (2.0, 22.74),
}


@pytest.fixture(scope="session")
def paper_results():
    """{name: (scenario, result)} for the five paper scenarios with their file defaults."""
    out = {}
    for name in PAPER_SCENARIOS:
        sc = pamsim.load_scenario(SCENARIOS / f"{name}.toml")
        out[name] = (sc, pamsim.simulate(sc))
    return out


@pytest.fixture(scope="session")
def fmus(tmp_path_factory):
    """{FMI version: path} of the FMU built once per test session from the current sources.

    The test processes of one ``pytest -n`` session share one build: the first to take the lock
    builds into the session's common temporary folder, the others wait and reuse it.
    """
    from pamsim.fmu import build

    root = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER") and fcntl is not None:
        root = root.parent  # shared by the session's workers, fresh for every session
    folder = root / "session-fmus"
    folder.mkdir(exist_ok=True)
    with open(folder / ".lock", "w") as lock:
        if fcntl is not None:
            fcntl.flock(lock, fcntl.LOCK_EX)
        paths = {v: folder / f"pamsim_muscle_fmi{v}.fmu" for v in (2, 3)}
        return {v: p if p.exists() else build(p, v) for v, p in paths.items()}


@pytest.fixture(scope="session")
def unzipped(fmus):
    """{FMI version: folder} of the extracted session FMUs."""
    from fmpy import extract

    return {v: extract(fmus[v]) for v in (2, 3)}


def run_cli(*args, cwd=None):
    """Run ``python -m pamsim ARGS`` as a user would; returns the CompletedProcess."""
    return subprocess.run([sys.executable, "-m", "pamsim", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=300)


def assert_refused(proc, key: str, output=None) -> None:
    """``proc`` (a :func:`run_main` result) exited 2 with one line naming ``key``, no traceback, and wrote
    nothing to ``output`` (if given)."""
    assert proc.returncode == 2, proc.stderr
    assert key in proc.stderr and "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
    assert output is None or not output.exists()


def run_main(*args):
    """Run ``pamsim ARGS`` in this process (the console script's ``main()``); returns a CompletedProcess.

    Most CLI tests use this (through the :func:`cli` fixture, or directly from module fixtures): a
    subprocess costs an interpreter and the imports every time.  A few representative tests still go
    through :func:`run_cli`.
    """
    from pamsim.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main([str(a) for a in args])
        except SystemExit as exc:  # argparse's own errors
            code = exc.code if isinstance(exc.code, int) else 1
    return subprocess.CompletedProcess(args, code, out.getvalue(), err.getvalue())


@pytest.fixture
def cli():
    """:func:`run_main`, for tests that take the command line as a fixture."""
    return run_main


def start_until_progress(*args, done: int = 10):
    """Start ``pamsim ARGS`` in a process of its own and return ``(process, stderr so far)`` once its
    progress bar shows at least ``done`` runs finished (so its workers are busy)."""
    proc = subprocess.Popen([sys.executable, "-m", "pamsim", *map(str, args)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    seen = ""
    try:
        while True:
            char = proc.stderr.read(1)
            assert char, f"pamsim ended before {done} runs: {seen}"
            seen += char
            if char in "\r\n" and _runs_done(seen) >= done:
                return proc, seen
    except BaseException:
        proc.kill()
        raise


def _runs_done(progress: str) -> int:
    """Runs finished in the last line of a tqdm bar (``name:  1%|   | 20/2000 [...]``)."""
    import re

    found = re.findall(r"\| (\d+)/\d+ \[", progress)
    return int(found[-1]) if found else 0


def slow_study(folder: Path, samples: int = 2000) -> Path:
    """A sweep file in ``folder`` of an uncertainty study of ``samples`` Python-backend runs of Figure 4
    (about 15 ms each): seconds of work, to stop in the middle."""
    path = folder / "slow.toml"
    path.write_text(f'base_scenario = "{(SCENARIOS / "acra2012_fig4.toml").as_posix()}"\nbackend = "python"\n'
                    f'[uncertainty]\nsamples = {samples}\nseed = 3\n[uncertainty.parameters.N0_N_per_bar]\n'
                    'distribution = "uniform"\nrelative = true\nlower = 0.9\nupper = 1.1\n')
    return path


@pytest.fixture
def floats_only_gaylord(monkeypatch):
    """Gaylord's model name given to a static model that takes floats alone (it calls :mod:`math`), so it
    has neither a symbolic nor a CasADi form: what needs C must refuse it by name."""
    import math

    from pamsim.static_models.base import Domain, StaticModelSpec

    class FloatsOnly:
        name = "gaylord"
        domain = Domain(0.0, 0.06, 0.0, 1e6)

        def force_N(self, x_m, p_gauge_Pa):
            return math.fsum([p_gauge_Pa * 2e-4, -500.0 * x_m])

    build = StaticModelSpec.build
    monkeypatch.setattr(StaticModelSpec, "build", lambda spec, params, variant=None:
                        FloatsOnly() if spec.name == "gaylord" else build(spec, params, variant))
    return "gaylord"
