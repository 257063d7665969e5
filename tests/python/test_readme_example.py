# SPDX-License-Identifier: MIT
"""The README's Python example, run as it is written there (this copy must stay equal to the README's)."""
import contextlib
import io
import os

from conftest import SOURCE_DIR

EXAMPLE = """\
import numpy as np
import hbvh

chair = hbvh.load("data/models/chair.xml")              # any file the CLI reads; a stored hierarchy comes back built
balls = hbvh.spheres([[0.0, 0.45, 0.0], [2.0, 0.0, 0.0]], [0.1, 0.2])
tree = hbvh.build([chair, balls], algorithm="auto")     # a list of Primitives is joined in order
print(tree.cost, tree.stats()["height"], len(tree.nodes))  # Eq. 2; stats() has the keys of `hbvh stats --json`
pose = np.eye(4); pose[:3, 3] = (0.3, 0.0, 0.0)         # 4x4 matrices, or (R, t) tuples
pairs = hbvh.collide(tree, np.eye(4), tree, pose)       # (N, 2) int64: primitive of a, primitive of b
many = hbvh.collide_many(tree, tree, np.repeat(pose[None], 100, axis=0))  # GIL released, one array per pose
assert all(np.array_equal(p, pairs) for p in many)
tree.save("chair.hbvh")                                 # survey XML, or the binary format for a .hbvh name
try:
    hbvh.spheres([[0, 0, 0]], [-1.0])
except hbvh.Error as error:                             # a ValueError carrying the CLI's message
    print(error)                                        # primitive 0 (sphere): radius -1 is negative
"""


def test_readme_example_is_this_one():
    assert "```python\n" + EXAMPLE + "```" in (SOURCE_DIR / "README.md").read_text()


def test_readme_example_runs(tmp_path, monkeypatch):
    (tmp_path / "data").symlink_to(SOURCE_DIR / "data")
    monkeypatch.chdir(tmp_path)
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        exec(compile(EXAMPLE, "README.md", "exec"), {})
    lines = printed.getvalue().splitlines()
    assert lines[-1] == "primitive 0 (sphere): radius -1 is negative"
    assert len(lines[0].split()) == 3
    assert os.path.getsize(tmp_path / "chair.hbvh") > 0
