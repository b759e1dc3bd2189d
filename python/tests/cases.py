"""Meshes, rays and oracle answers shared by the test files (built once a
session), and the comparisons of the package's answers with the oracle's."""

import functools
import os

import numpy as np
import pytest

import meshcast
import oracle
import shapes

DEFAULT_LAYOUT = "OctTreeCompressed/ClusterBitPackSOA8"
FLOAT3_LAYOUT = "AABBTree/Float3"
LAYOUTS = [DEFAULT_LAYOUT, FLOAT3_LAYOUT, "auto"]
NO_HIT = 0xFFFFFFFF
# How far a lossy layout may move a corner, as a fraction of the mesh's
# diagonal (the recommended layout keeps vertices on a grid of 2^-18 or finer
# of the box: half a step is about 2e-6 of the diagonal; auto picks layouts
# whose stated error is of that order). The float layouts store the float32
# vertices exactly.
LOSSY_DELTA = 4e-6
# The share of rays that must be clean (every candidate hit certain) for a
# comparison to count: the rays are generic, so nearly all are.
MIN_CLEAN = 0.85

MESH_NAMES = ["sphere", "soup", "grid", "bunny"]
RAY_COUNT = {"sphere": 2000, "soup": 2000, "grid": 2000, "bunny": 256}


def layout_delta(layout, vertices):
    return 0.0 if layout.endswith("/Float3") else LOSSY_DELTA * oracle.mesh_diagonal(vertices)


@functools.lru_cache(maxsize=None)
def mesh(name):
    if name == "sphere":
        return shapes.sphere()
    if name == "soup":
        return shapes.soup()
    if name == "grid":
        # Raised and tilted a little: generic rays, not the exact edge cases
        # (test_edges.py has those).
        v, f = shapes.grid(14, 10)
        v = v.astype(np.float64)
        v[:, 2] = 0.05 * v[:, 0] - 0.03 * v[:, 1] + 0.5
        return v.astype(np.float32), f
    if name == "bunny":
        if not os.path.exists(shapes.BUNNY):
            pytest.skip(f"{shapes.BUNNY} not present (set MESHCAST_DATA)")
        if not meshcast.features.get("reader"):
            pytest.skip("meshcast built without the mesh reader")
        v, f = meshcast.read_mesh(shapes.BUNNY)
        return np.asarray(v), np.asarray(f)
    raise KeyError(name)


class Case:
    """A mesh, its rays (with per-ray t ranges) and the oracle's candidates."""

    def __init__(self, name, seed=7):
        self.name = name
        self.vertices, self.triangles = mesh(name)
        n = RAY_COUNT[name]
        self.origins, self.directions = shapes.rays(self.vertices, n, seed=seed)
        rng = np.random.default_rng(seed + 1)
        # Half the rays end early, a quarter start late (secondary rays).
        self.t_max = np.where(rng.random(n) < 0.5, np.inf, rng.uniform(0.3, 4.0, n)).astype(np.float32)
        self.t_min = np.where(rng.random(n) < 0.25, rng.uniform(0.05, 0.3, n), 0.0).astype(np.float32)
        self._cands = {}

    def candidates(self, delta):
        # The bunny's brute force is the slow one: its lossy candidates serve
        # every layout (a larger delta only marks more rays unclear).
        if self.name == "bunny":
            delta = LOSSY_DELTA * oracle.mesh_diagonal(self.vertices)
        if delta not in self._cands:
            self._cands[delta] = oracle.brute_force(self.vertices, self.triangles, self.origins, self.directions, delta)
        return self._cands[delta]

    def truth(self, layout, cull="none", t_min=None, t_max=None):
        c = self.candidates(layout_delta(layout, self.vertices))
        return oracle.classify(c, self.t_min if t_min is None else t_min, self.t_max if t_max is None else t_max, cull)


@functools.lru_cache(maxsize=None)
def case(name):
    return Case(name)


@functools.lru_cache(maxsize=None)
def blob(name, layout):
    v, f = mesh(name)
    return meshcast.build(v, f, layout=layout)


