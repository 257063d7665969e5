# SPDX-License-Identifier: MIT
"""Hierarchy.stats / cost / save / load against `hbvh stats --json` of the CLI on the same saved file."""
import json

import numpy as np
import pytest

import hbvh
from conftest import MODELS, built, run_cli

STATS_KEYS = ["cost", "calibrated_cost", "height", "nodes", "inner_nodes", "leaves", "branching", "tightness", "leaf_depth", "overlap",
              "types", "violations"]


def assert_same_stats(ours, theirs):
    assert list(ours) == list(theirs)
    for key, value in theirs.items():
        if isinstance(value, dict):
            assert ours[key] == pytest.approx(value, rel=1e-12), key
        elif isinstance(value, float):
            assert ours[key] == pytest.approx(value, rel=1e-12), key
        else:
            assert ours[key] == value, key


@pytest.mark.parametrize("source", ["chair.xml", "tie_interceptor.xml", "generated"])
@pytest.mark.parametrize("extension", [".xml", ".hbvh"])
def test_cost_and_stats_equal_the_cli(cli, tmp_path, source, extension):
    # An exact builder on the chair, split on the others: bnb-exact takes tens of seconds on the 40 generated
    # primitives with capsules excluded under the sanitizers, and 8 s on the tie interceptor's 27, for statistics
    # that any tree shows. The .xml and .hbvh cases save the same tree.
    algorithm = "bnb-exact" if source == "chair.xml" else "split"
    tree = built(source, algorithm, "aabb,obb,sphere")
    stats = tree.stats()
    assert list(stats) == STATS_KEYS
    assert stats["cost"] == tree.cost and stats["nodes"] == len(tree) == len(tree.nodes)
    assert stats["leaves"] == len(tree.primitives) and stats["violations"] == []
    assert stats["types"]["capsule"] == int(np.sum(tree.primitives.array["type"] == 3)), "capsules only as leaves"
    path = tmp_path / ("tree" + extension)
    tree.save(str(path))
    result = run_cli(cli, "stats", "--json", path)
    assert result.returncode == 0, result.stderr
    theirs = json.loads(result.stdout)
    assert tree.cost == pytest.approx(theirs["cost"], rel=1e-12)
    assert_same_stats(stats, theirs)
    loaded = hbvh.load(str(path))
    assert isinstance(loaded, hbvh.Hierarchy)
    assert_same_stats(loaded.stats(), theirs)


def test_load_keeps_a_stored_hierarchy_and_reads_primitive_sets(tmp_path):
    assert isinstance(hbvh.load(str(MODELS / "chair.xml")), hbvh.Primitives)
    # Any built tree shows it: auto's over the chair, shared with test_collide.py (building optimal's tree here
    # took 10 s under the sanitizers).
    tree = built("chair.xml")
    tree.save(str(tmp_path / "chair.hbvh"))
    back = hbvh.load(str(tmp_path / "chair.hbvh"))
    assert isinstance(back, hbvh.Hierarchy) and back.cost == tree.cost
    assert np.array_equal(back.nodes, tree.nodes)  # the binary format keeps every bit and the input order


def test_stats_lists_violations_of_a_refitted_load(tmp_path):
    # A hand-written hierarchy whose root misses part of a child: refused by load, repaired with refit=True.
    path = tmp_path / "bad.xml"
    path.write_text('<hierarchy>\n<volume type="sphere" pos="0 0 0" radius="1">\n'
                    '  <volume type="sphere" name="a" pos="0 0 0" radius="0.5" />\n'
                    '  <volume type="sphere" name="b" pos="1 0 0" radius="0.5" />\n'
                    '</volume>\n</hierarchy>\n')
    with pytest.raises(hbvh.Error, match=r"bad.xml:2: volume \(sphere\) does not enclose primitive 1 \('b'\)"):
        hbvh.load(str(path))
    repaired = hbvh.load(str(path), refit=True)
    assert repaired.stats()["violations"] == [] and len(repaired) == 3


