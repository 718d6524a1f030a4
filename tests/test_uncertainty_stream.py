"""An uncertainty study's samples table is written to disk while the study runs, in the order of the runs,
under a hidden temporary name until the study is done; the chunks sent ahead are bounded; a study whose
table would not fit on the disk is refused before it starts."""

from __future__ import annotations

import csv
import io
import math
import threading
import time
from concurrent.futures import Executor, Future
from pathlib import Path

import pytest

import pamsim
from pamsim.sweep import run, sweep_from_dict
from pamsim.sweep.sample_table import NAME, row_bytes
from conftest import run_main as _cli

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"
FIG4 = str(SCENARIOS / "acra2012_fig4.toml")
FRICTIONS = ["load_dependent", "constant"]
SAMPLES = 8
STUDY = {"base_scenario": FIG4, "backend": "python", "friction_models": FRICTIONS,
         "uncertainty": {"samples": SAMPLES, "seed": 21, "sampling": "random", "parameters": {
             "N0_N_per_bar": {"distribution": "normal", "mean": 6.87, "std": 0.3, "lower": 6.0, "upper": 7.5},
             "valve_C_m3_per_s_Pa": {"distribution": "uniform", "relative": True, "lower": 0.9, "upper": 1.1}}}}


def _temporaries(folder: Path) -> list[Path]:
    return sorted(folder.glob(f".pamsim-{NAME}.*.tmp"))


class _ReversedExecutor(Executor):
    """Runs each chunk when it is sent, but finishes the chunks in batches of three, the last sent first (a
    thread finishes a smaller batch once the sweep has sent nothing for 50 ms: it waits for results).  It records how many chunks were
    out (sent, their result not yet taken) and the lines of the table's temporary file at each send."""

    _max_workers = 1  # the sweep keeps out 4 chunks per worker, at least 8

    def __init__(self, folder: Path, fail_at: int | None = None):
        self.folder, self.fail_at = folder, fail_at
        self.lock = threading.Lock()
        self.waiting: list[tuple[Future, object]] = []
        self.sent = self.taken = self.most_out = 0
        self.finished: list[int] = []
        self.lines_seen: list[int] = []
        self.last_send = time.monotonic()
        self.sending = False
        self.stop = False
        threading.Thread(target=self._finish, daemon=True).start()

    def submit(self, fn, *args, **kwargs):
        if self.sent == self.fail_at:
            raise KeyboardInterrupt  # as Ctrl-C would, in the middle of the study
        with self.lock:
            self.sending = True
        temporaries = _temporaries(self.folder)
        self.lines_seen.append(len(temporaries[0].read_text().splitlines()) if temporaries else -1)
        future = _Taken(self)
        result = fn(*args, **kwargs)
        with self.lock:
            self.waiting.append((future, result, self.sent))
            self.sent += 1
            self.most_out = max(self.most_out, self.sent - self.taken)
            self.last_send = time.monotonic()
            self.sending = False
        return future

    def _finish(self):
        while not self.stop:
            time.sleep(0.002)
            with self.lock:
                idle = not self.sending and time.monotonic() - self.last_send > 0.05
                if len(self.waiting) < 3 and not (idle and self.waiting):
                    continue
                batch, self.waiting = self.waiting[:3], self.waiting[3:]
            for future, result, index in reversed(batch):
                if future.set_running_or_notify_cancel():  # the sweep cancels what is out when it stops
                    self.finished.append(index)
                    future.set_result(result)

    def shutdown(self, wait=True, **kwargs):
        self.stop = True


class _Taken(Future):
    """A future that counts the first time its result is taken."""

    def __init__(self, executor):
        super().__init__()
        self.executor, self.counted = executor, False

    def result(self, timeout=None):
        value = super().result(timeout)
        if not self.counted:
            self.counted = True
            with self.executor.lock:
                self.executor.taken += 1
        return value