def describe(i, origins, directions):
    o = np.asarray(origins).reshape(-1, 3)[i]
    d = np.asarray(directions).reshape(-1, 3)[i]
    return f"ray {i} (origin {o.tolist()}, direction {d.tolist()})"


def _report(what, bad, lines):
    if bad:
        raise AssertionError(f"{what}: {bad} rays wrong; first:\n  " + "\n  ".join(lines[:8]))


def check_clean_share(truth, what):
    share = truth.clean.mean()
    assert share >= MIN_CLEAN, f"{what}: only {share:.2f} of the rays clean: the comparison says too little"
    hits = np.mean(truth.count[truth.clean] > 0)
    assert hits >= 0.03, f"{what}: only {hits:.3f} of the clean rays hit: the comparison says too little"


def check_closest(truth, t, tri, what, origins, directions, check_triangle=True):
    """closest: a miss where the oracle has none, else t within its tolerance
    and the oracle's triangle where the nearest hit is unique."""
    t = np.asarray(t, dtype=np.float64).ravel()
    tri = np.asarray(tri).ravel().astype(np.int64)
    check_clean_share(truth, what)
    et, etri, tol, unique = truth.nearest()
    lines = []
    for i in np.nonzero(truth.clean)[0]:
        if not np.isfinite(et[i]):
            if tri[i] != NO_HIT or np.isfinite(t[i]):
                lines.append(f"{describe(i, origins, directions)}: expected a miss, got triangle {tri[i]} at t {t[i]}")
            continue
        if tri[i] == NO_HIT:
            lines.append(f"{describe(i, origins, directions)}: expected triangle {etri[i]} at t {et[i]}, got a miss")
        elif not abs(t[i] - et[i]) <= tol[i]:
            lines.append(f"{describe(i, origins, directions)}: t {t[i]}, expected {et[i]} +- {tol[i]:.3g}")
        elif check_triangle and unique[i] and tri[i] != etri[i]:
            lines.append(f"{describe(i, origins, directions)}: triangle {tri[i]}, expected {etri[i]} (t {et[i]})")
    _report(what, len(lines), lines)


def check_any(truth, t, tri, what, origins, directions):
    """any: hit or miss as the oracle says; a hit names one of the ray's hits, at its t."""
    t = np.asarray(t, dtype=np.float64).ravel()
    tri = np.asarray(tri).ravel().astype(np.int64)
    check_clean_share(truth, what)
    lines = []
    for i in np.nonzero(truth.clean)[0]:
        etri, et, tol = truth.row(i)
        if len(etri) == 0:
            if tri[i] != NO_HIT:
                lines.append(f"{describe(i, origins, directions)}: expected a miss, got triangle {tri[i]}")
            continue
        if tri[i] == NO_HIT:
            lines.append(f"{describe(i, origins, directions)}: expected a hit ({len(etri)} on the ray), got a miss")
            continue
        k = np.nonzero(etri == tri[i])[0]
        if len(k) == 0:
            lines.append(f"{describe(i, origins, directions)}: triangle {tri[i]} is not on the ray (hits {etri.tolist()})")
        elif not abs(t[i] - et[k[0]]) <= tol[k[0]]:
            lines.append(f"{describe(i, origins, directions)}: triangle {tri[i]} at t {t[i]}, expected {et[k[0]]}")
    _report(what, len(lines), lines)


