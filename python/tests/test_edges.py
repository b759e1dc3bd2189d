"""Rays exactly through shared edges and vertices: nothing leaks.

Every coordinate here is a small dyadic number, so the rays, the corners and
the points where the rays cross the surface are exact in float32, and which
closed triangles hold a crossing point is decided exactly (fractions).

What must hold on every layout: one crossing of the surface is one distinct
t (never zero crossings: no leak; never two), a closest or any query never
misses, and every triangle reported holds the crossing point. How many of the
triangles around an edge or a vertex a query "all" reports is checked on its
own: the watertight test (Woop et al.) promises no leak, and reports every
triangle whose edge function comes out exactly zero, so a ray through an
edge meets both its triangles (Blob.cast, query "all"); RaycastingScene's
count_intersections and list_intersections count the crossing once
(test_one_hit_per_crossing)."""

from fractions import Fraction

import numpy as np
import pytest

import shapes
from cases import DEFAULT_LAYOUT, FLOAT3_LAYOUT, NO_HIT, describe
import meshcast

LAYOUTS = [DEFAULT_LAYOUT, FLOAT3_LAYOUT]


def containing(point, vertices, triangles):
    """The closed triangles holding an exact point (Fractions throughout)."""
    p = [Fraction(float(x)) for x in point]
    out = set()
    # Only triangles whose box holds the point can hold it (a float test,
    # exact: comparisons of exact values).
    corners = np.asarray(vertices, dtype=np.float64)[np.asarray(triangles, dtype=np.int64)]
    near = np.all((corners.min(axis=1) <= point) & (point <= corners.max(axis=1)), axis=1)
    for k in np.nonzero(near)[0]:
        tri = triangles[k]
        a, b, c = ([Fraction(float(x)) for x in vertices[i]] for i in tri)
        e1 = [b[i] - a[i] for i in range(3)]
        e2 = [c[i] - a[i] for i in range(3)]
        n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
        if sum(n[i] * (p[i] - a[i]) for i in range(3)) != 0:
            continue  # off the plane
        # Project along the normal's largest axis; signs of the three edge functions.
        ax = max(range(3), key=lambda i: abs(n[i]))
        i, j = [k2 for k2 in range(3) if k2 != ax]

        def edge(u, v):
            return (v[i] - u[i]) * (p[j] - u[j]) - (v[j] - u[j]) * (p[i] - u[i])

        s = [edge(a, b), edge(b, c), edge(c, a)]
        if all(x >= 0 for x in s) or all(x <= 0 for x in s):
            out.add(int(k))
    return out


def crossings(ts, tol):
    """Distinct crossings among sorted hit distances (hits within tol are one)."""
    ts = np.sort(np.asarray(ts, dtype=np.float64))
    return 0 if len(ts) == 0 else 1 + int(np.sum(np.diff(ts) > tol))


def grid_rays():
    """Rays through the 8x8 integer grid's interior vertices and edges (the
    three edge directions: x, y and the cells' diagonals), straight down, straight
    up and oblique; each crosses z = 0 at t = 2 at a known point."""
    points = []
    for x in range(1, 8):
        for y in range(1, 8):
            points.append((x, y))  # vertex
            points.append((x + 0.5, y))  # edge along x
            points.append((x, y + 0.5))  # edge along y
            points.append((x + 0.25, y + 0.25))  # a cell's diagonal
            points.append((x - 0.375, y - 0.375))
    origins, directions, hits = [], [], []
    for px, py in points:
        for d in ((0.0, 0.0, -1.0), (0.0, 0.0, 1.0), (0.5, -0.25, -1.0), (-0.125, 0.75, 1.0)):
            d = np.array(d)
            p = np.array([px, py, 0.0])
            origins.append(p - 2 * d)
            directions.append(d)
            hits.append(p)
    return (np.array(origins, dtype=np.float32), np.array(directions, dtype=np.float32), np.array(hits))


