"""Fixtures shared by the Python tests: the `remesh` command line to compare the module with."""

import json
import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def remesh_bin():
    given = os.environ.get("REMESH_BIN")
    if given:
        return Path(given)
    out = subprocess.run(
        ["cargo", "build", "--release", "--bin", "remesh", "--message-format=json-render-diagnostics"],
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
