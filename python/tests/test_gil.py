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

