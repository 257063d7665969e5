# SPDX-License-Identifier: MIT
"""Bad input raises hbvh.Error (a ValueError) with the message the CLI prints after 'hbvh: '."""
import numpy as np
import pytest

import hbvh
from conftest import MODELS, built, run_cli


def cli_message(cli, *args):
    result = run_cli(cli, *args)
    assert result.returncode == 1, (result.returncode, result.stderr)
    line = result.stderr.strip().splitlines()[-1]
    assert line.startswith("hbvh: ")
    return line[len("hbvh: "):]


def message_of(call, *args, **kwargs):
    with pytest.raises(hbvh.Error) as caught:
        call(*args, **kwargs)
    assert isinstance(caught.value, ValueError)
    return str(caught.value)


def test_bad_geometry():
    assert message_of(hbvh.spheres, [[0, 0, 0], [1, 1, 1]], [0.5, -1.0]) == "primitive 1 (sphere): radius -1 is negative"
    message = message_of(hbvh.spheres, [[0, np.nan, 0]], [1.0])
    assert message.startswith("primitive 0 (sphere): ") and "finite" in message
    message = message_of(hbvh.capsules, [[0, 0, 0]], [[1, 0, 0]], [-0.1])
    assert message.startswith("primitive 0 (capsule): ") and "negative" in message
    shear = np.array([[[1.0, 0.2, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]])
    assert message_of(hbvh.boxes, [[0, 0, 0]], [[1, 1, 1]], shear).startswith("primitive 0 (obb): ")
    assert "negative" in message_of(hbvh.boxes, [[0, 0, 0]], [[1, -1, 1]], np.eye(3)[None])


def test_bad_shapes_and_types():
    with pytest.raises(ValueError, match=r"centers must have shape \(2, 3\), got \(2, 2\)"):
        hbvh.spheres(np.zeros((2, 2)), [1.0, 1.0])
    with pytest.raises(ValueError, match=r"radii must have shape \(2,\)"):
        hbvh.spheres(np.zeros((2, 3)), [1.0, 1.0, 1.0])
    with pytest.raises(TypeError):
        hbvh.build([hbvh.spheres(np.zeros((1, 3)), 1.0), "not primitives"])


def test_bad_pose():
    tree = hbvh.build(hbvh.spheres(np.zeros((2, 3)) + [[0, 0, 0], [3, 0, 0]], [1.0, 1.0]))
    scaled = np.diag([2.0, 1.0, 1.0, 1.0])
    message = message_of(hbvh.collide, tree, np.eye(4), tree, scaled)
    assert message.startswith("pose_b: pose: ") and "rotation" in message
    translation_nan = np.eye(4)
    translation_nan[0, 3] = np.nan
    assert message_of(hbvh.collide, tree, translation_nan, tree, None) == "pose_a: pose: translation is not finite"
    poses = np.stack([np.eye(4), scaled])
    assert message_of(hbvh.collide_many, tree, tree, poses) == "poses[1]: " + message
    with pytest.raises(ValueError, match="last row"):
        hbvh.collide(tree, np.ones((4, 4)), tree, None)


def test_bad_build_arguments_match_the_cli(cli):
    chair = hbvh.load(str(MODELS / "chair.xml"))
    assert message_of(hbvh.build, chair, algorithm="nope") == cli_message(cli, "stats", MODELS / "chair.xml", "-a", "nope")
    assert message_of(hbvh.build, chair, types="aabb,cone") == cli_message(
        cli, "stats", MODELS / "chair.xml", "--types", "aabb,cone")
    with pytest.raises(ValueError, match="time_limit"):
        hbvh.build(chair, time_limit=-1.0)


def test_a_substituted_builder_warns_as_the_cli_does(cli):
    tie = hbvh.load(str(MODELS / "tie_interceptor.xml"))
    with pytest.warns(UserWarning) as caught:
        tree = hbvh.build(tie, algorithm="optimal")
    result = run_cli(cli, "build", MODELS / "tie_interceptor.xml", "-a", "optimal", "-o", "-")
    assert result.returncode == 0, result.stderr
    assert [str(w.message) for w in caught] == [result.stderr.strip()[len("hbvh: warning: "):]]
    assert "27 primitives exceed its limit of 18" in str(caught[0].message)
    assert tree.cost > 0


@pytest.mark.parametrize("content", [
    "<hierarchy><volume type='sphere' pos='0 0 0' radius='-1'/></hierarchy>",  # negative radius
    "<hierarchy><volume type='sphere' pos='0 nan 0' radius='1'/></hierarchy>",  # NaN
    "<hierarchy><volume type='obb' pos='0 0 0' width='1' depth='1' height='1' orientation='2 0 0 0 1 0 0 0 1'/></hierarchy>",
    "<hierarchy><volume type='sphere'",  # malformed XML
    "<hierarchy><volume type='cone' pos='0 0 0'/></hierarchy>",  # unknown type
])
def test_malformed_files_match_the_cli(cli, tmp_path, content):
    path = tmp_path / "bad.xml"
    path.write_text(content)
    assert message_of(hbvh.load, str(path)) == cli_message(cli, "stats", path)


def test_damaged_binary_and_missing_files_match_the_cli(cli, tmp_path):
    path = tmp_path / "chair.hbvh"
    built("chair.xml").save(str(path))
    data = path.read_bytes()
    path.write_bytes(data[:-20])  # truncated
    assert message_of(hbvh.load, str(path)) == cli_message(cli, "stats", path)
    path.write_bytes(data[:40] + bytes([data[40] ^ 1]) + data[41:])  # checksum mismatch
    assert message_of(hbvh.load, str(path)) == cli_message(cli, "stats", path)
    missing = tmp_path / "missing.xml"
    assert message_of(hbvh.load, str(missing)) == cli_message(cli, "stats", missing)
    assert message_of(hbvh.load, str(tmp_path)) == cli_message(cli, "stats", tmp_path)
    unknown = tmp_path / "model.abc"
    unknown.write_text("x")
    assert message_of(hbvh.load, str(unknown)) == cli_message(cli, "stats", unknown)
