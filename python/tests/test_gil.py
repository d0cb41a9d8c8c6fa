"""The batch calls release the GIL: Python threads run while Rust computes."""

import os
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np

import chain
from conftest import ROOT

AC = ROOT / "examples/machines/ac_trunnion.yaml"


def test_python_runs_during_a_batch():
    """While one thread is inside `sensitivity`, the main thread keeps executing Python
    (with the GIL held by the call it could not run at all)."""
    m = chain.Machine.load(AC)
    q = np.random.default_rng(0).uniform(-1, 1, size=(200_000, 5))
    done = threading.Event()
    ticks = 0

    def batch():
        for _ in range(3):
            m.sensitivity(q)
        done.set()

    t = threading.Thread(target=batch)
    t.start()
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    t.join()
    assert ticks >= 20, f"the main thread ran only {ticks} times during the batches"


def test_two_batches_concurrently_beat_twice_one():
    """On a one-thread pool (RAYON_NUM_THREADS=1, in a subprocess), two batches in two Python
    threads take less than 1.9x one batch: they ran in parallel, so the GIL was released."""
    script = textwrap.dedent(f"""
        import threading, time, numpy as np, chain
        m = chain.Machine.load({str(AC)!r})
        q = np.random.default_rng(0).uniform(-1, 1, size=(300_000, 5))
        m.sensitivity(q[:1000])
        def one():
            m.sensitivity(q)
        best = 1e9
        for _ in range(3):
            t = time.perf_counter(); one(); one_t = time.perf_counter() - t
            ts = [threading.Thread(target=one) for _ in range(2)]
            t = time.perf_counter()
            [x.start() for x in ts]; [x.join() for x in ts]
            best = min(best, (time.perf_counter() - t) / one_t)
        print(best)
    """)
    env = {**os.environ, "RAYON_NUM_THREADS": "1"}
    out = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, check=True)
    ratio = float(out.stdout.strip())
    if os.cpu_count() == 1:
        return
    assert ratio < 1.9, f"two concurrent batches took {ratio:.2f}x one"