def check_exact_crossings(v, f, layout, origins, directions, hit_points, t_hits, what):
    """hit_points[i]: the exact crossing points of ray i (at t_hits[i])."""
    b = meshcast.build(v, f, layout=layout)
    tol = 1e-6 if layout == FLOAT3_LAYOUT else 1e-4
    incident = [[containing(p, v, f) for p in pts] for pts in hit_points]
    for sets in incident:
        assert all(sets), "a test point is not on the surface"
    closest = b.cast(origins, directions)
    anyq = b.cast(origins, directions, query="any")
    allq = b.cast(origins, directions, query="all", max_hits=64)
    problems = []
    for i in range(len(origins)):
        near = min(range(len(t_hits[i])), key=lambda k: t_hits[i][k])
        if closest["triangle"][i] == NO_HIT:
            problems.append(f"ray {i} {origins[i].tolist()} -> {directions[i].tolist()}: closest leaked")
        elif closest["triangle"][i] not in incident[i][near] or abs(closest["t"][i] - t_hits[i][near]) > tol:
            problems.append(f"ray {i}: closest triangle {closest['triangle'][i]} at t {closest['t'][i]}, "
                            f"expected one of {sorted(incident[i][near])} at t {t_hits[i][near]}")
        if anyq["triangle"][i] == NO_HIT:
            problems.append(f"ray {i} {origins[i].tolist()} -> {directions[i].tolist()}: any leaked")
        s = slice(allq["offsets"][i], allq["offsets"][i + 1])
        ts, tris = allq["t"][s], allq["triangle"][s].tolist()
        found = int(allq["found"][i])
        if crossings(ts, tol) != len(t_hits[i]) or found != len(tris):
            problems.append(f"ray {i} {origins[i].tolist()} -> {directions[i].tolist()}: all found {found}, "
                            f"t {ts.tolist()}, expected {len(t_hits[i])} crossing(s) at t {list(t_hits[i])}")
            continue
        if len(set(tris)) != len(tris):
            problems.append(f"ray {i}: a triangle reported twice: {tris}")
        for th, sets in zip(t_hits[i], incident[i]):
            at = [tri for tri, t in zip(tris, ts) if abs(t - th) <= tol]
            if not at or not set(at) <= sets:
                problems.append(f"ray {i}: at t {th} triangles {at}, expected a subset of {sorted(sets)}")
    assert not problems, f"{what} {layout}: {len(problems)} problems:\n  " + "\n  ".join(problems[:10])


@pytest.mark.parametrize("layout", LAYOUTS)
def test_grid_edges_and_vertices(layout):
    v, f = shapes.grid(8, 8)
    o, d, p = grid_rays()
    check_exact_crossings(v, f, layout, o, d, [[x] for x in p], [[2.0]] * len(o), "grid")


def test_one_hit_per_crossing():
    """RaycastingScene counts and lists crossings: through a shared edge or
    vertex of the flat grid the ray crosses the surface once, so
    count_intersections is 1 and list_intersections lists one hit (Blob.cast
    with query "all" reports every triangle holding the point instead:
    test_grid_edges_and_vertices)."""
    v, f = shapes.grid(8, 8)
    o, d, p = grid_rays()
    rc = meshcast.RaycastingScene()
    rc.add_triangles(v, f)
    rays = np.concatenate([o, d], axis=1)
    counts = np.asarray(rc.count_intersections(rays))
    listed = rc.list_intersections(rays)
    per_ray = np.diff(np.asarray(listed["ray_splits"]))
    bad = np.nonzero((counts != 1) | (per_ray != 1))[0]
    kinds = {}
    for i in bad:
        kinds.setdefault((tuple(float(x) for x in p[i][:2] % 1)), []).append((int(counts[i]), int(per_ray[i])))
    if len(bad):
        pytest.fail(f"{len(bad)} of {len(o)} rays did not count one crossing; by the crossing "
                    f"point's place in its cell (x mod 1, y mod 1): (count, listed) "
                    + ", ".join(f"{k}: {sorted(set(v))}" for k, v in kinds.items()) + f"; first: {describe(bad[0], o, d)}")
    np.testing.assert_allclose(np.asarray(listed["t_hit"]), 2.0, atol=1e-6)


@pytest.mark.parametrize("layout", LAYOUTS)
def test_grid_culling_through_edges(layout):
    """Grid normals are +z: a ray going down sees front faces. Through an edge
    or a vertex, cull="back" keeps the hit at t 2 and cull="front" drops it."""
    v, f = shapes.grid(8, 8)
    o, d, _ = grid_rays()
    b = meshcast.build(v, f, layout=layout)
    down = d[:, 2] < 0
    for cull, kept in (("back", down), ("front", ~down)):
        for query in ("closest", "any"):
            r = b.cast(o, d, query=query, cull=cull)
            hit = r["triangle"] != NO_HIT
            np.testing.assert_array_equal(hit, kept, err_msg=f"cull={cull} query={query}")
            np.testing.assert_allclose(r["t"][kept], 2.0, rtol=1e-6 if layout == FLOAT3_LAYOUT else 1e-4)


def closed_rays(pairs):
    """A ray through each pair of surface points: origin one step before the
    first, so the crossings are at t 1 and 2."""
    p_in = np.array([p for p, _ in pairs], dtype=np.float64)
    p_out = np.array([q for _, q in pairs], dtype=np.float64)
    d = p_out - p_in
    return (p_in - d).astype(np.float32), d.astype(np.float32), [[a, b] for a, b in zip(p_in, p_out)]


