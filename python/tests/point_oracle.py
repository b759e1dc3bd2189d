"""An independent float64 answer for point queries: every triangle tried.

The nearest point of a triangle to a point is the point's projection onto
the triangle's plane where that falls inside the triangle (its barycentric
coordinates from a least-squares solve, all non-negative), else the nearest
point of the three edges. Shares nothing with the library's code.
"""

import numpy as np


def _segment(p, a, b):
    """Nearest points of segments [a, b] (T, 3) to points p (P, 1, 3): (P, T, 3)."""
    e = b - a
    length2 = np.einsum("tk,tk->t", e, e)
    s = np.einsum("ptk,tk->pt", p - a, e) / np.where(length2 > 0, length2, 1)
    s = np.clip(np.where(length2 > 0, s, 0), 0, 1)
    return a + s[..., None] * e


def nearest(points, vertices, triangles, chunk=256):
    """For each point: (distance, triangle, nearest point), float64, the
    lowest triangle at the least distance."""
    p_all = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(triangles, dtype=np.int64)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    ab, ac = b - a, c - a
    # Gram matrix of the edges, for the projection's barycentrics.
    g00, g01, g11 = (np.einsum("tk,tk->t", ab, ab), np.einsum("tk,tk->t", ab, ac), np.einsum("tk,tk->t", ac, ac))
    det = g00 * g11 - g01 * g01
    flat = ~(det > 1e-30 * g00 * g11)
    dist, tri, near = [], [], []
    for start in range(0, len(p_all), chunk):
        p = p_all[start:start + chunk, None, :]
        ap = p - a
        r0, r1 = np.einsum("ptk,tk->pt", ap, ab), np.einsum("ptk,tk->pt", ap, ac)
        safe = np.where(flat, 1, det)
        u = (g11 * r0 - g01 * r1) / safe
        w = (g00 * r1 - g01 * r0) / safe
        inside = (u >= 0) & (w >= 0) & (u + w <= 1) & ~flat
        q = a + u[..., None] * ab + w[..., None] * ac
        best_q = np.where(inside[..., None], q, np.inf)
        best_d = np.where(inside, np.linalg.norm(p - q, axis=2), np.inf)
        for x, y in ((a, b), (b, c), (c, a)):
            e = _segment(p, x, y)
            d = np.linalg.norm(p - e, axis=2)
            take = (d < best_d) & ~inside
            best_d = np.where(take, d, best_d)
            best_q = np.where(take[..., None], e, best_q)
        t = np.argmin(best_d, axis=1)
        rows = np.arange(len(t))
        dist.append(best_d[rows, t])
        tri.append(t)
        near.append(best_q[rows, t])
    return np.concatenate(dist), np.concatenate(tri), np.concatenate(near)


def distance_to(points, vertices, triangles, which):
    """The distance from each point to its own triangle `which[i]`."""
    f = np.asarray(triangles)[np.asarray(which)]
    out = np.empty(len(f))
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    for i in range(len(f)):
        out[i] = nearest(p[i:i + 1], vertices, f[i:i + 1])[0][0]
    return out


def winding_number(points, vertices, triangles):
    """The generalized winding number of each point: the triangles' signed
    solid angles over 4 pi (Van Oosterom and Strackee's formula), float64.
    About 1 inside a closed mesh wound outward, -1 wound inward, 0 outside."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(triangles, dtype=np.int64)
    out = np.zeros(len(p))
    for start in range(0, len(p), 256):
        q = p[start:start + 256, None, :]
        a, b, c = v[f[:, 0]] - q, v[f[:, 1]] - q, v[f[:, 2]] - q
        la, lb, lc = (np.linalg.norm(x, axis=2) for x in (a, b, c))
        det = np.einsum("ptk,ptk->pt", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("ptk,ptk->pt", a, b) * lc + np.einsum("ptk,ptk->pt", b, c) * la
               + np.einsum("ptk,ptk->pt", c, a) * lb)
        out[start:start + 256] = (2 * np.arctan2(det, den)).sum(axis=1) / (4 * np.pi)
    return out
