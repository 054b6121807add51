"""Fixtures shared by the Python tests: the `remesh` command line to compare the module with."""

import json
import os
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def remesh_bin():
    given = os.environ.get("REMESH_BIN")
    if given:
        return Path(given)
    out = subprocess.run(
        ["cargo", "build", "--release", "--workspace", "--bin", "remesh",
         "--message-format=json-render-diagnostics"],
        cwd=REPO,
        check=True,
        stdout=subprocess.PIPE,
        text=True,
    ).stdout
    for line in out.splitlines():
        message = json.loads(line)
        if message.get("reason") == "compiler-artifact" and message.get("executable"):
            if message["target"]["name"] == "remesh":
                return Path(message["executable"])
    pytest.fail("cargo build did not report the remesh executable")


@pytest.fixture
def gil_released():
    """A check that `work()` releases the GIL: it runs in another thread while this one reads
    the clock every millisecond; with the GIL released no gap between two readings comes near
    the call's length (a held GIL leaves one gap as long as the call). The call must be long
    against the polling for the gaps to tell."""

    def check(work):
        done = threading.Event()
        times = []

        def run():
            start = time.perf_counter()
            work()
            times.append(time.perf_counter() - start)
            done.set()

        stamps = [time.perf_counter()]
        worker = threading.Thread(target=run)
        worker.start()
        while not done.is_set():
            stamps.append(time.perf_counter())
            time.sleep(0.001)
        worker.join()
        stamps.append(time.perf_counter())
        (duration,) = times
        gaps = np.diff(stamps)
        assert duration > 0.05, duration
        assert gaps.max() < 0.5 * duration, (gaps.max(), duration)

    return check
