"""An independent double-precision brute force for meshcast's tests.

It shares nothing with the library: every ray is tested against every
triangle (after a bounding-sphere prefilter) with the Moeller-Trumbore test
carried out in float64 on the caller's vertices.

The library may move vertices (the recommended layout keeps them on a grid of
the mesh's box) and rounds to float32, so the oracle does not claim an exact
answer for every ray. For each ray and triangle it keeps the hit distance t,
the facing and a signed margin: the in-plane distance from the plane hit point
to the nearest edge line (positive inside). A corner moved by at most `delta`
moves that margin by at most delta * (1 + 1/|cos|) and the hit point along the
ray by delta / |cos| (cos: the angle between the ray and the normal), so a
hit whose margin, t-range boundaries and facing are all clear of those bounds
(times a safety factor) is certain, and a ray whose every candidate is certain
is "clean": its set of hits is known exactly. Tests compare clean rays only and
check that most rays are clean, so a comparison is never vacuous.
"""

from dataclasses import dataclass

import numpy as np

SAFETY = 2.5
# float32 rounding of coordinates, rays and the walkers' arithmetic, relative
# to the largest coordinate involved (mesh or ray origin).
FLOAT_EPS = 2e-6


def triangle_geometry(vertices, triangles):
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(triangles, dtype=np.int64)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    return a, b, c


def normals(vertices, triangles):
    """Unit geometric normals (b-a)x(c-a) normalized."""
    a, b, c = triangle_geometry(vertices, triangles)
    n = np.cross(b - a, c - a)
    return n / np.linalg.norm(n, axis=1, keepdims=True)


@dataclass
class Candidates:
    """Every (ray, triangle) pair that is or may be a hit, as flat arrays."""

    n_rays: int
    ray: np.ndarray  # int64
    tri: np.ndarray  # int64
    t: np.ndarray  # float64
    front: np.ndarray  # bool: the corners run counter-clockwise seen from the origin
    margin: np.ndarray  # signed distance of the plane hit point to the nearest edge line
    m: np.ndarray  # how far the margin may move (safety included)
    tol_t: np.ndarray  # how far t may move
    facing_ambiguous: np.ndarray  # bool: a moved corner could turn the face


