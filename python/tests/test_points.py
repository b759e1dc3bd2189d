"""Point queries: Blob.closest_points and RaycastingScene's
compute_closest_points and compute_distance, against the float64 answer of
point_oracle.py (every triangle tried)."""

import os

import numpy as np
import pytest

import meshcast
import shapes
from point_oracle import distance_to, nearest

EXACT = "OctTreeCompressed/Float3SOA8"
EXACT_CLUSTER = "OctTreeCompressed/ClusterFloat3SOA8"
RECOMMENDED = "OctTreeCompressed/ClusterBitPackSOA8"


def query_points(v, n, seed):
    """Scattered through the box grown by a fifth, near the surface, on
    corners, and far out."""
    rng = np.random.default_rng(seed)
    lo, hi = v.min(0).astype(np.float64), v.max(0).astype(np.float64)
    size = hi - lo
    scattered = lo - 0.2 * size + rng.uniform(0, 1.4, (n, 3)) * size
    near = v[rng.integers(0, len(v), n)] + rng.normal(0, 1e-3 * np.linalg.norm(size), (n, 3))
    corners = v[rng.integers(0, len(v), n // 4)]
    far = (lo + hi) / 2 + rng.uniform(-10, 10, (n // 4, 3)) * np.linalg.norm(size)
    return np.concatenate([scattered, near, corners, far]).astype(np.float32)


def tolerance(distance, scale):
    # float32 rounding of the answer and of the points' coordinates
    return 4e-7 * distance + 2e-7 * scale


MESHES = {"sphere": shapes.sphere(), "grid": shapes.grid(), "soup": shapes.soup(), "octahedron": shapes.octahedron()}


@pytest.mark.parametrize("layout", [EXACT, EXACT_CLUSTER])
@pytest.mark.parametrize("name", sorted(MESHES))
def test_exact_layout_distances_match_float64(name, layout):
    v, t = MESHES[name]
    blob = meshcast.build(v, t, layout=layout)
    p = query_points(v, 120, 3)
    got = blob.closest_points(p)
    d, tri, q = nearest(p, v, t)
    scale = max(np.abs(p).max(), np.abs(v).max())
    tol = tolerance(d, scale)
    assert np.all(np.abs(got["distance"] - d) <= tol)
    # the triangle named lies at that distance (a tie may name another)
    assert np.all(np.abs(distance_to(p, v, t, got["triangle"]) - d) <= tol)
    # the point given is that far away and is the triangle's (u, v) point
    assert np.all(np.abs(np.linalg.norm(got["point"] - p.astype(np.float64), axis=1) - d) <= tol + 4e-7 * scale)
    f = t[got["triangle"]].astype(np.int64)
    u, w = got["uv"][:, :1].astype(np.float64), got["uv"][:, 1:].astype(np.float64)
    at = (1 - u - w) * v[f[:, 0]] + u * v[f[:, 1]] + w * v[f[:, 2]]
    assert np.all(np.abs(at - got["point"]) <= 1e-6 * scale)


def test_recommended_layout_within_its_bound_of_the_input_mesh():
    v, t = shapes.read_off(shapes.BUNNY) if os.path.exists(shapes.BUNNY) else shapes.sphere(40, 60)
    blob = meshcast.build(v, t, layout=RECOMMENDED)
    p = query_points(v, 60, 5)
    got = blob.closest_points(p, nthreads=2)
    d, _, _ = nearest(p, v, t)
    diagonal = np.linalg.norm(v.max(0).astype(np.float64) - v.min(0))
    # the 18-bit grid of the mesh's box: half a step an axis, sqrt(3)/2 of
    # 2^-18 of the largest extent, below 4e-6 of the diagonal
    bound = 4e-6 * diagonal
    assert np.all(np.abs(got["distance"] - d) <= bound + tolerance(d, np.abs(p).max()))
    assert np.abs(got["distance"] - d).max() > 0  # quantized: not the input's exactly


def test_max_distance_shapes_and_dtypes():
    v, t = shapes.grid()  # z = 0
    blob = meshcast.build(v, t, layout=RECOMMENDED)
    centre = v.mean(0).astype(np.float64)
    p = np.tile(centre, (4, 5, 1))
    p[..., 2] = np.linspace(-2, 2, 20).reshape(4, 5)
    got = blob.closest_points(p, max_distance=1.0)
    assert got["distance"].shape == (4, 5) and got["point"].shape == (4, 5, 3) and got["uv"].shape == (4, 5, 2)
    assert got["distance"].dtype == np.float32 and got["triangle"].dtype == np.uint32
    far = np.abs(p[..., 2]) > 1.0
    assert np.all(got["triangle"][far] == meshcast.NO_HIT) and np.all(np.isinf(got["distance"][far]))
    assert np.all(np.isnan(got["point"][far]))
    assert np.allclose(got["distance"][~far], np.abs(p[..., 2][~far]), atol=1e-5)
    # float64, a list, one point: the same answers
    assert blob.closest_points(p.tolist(), max_distance=1.0)["distance"].tolist() == got["distance"].tolist()
    assert blob.closest_points(p[0, 0])["distance"].shape == ()


def test_bad_input_is_refused_by_name():
    v, t = shapes.sphere()
    blob = meshcast.build(v, t, layout=RECOMMENDED)
    with pytest.raises(ValueError, match=r"points\[1\]: coordinate 0 is nan"):
        blob.closest_points(np.array([[0, 0, 0], [np.nan, 0, 0]]))
    with pytest.raises(ValueError, match=r"points\[0\]: coordinate 2 is inf"):
        blob.closest_points(np.array([[0, 0, np.inf]]))
    with pytest.raises(ValueError, match=r"not \(\.\.\., 3\)"):
        blob.closest_points(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="max_distance"):
        blob.closest_points(np.zeros((1, 3)), max_distance=-1)
    with pytest.raises(ValueError, match="max_distance"):
        blob.closest_points(np.zeros((1, 3)), max_distance=float("nan"))
    other = meshcast.build(v, t, layout="AABBTree/Float3")
    with pytest.raises(ValueError, match="AABBTree/Float3"):
        other.closest_points(np.zeros((1, 3)))
    with pytest.raises(ValueError, match="AABBTree/Float3"):
        other.closest_points(np.zeros((0, 3)))
    assert blob.closest_points(np.zeros((0, 3)))["distance"].shape == (0,)
    with pytest.raises(ValueError, match="beyond float"):
        blob.closest_points(np.array([[1e39, 0, 0]]))


def test_raycasting_scene_nearest_of_every_geometry():
    """Two geometries, one about 10^6 units out (stored about its own
    float64 centre): the nearest of both, Open3D's keys, the normal and
    barycentrics of the triangle named."""
    sv, st = shapes.sphere()
    cv, ct = shapes.cube()
    cv64 = cv.astype(np.float64) + np.array([1e6, 0, 0])
    scene = meshcast.RaycastingScene()
    assert scene.add_triangles(sv, st) == 0
    assert scene.add_triangles(cv64, ct) == 1
    rng = np.random.default_rng(9)
    p = np.concatenate([rng.uniform(-3, 3, (80, 3)) + [0.25, -0.5, 2.0],
                        rng.uniform(-2, 2, (80, 3)) + [1e6, 0, 0],
                        rng.uniform(-1e6, 2e6, (40, 3))])
    got = scene.compute_closest_points(p)
    assert sorted(got) == ["geometry_ids", "points", "primitive_ids", "primitive_normals", "primitive_uvs"]
    d0, t0, _ = nearest(p, sv, st)
    d1, t1, _ = nearest(p - [1e6, 0, 0], cv, ct)
    want = np.minimum(d0, d1)
    scale = np.maximum(np.abs(p).max(1), 1.0)
    dist = scene.compute_distance(p)
    assert dist.dtype == np.float32 and dist.shape == (200,)
    # the scene's geometries are stored exactly: within float32 rounding of
    # each point in its geometry's frame
    bound = 0.0
    assert np.all(np.abs(dist - want) <= bound + tolerance(want, scale))
    g = got["geometry_ids"].numpy()
    assert set(np.unique(g)) == {0, 1}
    # the nearer geometry named, unless the two are within the bound
    assert np.all((g == np.where(d1 < d0, 1, 0)) | (np.abs(d0 - d1) <= 2 * bound + tolerance(want, scale)))
    pts = got["points"].numpy().astype(np.float64)
    assert np.all(np.abs(np.linalg.norm(pts - p, axis=1) - want) <= bound + tolerance(want, scale) + 1e-7 * scale)
    for geometry, (v, t, offset) in enumerate([(sv, st, 0.0), (cv, ct, 1e6)]):
        rows = g == geometry
        f = t[got["primitive_ids"].numpy()[rows]].astype(np.int64)
        a, b, c = (v.astype(np.float64)[f[:, k]] for k in range(3))
        n = np.cross(b - a, c - a)
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        assert np.all(np.abs(got["primitive_normals"].numpy()[rows] - n) <= 1e-4)
        uv = got["primitive_uvs"].numpy()[rows].astype(np.float64)
        at = (1 - uv[:, :1] - uv[:, 1:]) * a + uv[:, :1] * b + uv[:, 1:] * c
        at[:, 0] += offset
        # (u, v) of the stored corners, the input's
        assert np.all(np.abs(at - pts[rows]) <= bound + 1e-6 * np.maximum(np.abs(pts[rows]), 1))
    # The points are walked in an order of the library's own (near ones
    # together): asked in another order, each gets the same answer.
    order = rng.permutation(len(p))
    again = scene.compute_closest_points(p[order])
    for key in got:
        assert np.array_equal(again[key].numpy(), got[key].numpy()[order]), key


def test_raycasting_scene_without_geometry():
    scene = meshcast.RaycastingScene()
    got = scene.compute_closest_points(np.zeros((3, 3), np.float32))
    assert np.all(got["geometry_ids"].numpy() == meshcast.RaycastingScene.INVALID_ID)
    assert np.all(np.isinf(scene.compute_distance(np.zeros((2, 3)))))


def test_scene_closest_points_are_world_distances():
    """Scene.closest_points on instances rotated, scaled unevenly and
    mirrored: the nearest point of the world's triangles (each instance's
    mesh placed by its transform in float64), not of the frames'."""
    sv, st = shapes.sphere(rings=10, segments=16)
    gv, gt = shapes.grid(6, 5)
    blobs = [meshcast.build(sv, st, layout="OctTreeCompressed/Float3SOA8"), meshcast.build(gv, gt)]
    scene = meshcast.Scene()
    meshes = [scene.add_mesh(b) for b in blobs]
    rng = np.random.default_rng(21)
    world_v, world_t, owner = [], [], []
    base = 0
    for i in range(6):
        a = rng.uniform(0, 2 * np.pi)
        rotation = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
        m = (rotation * rng.uniform(0.3, 3.0, 3)).astype(np.float32)
        if i == 2:
            m[:, 0] *= -1
        translation = rng.uniform(-6, 6, 3) + [1e5, 0, 0]  # far out: the translations stay in double
        instance = scene.add_instance(meshes[i % 2], rotation_scale=m, translation=translation)
        v, t = (sv, st) if i % 2 == 0 else (gv, gt)
        world_v.append(v.astype(np.float64) @ m.astype(np.float64).T + translation)
        world_t.append(t.astype(np.int64) + base)
        owner += [(instance, k) for k in range(len(t))]
        base += len(v)
    scene.commit()
    world_v, world_t = np.concatenate(world_v), np.concatenate(world_t)
    p = rng.uniform(-10, 10, (300, 3)) + [1e5, 0, 0]
    got = scene.closest_points(p)
    want, tri, point = nearest(p, world_v, world_t)
    # The grid's blob is quantized: its corners within its stated bound
    # (a few millionths of its diagonal, times the scale) of the input's.
    assert np.allclose(got["distance"], want, rtol=0, atol=1e-4)
    assert got["distance"].dtype == np.float64 and got["point"].shape == (300, 3)
    assert np.allclose(np.linalg.norm(got["point"] - p, axis=1), got["distance"], atol=1e-6)
    ids = list(zip(got["instance"].tolist(), got["triangle"].tolist()))
    own = [owner.index(k) for k in ids]
    assert np.allclose(distance_to(p, world_v, world_t, own), want, atol=1e-4)
    # Within a limit
    near = scene.closest_points(p, max_distance=1.0)
    found = np.isfinite(near["distance"])
    assert found[want < 1.0 - 1e-4].all() and not found[want > 1.0 + 1e-4].any()
    assert (near["triangle"][~found] == meshcast.NO_HIT).all()
    with pytest.raises(ValueError, match="max_distance"):
        scene.closest_points(p, max_distance=-1.0)
