"""Shared fixtures of the vdbhair Python tests (run by CTest: `ctest -R python`).

The module is found through PYTHONPATH (the build's python/ folder, set by CTest). Real data is
read from $VDBHAIR_SHARED_DATA, else ../shared/data next to the checkout, as the C++ tests do;
tests marked `data` skip, saying so, when it is absent.
"""
import os
import pathlib

import numpy as np
import pytest

import vdbhair

SOURCE_DIR = pathlib.Path(__file__).resolve().parents[2]


def pytest_configure(config):
    config.addinivalue_line("markers", "data: reads the shared real hairstyles (../shared/data)")


@pytest.fixture(scope="session")
def shared_data():
    """The shared real-data folder, or a skip saying it is absent."""
    env = os.environ.get("VDBHAIR_SHARED_DATA")
    path = pathlib.Path(env) if env else (SOURCE_DIR.parent / "shared" / "data")
    if not path.is_dir():
        pytest.skip(f"the shared real data ({path}) is not available")
    return path


def straight_bundle(count=5, vertices=9, length=4.0, spacing=0.25, direction=(1.0, 0.0, 0.0)):
    """`count` x `count` parallel straight strands along `direction`, roots on a grid."""
    d = np.asarray(direction, dtype=np.float64)
    d /= np.linalg.norm(d)
    # Two axes perpendicular to d for the roots.
    a = np.cross(d, [0.0, 0.0, 1.0] if abs(d[2]) < 0.9 else [1.0, 0.0, 0.0])
    a /= np.linalg.norm(a)
    b = np.cross(d, a)
    t = np.linspace(0.0, length, vertices)
    strands = []
    for i in range(count):
        for j in range(count):
            root = (i - count // 2) * spacing * a + (j - count // 2) * spacing * b
            strands.append(root + t[:, None] * d)
    positions = np.concatenate(strands).astype(np.float32)
    offsets = np.arange(0, len(strands) + 1, dtype=np.int64) * vertices
    return vdbhair.Strands(positions, offsets)


def wavy_hairstyle(count=300, vertices=24, seed=7):
    """A deterministic hairstyle of wavy strands of different directions and lengths."""
    rng = np.random.default_rng(seed)
    strands = []
    for _ in range(count):
        root = rng.uniform(-1.0, 1.0, 3)
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        n = np.cross(d, [0.3, 1.0, 0.2])
        n /= np.linalg.norm(n)
        s = np.linspace(0.0, rng.uniform(1.0, 3.0), vertices)
        strands.append(root + s[:, None] * d + 0.1 * np.sin(4.0 * s)[:, None] * n)
    positions = np.concatenate(strands).astype(np.float32)
    offsets = np.arange(0, count + 1, dtype=np.int64) * vertices
    return vdbhair.Strands(positions, offsets)


@pytest.fixture
def bundle():
    return straight_bundle()


@pytest.fixture(scope="session")
def wavy():
    return wavy_hairstyle()