CUBE_PAIRS = [
    ((1, 1, 0.25), (-1, -1, -0.5)),  # edge to the opposite edge
    ((1, 1, 0.25), (-1, 0.375, 0.5)),  # edge to a face
    ((1, -1, 0.5), (-0.25, 1, -0.75)),
    ((1, 1, 1), (-1, -1, -1)),  # vertex to vertex (the diagonal)
    ((1, 1, 1), (-1, 0.25, -0.5)),  # vertex to a face
    ((-1, 1, -1), (1, -0.5, 1)),  # vertex to an edge
    ((0.5, 0.5, 1), (-1, -0.5, -0.5)),  # a face diagonal to a face diagonal
    ((1, 0.0, 0.0), (0.25, 1, 0.25)),
]

OCTAHEDRON_PAIRS = [
    ((1, 1, 0), (-1, -1, 0)),  # edge midpoints, opposite edges
    ((1, 1, 0), (-0.5, 0, 1.5)),  # edge to edge
    ((2, 0, 0), (-2, 0, 0)),  # vertex to vertex
    ((0, 2, 0), (-0.5, -0.5, -1)),  # vertex to a face
    ((0, 0, -2), (0.5, 0.5, 1)),  # vertex to a face
    ((1, 0, 1), (0, -1, -1)),  # edge to edge
]


@pytest.mark.parametrize("layout", LAYOUTS)
@pytest.mark.parametrize("shape", ["cube", "octahedron"])
def test_closed_mesh_edges_and_vertices(shape, layout):
    """From outside through edges and vertices of a closed convex mesh: two
    crossings (in and out), nothing leaked, nothing counted at another t."""
    v, f = shapes.cube() if shape == "cube" else shapes.octahedron()
    pairs = CUBE_PAIRS if shape == "cube" else OCTAHEDRON_PAIRS
    o, d, pts = closed_rays(pairs)
    # Both directions along each line.
    o2, d2, pts2 = closed_rays([(q, p) for p, q in pairs])
    o, d, pts = np.concatenate([o, o2]), np.concatenate([d, d2]), pts + pts2
    check_exact_crossings(v, f, layout, o, d, pts, [[1.0, 2.0]] * len(o), shape)


@pytest.mark.parametrize("layout", LAYOUTS)
def test_closed_cube_culling_through_edges(layout):
    """Outward faces: entering, the ray meets front faces, leaving back faces.
    cull="back" keeps the entry (t 1), cull="front" the exit (t 2)."""
    v, f = shapes.cube()
    o, d, _ = closed_rays(CUBE_PAIRS)
    b = meshcast.build(v, f, layout=layout)
    tol = 1e-6 if layout == FLOAT3_LAYOUT else 1e-4
    for cull, t in (("back", 1.0), ("front", 2.0)):
        r = b.cast(o, d, cull=cull)
        assert np.all(r["triangle"] != NO_HIT), f"cull={cull}: a ray leaked"
        np.testing.assert_allclose(r["t"], t, atol=tol, err_msg=f"cull={cull}")


@pytest.mark.parametrize("shape", ["cube", "octahedron"])
def test_closed_mesh_two_hits_through_edges(shape):
    """From outside through edges and vertices of a closed convex mesh:
    list_intersections lists exactly 2 hits, in and out (one a crossing)."""
    v, f = shapes.cube() if shape == "cube" else shapes.octahedron()
    o, d, _ = closed_rays(CUBE_PAIRS if shape == "cube" else OCTAHEDRON_PAIRS)
    rc = meshcast.RaycastingScene()
    rc.add_triangles(v, f)
    found = np.diff(np.asarray(rc.list_intersections(np.concatenate([o, d], axis=1))["ray_splits"]))
    bad = np.nonzero(found != 2)[0]
    if len(bad):
        pytest.fail(f"{shape}: listed {found.tolist()}, expected 2 on every ray; first: {describe(bad[0], o, d)}")


@pytest.mark.parametrize("shape", ["cube", "octahedron"])
def test_count_intersections_parity(shape):
    """RaycastingScene.count_intersections is what inside/outside tests count:
    through edges and vertices, 2 from outside and 1 from inside (from the
    midpoint of each outside ray's chord)."""
    v, f = shapes.cube() if shape == "cube" else shapes.octahedron()
    o, d, _ = closed_rays(CUBE_PAIRS if shape == "cube" else OCTAHEDRON_PAIRS)
    rc = meshcast.RaycastingScene()
    rc.add_triangles(v, f)
    outside = np.asarray(rc.count_intersections(np.concatenate([o, d], axis=1)))
    inside_o = (o.astype(np.float64) + 1.5 * d).astype(np.float32)  # halfway between t 1 and 2: exact
    inside = np.asarray(rc.count_intersections(np.concatenate([inside_o, d], axis=1)))
    if np.any(outside != 2) or np.any(inside != 1):
        pytest.fail(f"{shape}: from outside {outside.tolist()} (expected 2), from inside {inside.tolist()} (expected 1)")