def _rows_by_hand(spec) -> str:
    """The samples table made without the sweep: each sample simulated here, its row formatted as the table
    was before it was streamed (csv.DictWriter over every row, 9 significant digits)."""
    samples = spec.uncertainty.draw()
    buffer = io.StringIO()
    w = None
    for friction in FRICTIONS:
        base = spec.base.with_changes({"model": {"friction": friction}})
        for k, values in enumerate(samples.values):
            params = dict(zip(samples.names, map(float, values)))
            result = pamsim.simulate(base.with_changes({"parameters": params}), backend="python")
            row = {"sample": k, "friction_model": friction, **params,
                   "final_contraction_m": float(result.x_m[-1]),
                   "peak_contraction_m": float(result.peak_contraction_m),
                   "contraction_settled_time_s": pamsim.sweep.settled_time_s(result.t_s, result.x_m),
                   "at_rest": bool(result.at_rest_at_end), "failure": ""}
            if w is None:
                w = csv.DictWriter(buffer, fieldnames=list(row))
                w.writeheader()
            w.writerow({k: (f"{v:.9g}" if isinstance(v, float) else v) for k, v in row.items()})
    return buffer.getvalue()


@pytest.fixture(scope="module")
def spec():
    return sweep_from_dict(STUDY)


def test_rows_reach_the_disk_in_the_order_of_the_runs_while_chunks_finish_out_of_order(spec, tmp_path):
    out = tmp_path / "out"
    executor = _ReversedExecutor(tmp_path)  # the output folder does not exist yet: the file is made beside it
    try:
        result = pamsim.sweep(spec, executor, chunk_size=1, output_dir=out)
    finally:
        executor.shutdown()
    runs = SAMPLES * len(FRICTIONS)
    assert executor.sent == runs
    # The chunks finished out of order, and no more than the window were out at once.
    assert executor.finished != sorted(executor.finished)
    assert executor.most_out == run.MIN_IN_FLIGHT == 8
    # Rows were on disk before the last chunk was sent, under the temporary name, not the final one.
    assert 1 < max(executor.lines_seen) < runs + 1, executor.lines_seen
    assert not out.exists()
    with result:
        names = result.write(out)
        assert len(_temporaries(tmp_path)) == 1  # until the result is closed
    assert _temporaries(tmp_path) == [] and NAME in names
    table = (out / NAME).read_bytes().decode()
    assert table == _rows_by_hand(spec)
    # Every row within the bound the disk check assumes.
    for line in table.splitlines(keepends=True)[1:]:
        assert len(line.encode()) <= max(row_bytes(SAMPLES, 2, f) for f in FRICTIONS)


def test_the_tables_and_quantiles_do_not_depend_on_the_order_the_chunks_finish(spec, tmp_path):
    serial = pamsim.sweep(spec, output_dir=tmp_path)
    executor = _ReversedExecutor(tmp_path)
    try:
        reversed_ = pamsim.sweep(spec, executor, chunk_size=3, output_dir=tmp_path)
    finally:
        executor.shutdown()
    with serial, reversed_:
        assert reversed_.uncertainty.quantile_rows() == serial.uncertainty.quantile_rows()
        serial.write(tmp_path / "a")
        reversed_.write(tmp_path / "b")
    for name in ("uncertainty_samples.csv", "uncertainty_summary.csv", "uncertainty.md"):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes(), name
    assert _temporaries(tmp_path) == []


@pytest.mark.parametrize("made", [False, True], ids=["output folder not made yet", "output folder exists"])
def test_an_interrupted_study_leaves_no_table_and_no_temporary_file(spec, tmp_path, made):
    out = tmp_path / "out"
    if made:
        out.mkdir()
    executor = _ReversedExecutor(out if made else tmp_path, fail_at=12)  # after rows were written
    try:
        with pytest.raises(KeyboardInterrupt):
            pamsim.sweep(spec, executor, chunk_size=1, output_dir=out)
    finally:
        executor.shutdown()
    assert max(executor.lines_seen) > 1
    assert sorted(p.name for p in tmp_path.iterdir()) == (["out"] if made else [])
    assert not made or list(out.iterdir()) == []


