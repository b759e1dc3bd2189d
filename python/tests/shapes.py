"""Small generated meshes and ray sets for the tests (deterministic)."""

import os

import numpy as np

# The meshes fetched for the C++ tests (MESHCAST_DATA, as they read it; else
# the repository's data/).
DATA = os.environ.get("MESHCAST_DATA") or os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "data")
BUNNY = os.path.join(DATA, "bunny00.off")


def sphere(rings=12, segments=20, radius=1.5, centre=(0.25, -0.5, 2.0)):
    """Closed UV sphere, outward facing (counter-clockwise seen from outside),
    each edge shared by two triangles."""
    verts = [(0.0, 0.0, radius)]
    for r in range(1, rings):
        th = np.pi * r / rings
        for s in range(segments):
            ph = 2 * np.pi * s / segments
            verts.append((radius * np.sin(th) * np.cos(ph), radius * np.sin(th) * np.sin(ph), radius * np.cos(th)))
    verts.append((0.0, 0.0, -radius))
    south = len(verts) - 1

    def ring(r, s):
        return 1 + (r - 1) * segments + (s % segments)

    tris = []
    for s in range(segments):
        tris.append((0, ring(1, s), ring(1, s + 1)))
        tris.append((south, ring(rings - 1, s + 1), ring(rings - 1, s)))
    for r in range(1, rings - 1):
        for s in range(segments):
            a, b, c, d = ring(r, s), ring(r + 1, s), ring(r + 1, s + 1), ring(r, s + 1)
            tris.append((a, b, c))
            tris.append((a, c, d))
    v = (np.array(verts) + np.array(centre)).astype(np.float32)
    return v, np.array(tris, dtype=np.uint32)


def soup(n=300, seed=1, extent=4.0, size=0.6):
    """Random triangles of various sizes and orientations in a box (they may
    cross each other)."""
    rng = np.random.default_rng(seed)
    centres = rng.uniform(-extent / 2, extent / 2, (n, 1, 3))
    corners = centres + rng.normal(0, size / 2, (n, 3, 3)) * rng.uniform(0.2, 1.0, (n, 1, 1))
    return corners.reshape(-1, 3).astype(np.float32), np.arange(3 * n, dtype=np.uint32).reshape(n, 3)


def grid(nx=12, ny=10, z=0.0, scale=1.0):
    """Flat grid on z = const with vertices on integer points (times scale),
    two triangles a cell, normals +z. Every coordinate exactly representable."""
    xs, ys = np.meshgrid(np.arange(nx + 1), np.arange(ny + 1))
    v = np.stack([xs.ravel() * scale, ys.ravel() * scale, np.full(xs.size, z)], axis=1).astype(np.float32)
    tris = []
    for y in range(ny):
        for x in range(nx):
            i = y * (nx + 1) + x
            tris.append((i, i + 1, i + nx + 2))
            tris.append((i, i + nx + 2, i + nx + 1))
    return v, np.array(tris, dtype=np.uint32)


def cube(lo=-1.0, hi=1.0):
    """Closed cube, 12 triangles, outward facing."""
    v = np.array([[x, y, z] for z in (lo, hi) for y in (lo, hi) for x in (lo, hi)], dtype=np.float32)
    # corners: index = x + 2y + 4z (0: lo, 1: hi)
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    tris = []
    for a, b, c, d in quads:
        tris += [(a, b, c), (a, c, d)]
    tris = np.array(tris, dtype=np.uint32)
    # Outward: the normal points away from the centre.
    a, b, c = (v[tris[:, k]].astype(float) for k in range(3))
    n = np.cross(b - a, c - a)
    assert np.all(np.einsum("ij,ij->i", n, (a + b + c) / 3) > 0)
    return v, tris


def octahedron(r=2.0):
    """Closed octahedron, 8 triangles, outward facing."""
    v = np.array([[r, 0, 0], [-r, 0, 0], [0, r, 0], [0, -r, 0], [0, 0, r], [0, 0, -r]], dtype=np.float32)
    tris = []
    for x in (0, 1):
        for y in (2, 3):
            for z in (4, 5):
                t = [x, y, z]
                a, b, c = (v[k].astype(float) for k in t)
                if np.dot(np.cross(b - a, c - a), a + b + c) < 0:
                    t = [x, z, y]
                tris.append(t)
    return v, np.array(tris, dtype=np.uint32)


def rays(vertices, n, seed=0, inside_fraction=0.3):
    """Rays at a mesh: most from a sphere around it aimed at random points of
    its box, the rest from inside the box in random directions; directions
    of random length (t is in their units). float32 values (so float32 and
    float64 copies are the same rays)."""
    rng = np.random.default_rng(seed)
    v = np.asarray(vertices, dtype=np.float64)
    lo, hi = v.min(axis=0), v.max(axis=0)
    centre, diag = (lo + hi) / 2, np.linalg.norm(hi - lo)
    # Inside origins from a box a little larger than the mesh's, so a flat
    # mesh's rays do not start on its plane.
    pad = 0.05 * diag
    n_in = int(n * inside_fraction)
    n_out = n - n_in
    dirs_out = rng.normal(size=(n_out, 3))
    dirs_out /= np.linalg.norm(dirs_out, axis=1, keepdims=True)
    org_out = centre + dirs_out * diag
    target = rng.uniform(lo, hi, (n_out, 3))
    d_out = target - org_out
    org_in = rng.uniform(lo - pad, hi + pad, (n_in, 3))
    d_in = rng.normal(size=(n_in, 3))
    origins = np.concatenate([org_out, org_in])
    directions = np.concatenate([d_out / np.linalg.norm(d_out, axis=1, keepdims=True), d_in / np.linalg.norm(d_in, axis=1, keepdims=True)])
    directions *= rng.uniform(0.5, 3.0, (n, 1))
    perm = rng.permutation(n)
    return origins[perm].astype(np.float32), directions[perm].astype(np.float32)


def read_off(path):
    """A plain OFF reader (triangles only, fans for polygons) for meshes the
    tests use without meshcast.read_mesh."""
    with open(path) as f:
        words = f.read().split()
    assert words[0] == "OFF"
    nv, nf = int(words[1]), int(words[2])
    pos = 4
    v = np.array(words[pos:pos + 3 * nv], dtype=np.float64).reshape(nv, 3).astype(np.float32)
    pos += 3 * nv
    tris = []
    for _ in range(nf):
        k = int(words[pos])
        idx = [int(w) for w in words[pos + 1:pos + 1 + k]]
        pos += 1 + k
        for j in range(1, k - 1):
            tris.append((idx[0], idx[j], idx[j + 1]))
    return v, np.array(tris, dtype=np.uint32)
