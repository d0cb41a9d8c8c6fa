"""The batch calls release the GIL: Python threads run while Rust computes.

The test looks at when the main thread ran, not at how fast anything ran, so a loaded or
single-core machine cannot fail it: with the GIL held by a call, the main thread could not
run at all between the call's entry and exit, leaving a gap as long as the call."""

import threading
import time

import numpy as np

import chain
from conftest import ROOT

AC = ROOT / "examples/machines/ac_trunnion.yaml"


def _largest_gaps(calls, ticks):
    """For each call interval (t0, t1), the longest stretch of it without a main-thread tick,
    as a fraction of the call's length."""
    ticks = np.asarray(ticks)
    out = []
    for t0, t1 in calls:
        inside = ticks[(ticks > t0) & (ticks < t1)]
        edges = np.concatenate([[t0], inside, [t1]])
        out.append(np.max(np.diff(edges)) / (t1 - t0))
    return out


def _run_beside_ticks(workers):
    """Start the worker threads, tick (record the time) in the main thread until they are
    done, and return the ticks."""
    done = threading.Event()
    ts = [threading.Thread(target=w) for w in workers]
    [t.start() for t in ts]

    def watch():
        [t.join() for t in ts]
        done.set()

    threading.Thread(target=watch).start()
    ticks = []
    while not done.is_set():
        ticks.append(time.perf_counter())
    return ticks


def test_python_runs_during_a_batch():
    """While one thread is inside `sensitivity`, the main thread keeps executing Python: in
    most calls no stretch of half the call passes without it running."""
    m = chain.Machine.load(AC)
    q = np.random.default_rng(0).uniform(-1, 1, size=(200_000, 5))
    m.sensitivity(q[:1000])
    calls = []

    def batch():
        for _ in range(5):
            t0 = time.perf_counter()
            m.sensitivity(q)
            calls.append((t0, time.perf_counter()))

    gaps = _largest_gaps(calls, _run_beside_ticks([batch]))
    assert np.median(gaps) < 0.5, f"the main thread stood still for {gaps} of each call"



def test_a_file_read_releases_the_gil(tmp_path):
    """Deterministic, whatever the scheduler: `inverse` on a FIFO blocks in the Rust reader until
    this thread writes the poses. Were the GIL held while it reads, this thread could not run the
    write and the two would wait on each other (the join's timeout only ends such a deadlock)."""
    import os

    fifo = tmp_path / "poses.csv"
    os.mkfifo(fifo)
    m = chain.Machine.load(ROOT / "examples/paths/cnc5_bevel_stats.yaml")
    result = {}

    def read():
        try:
            result["doc"] = m.inverse(fifo, fix={"mu": 0.0}).to_dict()
        except Exception as e:  # pragma: no cover - reported below
            result["error"] = e

    worker = threading.Thread(target=read)
    worker.start()
    with open(fifo, "w") as f:  # blocks until the reader opens the FIFO
        f.write("px,py,pz,i,j,k\n")
        f.write((ROOT / "examples/paths/cnc5_bevel_pose.csv").read_text().splitlines()[-1].split(",", 1)[1] + "\n")
    worker.join(timeout=120)
    assert not worker.is_alive(), "the reader still holds the GIL"
    assert "error" not in result, result.get("error")
    assert len(result["doc"]["rows"]) >= 1
