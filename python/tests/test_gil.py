"""The calls that compute release the GIL: Python threads run while Rust computes.

Both tests are deterministic, whatever the scheduler and the machine's load: they do not time
anything, they arrange that the test thread can only run at a point where the call has let the
GIL go."""

import os
import sys
import threading

import numpy as np

import chain
from conftest import ROOT

AC = ROOT / "examples/machines/ac_trunnion.yaml"


def test_a_batch_releases_the_gil():
    """With a switch interval of 1000 s, CPython hands the GIL to a waiting thread only where the
    holder lets it go (a blocking call, or Rust's `allow_threads`), never by preemption. The test
    thread waits for the worker to start and then needs the GIL to go on: it gets it while the
    worker is inside `sensitivity` only if the call releases it; were the GIL held through the
    call, the test thread could only run again after the worker had finished."""
    m = chain.Machine.load(AC)
    q = np.ascontiguousarray(np.random.default_rng(0).uniform(-1, 1, size=(400_000, 5)))
    m.sensitivity(q[:10])
    state = {"done": False}

    def batch():
        m.sensitivity(q)
        state["done"] = True

    old = sys.getswitchinterval()
    sys.setswitchinterval(1000.0)
    try:
        worker = threading.Thread(target=batch)
        worker.start()  # waits (GIL released) until the worker runs; the worker keeps the GIL
        ran_during_the_call = not state["done"]
        worker.join()
    finally:
        sys.setswitchinterval(old)
    assert state["done"]
    assert ran_during_the_call, "the test thread could not run until `sensitivity` returned"


def test_a_file_read_releases_the_gil(tmp_path):
    """Deterministic, whatever the scheduler: `inverse` on a FIFO blocks in the Rust reader until
    this thread writes the poses. Were the GIL held while it reads, this thread could not run the
    write and the two would wait on each other (the join's timeout only ends such a deadlock)."""
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
