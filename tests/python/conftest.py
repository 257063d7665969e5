# SPDX-License-Identifier: MIT
"""Shared fixtures: where the sources and the CLI are, the models, seeded poses, built trees."""
import functools
import os
import pathlib
import shutil
import subprocess

import numpy as np
import pytest

import hbvh

SOURCE_DIR = pathlib.Path(os.environ.get("HBVH_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
MODELS = SOURCE_DIR / "data" / "models"


def random_rotations(rng, count):
    """count uniformly random proper rotations (QR of Gaussian matrices, signs fixed)."""
    q, r = np.linalg.qr(rng.normal(size=(count, 3, 3)))
    q = q * np.sign(np.diagonal(r, axis1=1, axis2=2))[:, None, :]
    q[np.linalg.det(q) < 0, :, 0] *= -1.0
    return q


def random_poses(rng, count, reach):
    poses = np.repeat(np.eye(4)[None], count, axis=0)
    poses[:, :3, :3] = random_rotations(rng, count)
    poses[:, :3, 3] = rng.uniform(-reach, reach, size=(count, 3))
    return poses


def generated_set(seed=7):
    """A mixed set (OBBs, AABBs, spheres, capsules) from numpy, joined from a list of Primitives."""
    rng = np.random.default_rng(seed)
    side = 6.0
    centers = lambda n: rng.uniform(-side / 2, side / 2, size=(n, 3))  # noqa: E731
    sizes = lambda *shape: rng.uniform(0.2, 1.0, size=shape)  # noqa: E731
    obbs = hbvh.boxes(centers(12), sizes(12, 3), random_rotations(rng, 12))
    aabbs = hbvh.boxes(centers(8), sizes(8, 3))
    spheres = hbvh.spheres(centers(10), sizes(10))
    p0 = centers(10)
    capsules = hbvh.capsules(p0, p0 + rng.normal(size=(10, 3)) * 0.8, sizes(10) * 0.5)
    return [obbs, aabbs, spheres, capsules]


def round_set(seed=11):
    """Spheres and capsules only: every brute-force test for it is a closed form or a 1-D convex search."""
    rng = np.random.default_rng(seed)
    spheres = hbvh.spheres(rng.uniform(-2, 2, size=(20, 3)), rng.uniform(0.1, 0.6, size=20))
    p0 = rng.uniform(-2, 2, size=(20, 3))
    capsules = hbvh.capsules(p0, p0 + rng.normal(size=(20, 3)) * 0.7, rng.uniform(0.05, 0.4, size=20))
    return spheres + capsules


def model(name):
    """A bundled model by file name, or "generated" / "round"."""
    if name == "generated":
        return hbvh.Primitives(generated_set())
    if name == "round":
        return round_set()
    return hbvh.load(str(MODELS / name))


def built(name, algorithm="auto", types=None):
    """hbvh.build(model(name), ...), built once per session: several tests query the same tree (read only), and
    the builds dominate the suite's time under the sanitizers (auto over 80 generated primitives took 10-13 s and
    over 40 about 5 s, which is why the generated and round sets hold 40 each and auto builds only the bundled
    models). Builds are deterministic, so a rebuild would be the same tree."""
    return _built(name, algorithm, types)


@functools.lru_cache(maxsize=None)
def _built(name, algorithm, types):  # every argument positional, so that equal requests share one cache entry
    options = {"algorithm": algorithm} if types is None else {"algorithm": algorithm, "types": types}
    return hbvh.build(model(name), **options)


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("HBVH_CLI") or shutil.which("hbvh")
    if not path:
        pytest.skip("HBVH_CLI is not set (ctest sets it to the built CLI)")
    return path


def run_cli(cli_path, *args):
    return subprocess.run([cli_path, *map(str, args)], capture_output=True, text=True, timeout=120)