def brute_force(vertices, triangles, origins, directions, delta=0.0, facing_sign=None, chunk_elems=1_500_000):
    """All candidate hits of rays (N,3)+(N,3) on the mesh, t >= 0 (roughly).

    delta: how far the library may have moved a corner (a scalar or one value
    a triangle), in the vertices' units. facing_sign: +1/-1 a triangle, which
    turns its facing (a mirroring instance transform, flip_facing)."""
    a, b, c = triangle_geometry(vertices, triangles)
    o = np.asarray(origins, dtype=np.float64).reshape(-1, 3)
    d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    n_rays, n_tris = len(o), len(a)
    e1, e2 = b - a, c - a
    nrm = np.cross(e1, e2)
    area2 = np.linalg.norm(nrm, axis=1)
    # Altitudes from each corner onto its opposite edge.
    h_a = area2 / np.linalg.norm(c - b, axis=1)
    h_b = area2 / np.linalg.norm(e2, axis=1)
    h_c = area2 / np.linalg.norm(e1, axis=1)
    h_min = np.minimum(np.minimum(h_a, h_b), h_c)
    centroid = (a + b + c) / 3
    radius = np.sqrt(np.max([np.sum((p - centroid) ** 2, axis=1) for p in (a, b, c)], axis=0))
    delta_tri = np.broadcast_to(np.asarray(delta, dtype=np.float64), (n_tris,))
    sign_tri = np.ones(n_tris) if facing_sign is None else np.broadcast_to(np.asarray(facing_sign, float), (n_tris,))
    mesh_scale = float(np.max(np.abs(np.concatenate([a, b, c])))) if n_tris else 0.0
    ray_eps = FLOAT_EPS * np.maximum(mesh_scale, np.max(np.abs(o), axis=1))
    d_len = np.linalg.norm(d, axis=1)
    d_unit = d / d_len[:, None]

    out = {k: [] for k in ("ray", "tri", "t", "front", "margin", "m", "tol_t", "amb")}
    rows = max(1, chunk_elems // max(n_tris, 1))
    for r0 in range(0, n_rays, rows):
        rs = slice(r0, min(n_rays, r0 + rows))
        # Prefilter: the ray's line within the triangle's bounding sphere
        # (plus every tolerance). A farther line cannot reach the triangle
        # however its corners move.
        w = centroid[None, :, :] - o[rs, None, :]
        cr = np.cross(w, d_unit[rs, None, :])
        dist2 = np.einsum("rtk,rtk->rt", cr, cr)
        slack = radius[None, :] + 4 * SAFETY * (delta_tri[None, :] + ray_eps[rs, None])
        ri, ti = np.nonzero(dist2 <= slack * slack)
        if len(ri) == 0:
            continue
        ri = ri + r0
        dd, oo = d[ri], o[ri]
        pvec = np.cross(dd, e2[ti])
        det = np.einsum("pk,pk->p", e1[ti], pvec)
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / det
            tvec = oo - a[ti]
            u = np.einsum("pk,pk->p", tvec, pvec) * inv
            qvec = np.cross(tvec, e1[ti])
            v = np.einsum("pk,pk->p", dd, qvec) * inv
            t = np.einsum("pk,pk->p", e2[ti], qvec) * inv
            cos = np.abs(det) / (d_len[ri] * area2[ti])
            margin = np.minimum(np.minimum((1 - u - v) * h_a[ti], u * h_b[ti]), v * h_c[ti])
            dl = delta_tri[ti] + ray_eps[ri]
            m = SAFETY * dl * (1 + 1 / cos)
            tol_t = SAFETY * dl / (cos * d_len[ri]) + FLOAT_EPS * np.abs(t)
        keep = np.isfinite(t) & np.isfinite(margin) & (margin > -m) & (t >= -tol_t)
        # A triangle the ray meets nearly edge-on: a moved corner may turn it.
        facing_amb = cos < 4 * SAFETY * dl / h_min[ti] + 1e-9
        # det > 0: e1 . (d x e2) = -d . n > 0, n pointing back at the origin.
        front = (det * sign_tri[ti]) > 0
        for key, val in (("ray", ri), ("tri", ti), ("t", t), ("front", front), ("margin", margin), ("m", m),
                         ("tol_t", tol_t), ("amb", facing_amb)):
            out[key].append(val[keep])
    cat = {k: (np.concatenate(v) if v else np.zeros(0)) for k, v in out.items()}
    return Candidates(n_rays, cat["ray"].astype(np.int64), cat["tri"].astype(np.int64), cat["t"].astype(float),
                      cat["front"].astype(bool), cat["margin"].astype(float), cat["m"].astype(float),
                      cat["tol_t"].astype(float), cat["amb"].astype(bool))


@dataclass
class Truth:
    """What a query must answer on the clean rays."""

    clean: np.ndarray  # bool (N,): every candidate certain
    count: np.ndarray  # int (N,): hits on the ray (clean rays)
    offsets: np.ndarray  # int (N+1,): rows into tri/t/tol_t, nearest first
    tri: np.ndarray
    t: np.ndarray
    tol_t: np.ndarray

    def nearest(self):
        """(t, triangle, tol, unique) of each ray's nearest hit (inf / -1 on a miss).
        unique: the second hit is farther than both tolerances and a relative 1e-5."""
        n = len(self.count)
        t = np.full(n, np.inf)
        tri = np.full(n, -1, dtype=np.int64)
        tol = np.zeros(n)
        unique = np.ones(n, dtype=bool)
        hit = self.count > 0
        first = self.offsets[:-1][hit]
        t[hit], tri[hit], tol[hit] = self.t[first], self.tri[first], self.tol_t[first]
        two = self.count >= 2
        f2 = self.offsets[:-1][two]
        gap = self.t[f2 + 1] - self.t[f2]
        unique[two] = gap > self.tol_t[f2] + self.tol_t[f2 + 1] + 1e-5 * np.abs(self.t[f2])
        return t, tri, tol, unique

    def row(self, i):
        s = slice(self.offsets[i], self.offsets[i + 1])
        return self.tri[s], self.t[s], self.tol_t[s]


def classify(cands, t_min=0.0, t_max=np.inf, cull="none", enabled=None):
    """The certain answer of each ray for a t-range and a culling.
    enabled: optional bool a triangle (instances masked out or disabled)."""
    n = cands.n_rays
    tmin = np.broadcast_to(np.asarray(t_min, dtype=np.float64), (n,))
    tmax = np.broadcast_to(np.asarray(t_max, dtype=np.float64), (n,))
    r, t, tol = cands.ray, cands.t, cands.tol_t
    if cull == "none":
        face_ok = np.ones(len(r), dtype=bool)
        face_amb = np.zeros(len(r), dtype=bool)
    else:
        face_ok = cands.front if cull == "back" else ~cands.front
        face_amb = cands.facing_ambiguous
    lo, hi = tmin[r], tmax[r]
    with np.errstate(invalid="ignore"):
        relevant = (t >= lo - tol) & (t <= hi + tol) & (face_ok | face_amb)
        if enabled is not None:
            relevant &= np.asarray(enabled)[cands.tri]
        boundary = (np.abs(t - lo) <= tol) | (np.abs(t - hi) <= tol)
    ambiguous = relevant & ((cands.margin < cands.m) | boundary | face_amb)
    definite = relevant & ~ambiguous
    clean = np.ones(n, dtype=bool)
    clean[r[ambiguous]] = False
    rd, td, tri_d, told = r[definite], t[definite], cands.tri[definite], tol[definite]
    order = np.lexsort((tri_d, td, rd))
    rd, td, tri_d, told = rd[order], td[order], tri_d[order], told[order]
    count = np.bincount(rd, minlength=n)
    offsets = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(count, out=offsets[1:])
    return Truth(clean, count, offsets, tri_d, td, told)


def mesh_diagonal(vertices):
    v = np.asarray(vertices, dtype=np.float64)
    return float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