def test_an_interrupt_while_the_outputs_are_written_leaves_nothing(tmp_path, monkeypatch):
    from pamsim.cli import main
    from pamsim.sweep import figures

    (tmp_path / "study").mkdir()
    (tmp_path / "study" / "s.toml").write_text(
        f'base_scenario = "{FIG4}"\n[uncertainty]\nsamples = 3\nseed = 1\n'
        '[uncertainty.parameters.N0_N_per_bar]\ndistribution = "uniform"\nlower = 6.0\nupper = 7.0\n')

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(figures, "render_all", interrupted)
    code = main(["sweep", str(tmp_path / "study" / "s.toml"), "-o", str(tmp_path / "out"), "--workers", "1",
                 "--no-progress"])
    assert code == 130
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["s.toml", "study"]


def test_failed_runs_are_counted_and_their_messages_are_all_in_the_table(spec, tmp_path, monkeypatch):
    """A study keeps the messages of its first failed samples in memory, not all of them."""
    monkeypatch.setattr(pamsim.sweep.uncertainty, "MAX_KEPT_MESSAGES", 3)
    monkeypatch.setattr(run, "run_chunk", lambda tasks: [{"error": f"ValueError: sample {t.key[0]}"} for t in tasks])
    with pamsim.sweep(spec, output_dir=tmp_path) as result:
        result.write(tmp_path / "out")
    assert result.failed_runs == 2 * SAMPLES
    assert result.failures == [f"acra2012_fig4 sample {k}: ValueError: sample {k}"
                               for _ in FRICTIONS for k in range(3)]
    with open(tmp_path / "out" / NAME, newline="") as fh:
        table = list(csv.DictReader(fh))
    assert [r["failure"] for r in table] == [f"ValueError: sample {k}" for _ in FRICTIONS for k in range(SAMPLES)]
    assert all(r["final_contraction_m"] == "nan" and r["at_rest"] == "nan" for r in table)
    summary = list(csv.DictReader(open(tmp_path / "out" / "uncertainty_summary.csv")))
    assert all(r["failed"] == str(SAMPLES) and r["runs"] == "0" for r in summary)


def test_a_study_too_large_for_the_disk_is_refused_before_anything_runs(tmp_path, monkeypatch, capsys):
    from pamsim.cli import main

    monkeypatch.setattr(run, "free_disk_bytes", lambda folder: 1_000_000)
    code = main(["sweep", str(SCENARIOS / "acra2012_fig4_uncertainty.toml"), "-o", str(tmp_path / "out"),
                 "--no-progress"])
    err = capsys.readouterr().err.strip().splitlines()
    # 10,000 samples of 4 parameters under load_dependent friction: a row takes at most
    # 5 (sample number) + 14 (friction) + 2 commas + 7 numbers x 16 + 8 = 141 bytes, 1.41 MB in all;
    # 1 MB holds 1e6 / 141 = 7,092 rows.
    assert code == 2 and len(err) == 1, err
    assert "uncertainty.samples = 10000: the samples table needs up to 1.41 MB of disk" in err[0], err
    assert "1 MB is free; take at most 7,092 samples" in err[0], err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("workers,chunks", [(1, 8), (2, 8), (5, 20), (16, 64), (40, 64), (None, 64)])
def test_the_chunks_sent_ahead_follow_the_workers(workers, chunks):
    class Pool(Executor):
        _max_workers = workers

    assert run.chunks_in_flight(Pool()) == chunks


def test_the_study_goes_to_the_workers_that_draw_its_figures_without_its_table(spec, tmp_path):
    """The figures are drawn on the executor's workers, which get the study pickled: its open table's file
    object cannot be (the figures were then drawn in the sweep's process instead, silently)."""
    import pickle

    with pamsim.sweep(spec, output_dir=tmp_path) as result:
        copy = pickle.loads(pickle.dumps(result.uncertainty))
        assert copy.table is None and result.uncertainty.table is not None
        assert copy.quantile_rows() == result.uncertainty.quantile_rows()
