# SPDX-License-Identifier: MIT
"""hbvh.collide and hbvh.collide_many against a numpy brute force, on bundled, generated and round models."""
import numpy as np
import pytest

import brute_force
import hbvh
from conftest import built, model, random_poses


def extent(primitives):
    a = primitives.array
    reach = np.abs(a["center"]).max(axis=0) + np.abs(a["half_extents"]).max() + a["radius"].max()
    return float(np.linalg.norm(a["p1"] - a["p0"], axis=1).max() + reach.max())


# auto on the two bundled models only: its 40-primitive builds took 5 s each under the sanitizers, and which
# builder made a tree is no concern of the binding (the C++ suite checks auto's trees against brute force).
@pytest.mark.parametrize("name,algorithm", [(name, algorithm) for name in ["chair.xml", "tie_interceptor.xml", "generated", "round"]
                                            for algorithm in ["auto", "fast", "split", "two-level"]
                                            if algorithm != "auto" or name.endswith(".xml")])
def test_pairs_equal_brute_force(name, algorithm):
    primitives = model(name)
    assert isinstance(primitives, hbvh.Primitives)
    tree = built(name, algorithm)
    assert len(tree.primitives) == len(primitives)
    rng = np.random.default_rng(len(name) * 31 + len(algorithm))
    reach = extent(primitives)
    poses_a = random_poses(rng, 8, 0.1 * reach)
    poses_b = random_poses(rng, 8, 0.5 * reach)
    found = missed = 0
    for pose_a, pose_b in zip(poses_a, poses_b):
        pairs = hbvh.collide(tree, pose_a, tree, pose_b)
        assert pairs.dtype == np.int64 and pairs.ndim == 2 and pairs.shape[1] == 2
        got = {tuple(p) for p in pairs}
        assert len(got) == len(pairs), "a pair reported twice"
        must, may = brute_force.expected_pairs(primitives.array, pose_a, primitives.array, pose_b, 1e-9 * reach)
        assert must <= got, f"missed {sorted(must - got)[:5]}"
        assert got <= must | may, f"reported separated pairs {sorted(got - must - may)[:5]}"
        found += len(must)
        missed += len(primitives) ** 2 - len(must) - len(may)
        # first=True: one of the pairs, or none when there are none.
        first = hbvh.collide(tree, pose_a, tree, pose_b, first=True)
        assert len(first) == min(1, len(pairs)) and all(tuple(p) in got for p in first)
        # (R, t) tuples mean the same pose as the 4x4 matrix.
        as_tuples = hbvh.collide(tree, (pose_a[:3, :3], pose_a[:3, 3]), tree, (pose_b[:3, :3], pose_b[:3, 3]))
        assert np.array_equal(as_tuples, pairs)
    # The poses must give both answers, or the comparison proves little.
    assert found > 0 and missed > 0


@pytest.mark.parametrize("name", ["chair.xml", "generated"])
def test_two_different_models(name):
    a = built(name, "auto" if name.endswith(".xml") else "split")
    b_primitives = model("round")
    b = built("round", "merge")
    rng = np.random.default_rng(3)
    for pose_b in random_poses(rng, 10, 2.0):
        pairs = {tuple(p) for p in hbvh.collide(a, None, b, pose_b)}
        must, may = brute_force.expected_pairs(a.primitives.array, np.eye(4), b_primitives.array, pose_b, 1e-8)
        assert must <= pairs <= must | may


@pytest.mark.parametrize("name", ["tie_interceptor.xml", "generated"])
def test_collide_many_equals_repeated_collide(name):
    primitives = model(name)
    a = built(name, "split")
    b = built(name, "insertion")
    poses = random_poses(np.random.default_rng(5), 50, extent(primitives))
    many = hbvh.collide_many(a, b, poses)
    assert isinstance(many, list) and len(many) == len(poses)
    assert sum(len(p) for p in many) > 0
    for pose, pairs in zip(poses, many):
        assert np.array_equal(pairs, hbvh.collide(a, np.eye(4), b, pose))
    first = hbvh.collide_many(a, b, poses, first=True)
    assert [len(f) for f in first] == [min(1, len(p)) for p in many]
    assert hbvh.collide_many(a, b, np.zeros((0, 4, 4))) == []


def test_primitive_arrays_round_trip():
    rng = np.random.default_rng(1)
    centers, half, rotations = rng.normal(size=(4, 3)), rng.uniform(0.1, 1, (4, 3)), np.stack([np.eye(3)] * 4)
    boxes = hbvh.boxes(centers, half, rotations, names=["a", "b", "c", "d"])
    a = boxes.array
    assert list(a["type"]) == [1] * 4 and np.allclose(a["center"], centers) and np.allclose(a["half_extents"], half)
    assert boxes.names == ["a", "b", "c", "d"]
    aabbs = hbvh.boxes(centers, half)
    assert list(aabbs.array["type"]) == [0] * 4 and np.allclose(aabbs.array["center"], centers)
    spheres = hbvh.spheres(centers, 0.5)  # one radius for all
    assert np.allclose(spheres.array["radius"], 0.5) and list(spheres.array["type"]) == [2] * 4
    capsules = hbvh.capsules(centers, centers + 1, np.full(4, 0.25))
    assert np.allclose(capsules.array["p1"], centers + 1) and np.allclose(capsules.array["center"], centers + 0.5)
    joined = boxes + spheres
    assert len(joined) == 8 and len(hbvh.Primitives([boxes, spheres, capsules])) == 12
    tree = hbvh.build([boxes, spheres, capsules])
    nodes = tree.nodes
    assert len(nodes) == len(tree) and nodes[0]["child_count"] >= 2
    leaves = nodes[nodes["child_count"] == 0]
    assert sorted(leaves["primitive"]) == list(range(12))
    # Breadth-first: every inner node's children follow it.
    inner = nodes[nodes["child_count"] > 0]
    assert (inner["first_child"] > 0).all() and (inner["first_child"] + inner["child_count"] <= len(nodes)).all()