def test_the_calibrated_objective_builds_what_the_cli_builds(cli, tmp_path):
    # The same builder under --objective calibrated gives another tree on the tie interceptor (split's cuts
    # and fits follow the measure), cheaper under that measure, and the module's objective= is the CLI's flag.
    primitives = hbvh.load(str(MODELS / "tie_interceptor.xml"))
    by_volume = hbvh.build(primitives, "split")
    by_minkowski = hbvh.build(primitives, "split", objective="calibrated")
    assert by_minkowski.stats()["calibrated_cost"] < by_volume.stats()["calibrated_cost"]
    assert by_minkowski.cost > by_volume.cost
    path = tmp_path / "cli.xml"
    result = run_cli(cli, "build", MODELS / "tie_interceptor.xml", "-a", "split", "--objective", "calibrated", "-o", path)
    assert result.returncode == 0, result.stderr
    assert_same_stats(by_minkowski.stats(), hbvh.load(str(path)).stats())
    with pytest.raises(ValueError, match="objective"):
        hbvh.build(primitives, "split", objective="fastest")


def test_type_weights_are_the_clis_in_every_form(cli, tmp_path):
    # type_weights= takes what --type-weight takes: a list, the file `hbvh calibrate -o` writes (its table of
    # pairs as comments), or a dict; each gives the CLI's tree, and a bad entry is named with its file and line.
    primitives = hbvh.load(str(MODELS / "tie_interceptor.xml"))
    weights = tmp_path / "weights.txt"
    weights.write_text("# ns per inner-node test\n#          aabb   obb\n# aabb    19.5  24.0\n"
                       "aabb=1.000,obb=1.275,sphere=0.384,capsule=1.258\n")
    from_file = hbvh.build(primitives, "split", objective="calibrated", type_weights="@" + str(weights))
    from_list = hbvh.build(primitives, "split", objective="calibrated",
                           type_weights="aabb=1,obb=1.275,sphere=0.384,capsule=1.258")
    from_dict = hbvh.build(primitives, "split", objective="calibrated",
                           type_weights={"obb": 1.275, "sphere": 0.384, "capsule": 1.258})
    unweighted = hbvh.build(primitives, "split", objective="calibrated")
    assert_same_stats(from_file.stats(), from_list.stats())
    assert_same_stats(from_file.stats(), from_dict.stats())
    assert from_file.stats()["types"] != unweighted.stats()["types"]  # the cheap spheres change the kinds chosen
    path = tmp_path / "cli.xml"
    result = run_cli(cli, "build", MODELS / "tie_interceptor.xml", "-a", "split", "--objective", "calibrated",
                     "--type-weight", "@" + str(weights), "-o", path)
    assert result.returncode == 0, result.stderr
    assert_same_stats(from_file.stats(), hbvh.load(str(path)).stats())
    bad = tmp_path / "bad.txt"
    bad.write_text("aabb=1\nobb=heavy\n")
    with pytest.raises(hbvh.Error, match=r"bad.txt:2: type weight 'obb=heavy': a weight must be a number from 1e-6 to 1e6"):
        hbvh.build(primitives, "split", type_weights="@" + str(bad))
    with pytest.raises(hbvh.Error, match="unknown bounding-volume type"):
        hbvh.build(primitives, "split", type_weights={"cone": 2.0})


def test_paths_may_be_pathlib_paths(tmp_path):
    chair = hbvh.load(MODELS / "chair.xml")          # a pathlib.Path, as open() takes
    tree = hbvh.build(chair, algorithm="split")
    tree.save(tmp_path / "chair.hbvh")
    assert hbvh.load(tmp_path / "chair.hbvh").cost == tree.cost


def test_names_with_control_characters_are_written_as_xml_that_expat_reads(tmp_path):
    # "&#01;" is no XML 1.0 (libxml2 and expat refuse it; hbvh's own reader did not): control characters other
    # than tab, line feed and carriage return are now written as U+FFFD, as bytes that are no UTF-8 are.
    import xml.etree.ElementTree as ElementTree
    spheres = hbvh.spheres([[0, 0, 0], [3, 0, 0], [6, 0, 0]], [1.0, 1.0, 1.0],
                           names=["bell\x07", "tab\there", "line\nbreak"])
    path = tmp_path / "names.xml"
    hbvh.build(spheres, algorithm="two-level").save(path)
    written = {element.get("name") for element in ElementTree.parse(path).iter("volume")} - {None}
    assert written == {"bell\ufffd", "tab\there", "line\nbreak"}
    assert set(hbvh.load(path).primitives.names) == written