def test_crossings_of_two_geometries_stay_two():
    """Two geometries whose surfaces lie at one t are two crossings: only a
    geometry's own triangles around an edge or vertex make one."""
    v, f = shapes.grid(2, 2)
    rc = meshcast.RaycastingScene()
    rc.add_triangles(v, f)
    rc.add_triangles(v, f)
    rays = np.array([[0.5, 0.25, 1.0, 0, 0, -1.0], [1.0, 1.0, 1.0, 0, 0, -1.0]], np.float32)  # a face; a vertex
    np.testing.assert_array_equal(np.asarray(rc.count_intersections(rays)), [2, 2])
    listed = rc.list_intersections(rays)
    np.testing.assert_array_equal(np.asarray(listed["ray_splits"]), [0, 2, 4])
    assert sorted(np.asarray(listed["geometry_ids"])[:2].tolist()) == [0, 1]


def stacked_triangles(zs):
    """One triangle over (0..1, 0..1) at each height of zs."""
    zs = np.asarray(zs, np.float64)
    v = np.zeros((3 * len(zs), 3))
    v[:, 2] = np.repeat(zs, 3)
    v[1::3, 0] = 1
    v[2::3, 1] = 1
    return v, np.arange(3 * len(zs)).reshape(-1, 3)


def fan(n, z, centre=(0.25, 0.25)):
    """A flat disk of n triangles around the vertex `centre` at height z: a
    ray through that vertex meets all n at one t, one crossing."""
    angle = 2 * np.pi * np.arange(n) / n
    v = np.zeros((n + 1, 3))
    v[0, :2] = centre
    v[1:, 0] = centre[0] + 0.5 * np.cos(angle)
    v[1:, 1] = centre[1] + 0.5 * np.sin(angle)
    v[:, 2] = z
    k = np.arange(n)
    return v, np.stack([np.zeros(n, np.int64), 1 + k, 1 + (k + 1) % n], axis=1)


def joined(*meshes):
    vertices, triangles, base = [], [], 0
    for v, t in meshes:
        vertices.append(v)
        triangles.append(t + base)
        base += len(v)
    return np.concatenate(vertices), np.concatenate(triangles)


def test_list_intersections_lists_every_crossing_beyond_a_row():
    """A ray of more hits than a walk's row keeps (4096) is listed whole,
    nearest first: 4090 planes, then a fan of 40 triangles through whose
    centre it passes (where the first row is cut: 6 of its 40 hits kept),
    then 30 planes. The fan is one crossing, as with fewer hits."""
    planes = np.concatenate([np.arange(4090), np.arange(4091, 4121)])
    v, f = joined(stacked_triangles(planes), fan(40, 4090.0))
    rc = meshcast.RaycastingScene()
    rc.add_triangles(v, f)
    ray = np.array([[0.25, 0.25, -1.0, 0, 0, 1.0], [0.25, 0.25, 9000.0, 0, 0, -1.0]], np.float32)
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        listed = rc.list_intersections(ray)
    crossings = len(planes) + 1
    assert np.asarray(rc.count_intersections(ray)).tolist() == [crossings, crossings]
    splits = np.asarray(listed["ray_splits"])
    assert splits.tolist() == [0, crossings, 2 * crossings]
    heights = np.sort(np.concatenate([planes, [4090.0]]))
    for r, order in ((0, 1), (1, -1)):
        ids = np.asarray(listed["primitive_ids"])[splits[r]:splits[r + 1]]
        t = np.asarray(listed["t_hit"])[splits[r]:splits[r + 1]]
        assert np.all(np.diff(t) > 0)
        assert np.array_equal(np.sort(ray[r, 2] + order * t), heights.astype(np.float32))
        planes_listed = ids[ids < len(planes)]
        assert sorted(planes_listed.tolist()) == list(range(len(planes)))  # each plane once
        assert (ids >= len(planes)).sum() == 1  # the fan once, by one of its triangles


def test_list_intersections_warns_of_what_it_leaves_out():
    """More hits at one t than a row keeps (a fan of 4100 triangles about
    the ray's vertex) warn; a filter that makes warnings errors raises that
    error (not a SystemError)."""
    import warnings
    v, f = joined(fan(4100, 0.0), stacked_triangles([1.0]))
    rc = meshcast.RaycastingScene()
    rc.add_triangles(v, f)
    ray = np.array([[0.25, 0.25, -1.0, 0, 0, 1.0]], np.float32)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(RuntimeWarning, match="left out"):
            rc.list_intersections(ray)
