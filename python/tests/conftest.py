"""Shared fixtures: the module from the build tree, the command line beside it, small scenes."""
import copy
import json
import os
import subprocess

import pytest

import lattice

SOURCE_DIR = os.environ.get("LATTICE_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
LATTICE_BINARY = os.environ.get("LATTICE_BINARY", "lattice")


def example(name):
    return os.path.join(SOURCE_DIR, "examples", name)


def plate4_dict(width=64, height=64, hairs=None):
    """Plate 4 (a sphere with 1000 hairs), smaller: a few hundred ms to render."""
    with open(example("plate4-fuzzy-sphere-1000.json")) as f:
        d = json.load(f)
    d["camera"]["width"], d["camera"]["height"] = width, height
    if hairs is not None:
        d["objects"] = d["objects"][: 2 + hairs]
    return d


@pytest.fixture(scope="session")
def plate4():
    return plate4_dict()


@pytest.fixture
def cli(tmp_path):
    """Runs `lattice ARGS...`; returns the completed process (check=True)."""

    def run(*args, check=True):
        return subprocess.run([LATTICE_BINARY, *map(str, args)], capture_output=True, text=True, check=check)

    return run


@pytest.fixture
def scene_file(tmp_path):
    """Writes a scene dict to a file; returns its path."""

    def write(d, name="scene.json"):
        path = tmp_path / name
        path.write_text(json.dumps(d))
        return str(path)

    return write


def with_singular_transform(d, index):
    d = copy.deepcopy(d)
    d["objects"][index]["transform"] = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 0]]
    return d