def check_all(truth, found, offsets, t, tri, max_hits, what, origins, directions):
    """all: found = the oracle's count; min(found, max_hits) kept, nearest
    first, their t the oracle's nearest ones; the kept triangles the oracle's
    nearest (where the cut after the last kept one is clear)."""
    found = np.asarray(found).astype(np.int64)
    offsets = np.asarray(offsets).astype(np.int64)
    t = np.asarray(t, dtype=np.float64)
    tri = np.asarray(tri).astype(np.int64)
    n = len(truth.clean)
    assert found.shape == (n,) and offsets.shape == (n + 1,), (found.shape, offsets.shape)
    assert offsets[0] == 0 and offsets[-1] == len(t) == len(tri)
    kept = np.diff(offsets)
    # Every ray, clean or not: at most max_hits kept, no more than found.
    assert np.all(kept == np.minimum(found, max_hits)), f"{what}: kept != min(found, max_hits)"
    check_clean_share(truth, what)
    lines = []
    for i in np.nonzero(truth.clean)[0]:
        s = slice(offsets[i], offsets[i + 1])
        gt, gtri = t[s], tri[s]
        etri, et, tol = truth.row(i)
        if found[i] != len(etri):
            lines.append(f"{describe(i, origins, directions)}: found {found[i]}, expected {len(etri)}")
            continue
        if np.any(np.diff(gt) < 0):
            lines.append(f"{describe(i, origins, directions)}: kept hits not nearest first: {gt.tolist()}")
            continue
        k = len(gt)
        if not np.all(np.abs(gt - et[:k]) <= tol[:k]):
            lines.append(f"{describe(i, origins, directions)}: t {gt.tolist()}, expected {et[:k].tolist()}")
            continue
        if len(set(gtri.tolist())) != k:
            lines.append(f"{describe(i, origins, directions)}: a triangle kept twice: {gtri.tolist()}")
            continue
        cut_clear = k == len(et) or et[k] - et[k - 1] > tol[k] + tol[k - 1]
        if cut_clear and set(gtri.tolist()) != set(etri[:k].tolist()):
            lines.append(f"{describe(i, origins, directions)}: triangles {sorted(gtri.tolist())}, expected {sorted(etri[:k].tolist())}")
    _report(what, len(lines), lines)


def rays6(origins, directions, dtype=np.float32):
    return np.concatenate([np.asarray(origins, dtype), np.asarray(directions, dtype)], axis=-1)


def rotation(seed):
    """A random rotation (a unit quaternion from four normal draws), float32."""
    q = np.random.default_rng(seed).normal(size=4)
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]], dtype=np.float32)


class World:
    """Instances of meshes placed in world space, as one mesh for the oracle.
    parts: (vertices, triangles, rotation_scale or None, translation, flip_facing, delta in local units).
    Faces are decided in each mesh's own frame, so a mirroring transform
    (det < 0) keeps a face's facing: in world space its sign turns."""

    def __init__(self, parts):
        vs, fs, sign, delta, owner, local = [], [], [], [], [], []
        self.base = []
        count = 0
        for k, (v, f, m, tr, flip, dl) in enumerate(parts):
            m = np.eye(3) if m is None else np.asarray(m, dtype=np.float32).astype(np.float64)
            w = np.asarray(v, dtype=np.float64) @ m.T + np.asarray(tr, dtype=np.float64)
            f = np.asarray(f, dtype=np.int64)
            vs.append(w)
            fs.append(f + sum(len(x) for x in vs[:-1]))
            s = np.sign(np.linalg.det(m)) * (-1 if flip else 1)
            sign.append(np.full(len(f), s))
            delta.append(np.full(len(f), dl * np.linalg.norm(m, 2)))
            owner.append(np.full(len(f), k))
            local.append(np.arange(len(f)))
            self.base.append(count)
            count += len(f)
        self.vertices = np.concatenate(vs)
        self.triangles = np.concatenate(fs)
        self.sign = np.concatenate(sign)
        self.delta = np.concatenate(delta)
        self.owner = np.concatenate(owner)
        self.local = np.concatenate(local)
        self.base = np.array(self.base, dtype=np.int64)

    def candidates(self, origins, directions):
        return oracle.brute_force(self.vertices, self.triangles, origins, directions, self.delta, self.sign)

    def global_ids(self, instance, triangle):
        """The package's (instance, triangle) as world triangle numbers (NO_HIT kept)."""
        instance = np.asarray(instance).astype(np.int64).ravel()
        triangle = np.asarray(triangle).astype(np.int64).ravel()
        miss = triangle == NO_HIT
        out = np.where(miss, NO_HIT, self.base[np.where(miss, 0, instance)] + triangle)
        assert np.all(instance[miss] == NO_HIT), "a miss names an instance"
        return out
