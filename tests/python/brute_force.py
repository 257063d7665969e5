# SPDX-License-Identifier: MIT
"""Overlapping primitive pairs by brute force, in numpy, independent of hbvh's C++ code.

Every pair of posed primitives gets a signed gap: > 0 separated, < 0 overlapping, and |gap| small only when the two
nearly touch. Closed forms for sphere-sphere, sphere-capsule and point-box distances; the 15-axis separating-axis
test for box-box (its gap is the largest separation along a candidate axis); and, for the segment cases
(capsule-capsule, box-capsule), a golden-section search over the segment parameter of a point distance, which is a
convex function of that parameter (the distance to a convex set along a line), so the search finds its minimum.
"""
import numpy as np

AABB, OBB, SPHERE, CAPSULE = 0, 1, 2, 3


def posed(array, pose):
    """World-space geometry of a Primitives.array under a 4x4 pose: dict of per-primitive arrays."""
    rotation, translation = pose[:3, :3], pose[:3, 3]
    return {
        "type": array["type"].astype(int),
        "center": array["center"] @ rotation.T + translation,
        # An AABB's rotation field is the identity, so boxes of both kinds are centre + axes + half extents.
        "axes": np.einsum("ij,njk->nik", rotation, array["rotation"]),
        "half": array["half_extents"],
        "radius": array["radius"],
        "p0": array["p0"] @ rotation.T + translation,
        "p1": array["p1"] @ rotation.T + translation,
    }


def point_segment_distance(p, a, b):
    ab = b - a
    length2 = np.einsum("ni,ni->n", ab, ab)
    t = np.where(length2 > 0, np.einsum("ni,ni->n", p - a, ab) / np.where(length2 > 0, length2, 1), 0.0)
    t = np.clip(t, 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * ab), axis=1)


def point_box_distance(p, center, axes, half):
    local = np.einsum("nij,ni->nj", axes, p - center)  # axes' columns are the box axes
    outside = np.maximum(np.abs(local) - half, 0.0)
    return np.linalg.norm(outside, axis=1)


def golden_minimum(f, n, iterations=90):
    """min over t in [0, 1] of the convex f(t) (vectorised over n problems)."""
    lo, hi = np.zeros(n), np.ones(n)
    ratio = (np.sqrt(5.0) - 1.0) / 2.0
    for _ in range(iterations):
        t1 = hi - ratio * (hi - lo)
        t2 = lo + ratio * (hi - lo)
        left = f(t1) < f(t2)
        hi = np.where(left, t2, hi)
        lo = np.where(left, lo, t1)
    return np.minimum.reduce([f(lo), f(hi), f(np.zeros(n)), f(np.ones(n))])


def segment_segment_distance(a0, a1, b0, b1):
    return golden_minimum(lambda t: point_segment_distance(a0 + t[:, None] * (a1 - a0), b0, b1), len(a0))


def segment_box_distance(a0, a1, center, axes, half):
    return golden_minimum(lambda t: point_box_distance(a0 + t[:, None] * (a1 - a0), center, axes, half), len(a0))


def box_box_gap(ca, aa, ha, cb, ab, hb):
    """Largest separation over the 15 SAT axes (face normals of both, and their pairwise cross products)."""
    axes = [aa[:, :, i] for i in range(3)] + [ab[:, :, j] for j in range(3)]
    axes += [np.cross(aa[:, :, i], ab[:, :, j]) for i in range(3) for j in range(3)]
    gap = np.full(len(ca), -np.inf)
    d = cb - ca
    for axis in axes:
        norm = np.linalg.norm(axis, axis=1)
        usable = norm > 1e-9  # parallel edges: their cross product is no axis (the face axes cover the case)
        axis = axis / np.where(usable, norm, 1.0)[:, None]
        reach_a = sum(ha[:, i] * np.abs(np.einsum("ni,ni->n", axis, aa[:, :, i])) for i in range(3))
        reach_b = sum(hb[:, j] * np.abs(np.einsum("ni,ni->n", axis, ab[:, :, j])) for j in range(3))
        separation = np.abs(np.einsum("ni,ni->n", axis, d)) - reach_a - reach_b
        gap = np.where(usable, np.maximum(gap, separation), gap)
    return gap


def gaps(a, pose_a, b, pose_b):
    """(len(a), len(b)) signed gaps between the primitives of a under pose_a and those of b under pose_b."""
    wa, wb = posed(a, pose_a), posed(b, pose_b)
    i, j = np.meshgrid(np.arange(len(a)), np.arange(len(b)), indexing="ij")
    i, j = i.ravel(), j.ravel()
    out = np.full(len(i), np.nan)
    kind = lambda w, idx: np.where(w["type"][idx] == AABB, OBB, w["type"][idx])  # noqa: E731
    ka, kb = kind(wa, i), kind(wb, j)
    for x in (OBB, SPHERE, CAPSULE):
        for y in (OBB, SPHERE, CAPSULE):
            sel = (ka == x) & (kb == y)
            if not sel.any():
                continue
            # Order each pair so that the first kind is the "smaller" index; the gap is symmetric.
            first, second = (wa, wb) if x <= y else (wb, wa)
            fi, si = (i[sel], j[sel]) if x <= y else (j[sel], i[sel])
            lo, hi = min(x, y), max(x, y)
            f = {k: v[fi] for k, v in first.items()}
            s = {k: v[si] for k, v in second.items()}
            if (lo, hi) == (OBB, OBB):
                g = box_box_gap(f["center"], f["axes"], f["half"], s["center"], s["axes"], s["half"])
            elif (lo, hi) == (OBB, SPHERE):
                g = point_box_distance(s["center"], f["center"], f["axes"], f["half"]) - s["radius"]
            elif (lo, hi) == (OBB, CAPSULE):
                g = segment_box_distance(s["p0"], s["p1"], f["center"], f["axes"], f["half"]) - s["radius"]
            elif (lo, hi) == (SPHERE, SPHERE):
                g = np.linalg.norm(f["center"] - s["center"], axis=1) - f["radius"] - s["radius"]
            elif (lo, hi) == (SPHERE, CAPSULE):
                g = point_segment_distance(f["center"], s["p0"], s["p1"]) - f["radius"] - s["radius"]
            else:
                g = segment_segment_distance(f["p0"], f["p1"], s["p0"], s["p1"]) - f["radius"] - s["radius"]
            out[sel] = g
    assert not np.isnan(out).any()
    return out.reshape(len(a), len(b))


def expected_pairs(a, pose_a, b, pose_b, tolerance):
    """(pairs that must be reported, pairs that may be): those with gap < -tolerance, and those with |gap| <= it."""
    g = gaps(a, pose_a, b, pose_b)
    must = {tuple(p) for p in np.argwhere(g < -tolerance)}
    may = {tuple(p) for p in np.argwhere(np.abs(g) <= tolerance)}
    return must, may
