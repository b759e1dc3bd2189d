"""Every query and culling on Blob.cast, Scene.cast and the RaycastingScene
methods, against the double-precision brute force (oracle.py) on generic rays."""

import numpy as np
import pytest

import meshcast
import oracle
import shapes
from cases import (DEFAULT_LAYOUT, FLOAT3_LAYOUT, LAYOUTS, LOSSY_DELTA, MESH_NAMES, NO_HIT, World, blob, case,
                   check_all, check_any, check_closest, rays6, rotation)

CULLS = ["none", "back", "front"]


@pytest.mark.parametrize("cull", CULLS)
@pytest.mark.parametrize("layout", LAYOUTS)
@pytest.mark.parametrize("name", MESH_NAMES)
def test_blob_closest(name, layout, cull):
    c = case(name)
    b = blob(name, layout)
    r = b.cast(c.origins, c.directions, t_min=c.t_min, t_max=c.t_max, query="closest", cull=cull)
    assert r["t"].dtype == np.float32 and r["t"].shape == (len(c.origins),)
    assert r["triangle"].dtype == np.uint32 and r["triangle"].shape == (len(c.origins),)
    assert np.all(np.isinf(r["t"]) == (r["triangle"] == NO_HIT)), "t is inf exactly on the misses"
    check_closest(c.truth(layout, cull), r["t"], r["triangle"], f"{name} {layout} closest cull={cull}", c.origins,
                  c.directions)


@pytest.mark.parametrize("cull", CULLS)
@pytest.mark.parametrize("layout", LAYOUTS)
@pytest.mark.parametrize("name", MESH_NAMES)
def test_blob_any(name, layout, cull):
    c = case(name)
    r = blob(name, layout).cast(c.origins, c.directions, t_min=c.t_min, t_max=c.t_max, query="any", cull=cull)
    assert r["triangle"].dtype == np.uint32 and r["t"].dtype == np.float32
    check_any(c.truth(layout, cull), r["t"], r["triangle"], f"{name} {layout} any cull={cull}", c.origins, c.directions)


@pytest.mark.parametrize("max_hits", [2, 4096])
@pytest.mark.parametrize("cull", CULLS)
@pytest.mark.parametrize("layout", LAYOUTS)
@pytest.mark.parametrize("name", MESH_NAMES)
def test_blob_all(name, layout, cull, max_hits):
    c = case(name)
    r = blob(name, layout).cast(c.origins, c.directions, t_min=c.t_min, t_max=c.t_max, query="all", cull=cull,
                                max_hits=max_hits)
    assert r["found"].dtype == np.uint32 and r["offsets"].dtype == np.int64
    assert r["t"].dtype == np.float32 and r["triangle"].dtype == np.uint32
    check_all(c.truth(layout, cull), r["found"], r["offsets"], r["t"], r["triangle"], max_hits,
              f"{name} {layout} all cull={cull} max_hits={max_hits}", c.origins, c.directions)


@pytest.mark.parametrize("layout", [name for name in meshcast.layouts() if name.endswith("/Float3")])
def test_every_tree_family(layout):
    """Each tree family (the float32 corners kept exactly) on the soup: the
    three queries, culling back faces."""
    c = case("soup")
    b = meshcast.build(c.vertices, c.triangles, layout=layout)
    assert b.layout == layout
    truth = c.truth(layout, "back")
    kw = dict(t_min=c.t_min, t_max=c.t_max, cull="back")
    r = b.cast(c.origins, c.directions, **kw)
    check_closest(truth, r["t"], r["triangle"], f"soup {layout} closest", c.origins, c.directions)
    r = b.cast(c.origins, c.directions, query="any", **kw)
    check_any(truth, r["t"], r["triangle"], f"soup {layout} any", c.origins, c.directions)
    r = b.cast(c.origins, c.directions, query="all", max_hits=3, **kw)
    check_all(truth, r["found"], r["offsets"], r["t"], r["triangle"], 3, f"soup {layout} all", c.origins, c.directions)


@pytest.mark.parametrize("layout", [DEFAULT_LAYOUT, FLOAT3_LAYOUT])
def test_blob_scalar_t_range_and_leading_shape(layout):
    """Scalar t_min/t_max, and rays of leading shape (40, 50): answers of that shape."""
    c = case("sphere")
    o, d = c.origins[:2000].reshape(40, 50, 3), c.directions[:2000].reshape(40, 50, 3)
    r = blob("sphere", layout).cast(o, d, t_min=0.1, t_max=2.5)
    assert r["t"].shape == (40, 50) and r["triangle"].shape == (40, 50)
    truth = c.truth(layout, t_min=0.1, t_max=2.5)
    check_closest(truth, r["t"], r["triangle"], f"sphere {layout} scalar t range", c.origins, c.directions)
    # Per-ray t ranges of the rays' leading shape.
    r2 = blob("sphere", layout).cast(o, d, t_min=c.t_min[:2000].reshape(40, 50), t_max=c.t_max[:2000].reshape(40, 50))
    assert r2["t"].shape == (40, 50)
    check_closest(c.truth(layout), r2["t"], r2["triangle"], f"sphere {layout} t range (40, 50)", c.origins, c.directions)
    a = blob("sphere", layout).cast(o, d, t_min=0.1, t_max=2.5, query="all")
    assert a["found"].shape == (2000,) and a["offsets"].shape == (2001,)
    check_all(truth, a["found"], a["offsets"], a["t"], a["triangle"], 16, f"sphere {layout} all, leading shape",
              c.origins, c.directions)


@pytest.mark.parametrize("layout", [DEFAULT_LAYOUT, FLOAT3_LAYOUT])
@pytest.mark.parametrize("query", ["closest", "any", "all"])
def test_blob_uv(layout, query):
    """uv: point = (1-u-v) a + u b + v c is the hit point o + t d, and u, v, 1-u-v >= 0
    (up to how far the layout may move a corner)."""
    c = case("soup")
    b = blob("soup", layout)
    r = b.cast(c.origins, c.directions, query=query, uv=True)
    plain = b.cast(c.origins, c.directions, query=query)
    for key in plain:
        np.testing.assert_array_equal(r[key], plain[key], err_msg=f"uv=True changed {key}")
    uv = r["uv"]
    assert uv.dtype == np.float32
    if query != "all":
        assert uv.shape == (len(c.origins), 2)
        hit = r["triangle"] != NO_HIT
        ray = np.nonzero(hit)[0]
    else:
        assert uv.shape == (len(r["t"]), 2)
        ray = np.repeat(np.arange(len(c.origins)), np.diff(r["offsets"]))
        hit = np.ones(len(r["t"]), dtype=bool)
    assert hit.sum() > 100
    tri = r["triangle"][hit].astype(np.int64)
    u, v = uv[hit, 0].astype(np.float64), uv[hit, 1].astype(np.float64)
    a, bb, cc = oracle.triangle_geometry(c.vertices, c.triangles[tri])
    p = (1 - u - v)[:, None] * a + u[:, None] * bb + v[:, None] * cc
    q = c.origins[ray].astype(np.float64) + r["t"][hit, None].astype(np.float64) * c.directions[ray]
    diag = oracle.mesh_diagonal(c.vertices)
    tol = (LOSSY_DELTA if layout != FLOAT3_LAYOUT else 1e-6) * diag * 4
    err = np.linalg.norm(p - q, axis=1)
    assert np.max(err) <= tol, f"uv's point off the hit point by {np.max(err)} (ray {ray[np.argmax(err)]})"
    # Barycentrics of the stored corners: inside, up to the corners' movement.
    assert np.min(np.minimum(np.minimum(u, v), 1 - u - v)) >= -1e-3


# ---- Scene.cast -------------------------------------------------------------

def scene_world(layout):
    """A scene of three instances of two meshes: the soup as it is, the sphere
    turned and moved, the sphere mirrored, scaled unevenly and moved."""
    sv, sf = shapes.sphere()
    pv, pf = shapes.soup(n=200, seed=3)
    mirror = np.diag([-1.0, 1.0, 1.0]) @ np.diag([1.5, 0.75, 1.25]) @ rotation(5).astype(np.float64)
    parts = [
        (pv, pf, None, (0.0, 0.0, 0.0), False),
        (sv, sf, rotation(4), (3.0, -1.0, 0.5), False),
        (sv, sf, mirror.astype(np.float32), (-2.5, 2.0, -1.0), False),
    ]
    scene = meshcast.Scene()
    mesh_ids = [scene.add_mesh(meshcast.build(pv, pf, layout=layout)), scene.add_mesh(meshcast.build(sv, sf, layout=layout))]
    for (v, f, m, tr, flip), mesh_id in zip(parts, [mesh_ids[0], mesh_ids[1], mesh_ids[1]]):
        scene.add_instance(mesh_id, rotation_scale=m, translation=tr, flip_facing=flip)
    scene.commit()
    world = World([(v, f, m, tr, flip, 0.0 if layout == FLOAT3_LAYOUT else LOSSY_DELTA * oracle.mesh_diagonal(v))
                   for v, f, m, tr, flip in parts])
    return scene, world


_scenes = {}


def scene_case(layout):
    if layout not in _scenes:
        scene, world = scene_world(layout)
        o, d = shapes.rays(world.vertices, 1500, seed=11)
        _scenes[layout] = (scene, world, o, d, world.candidates(o, d))
    return _scenes[layout]


@pytest.mark.parametrize("origin_dtype", [np.float32, np.float64])
@pytest.mark.parametrize("query", ["closest", "any", "all"])
@pytest.mark.parametrize("cull", CULLS)
@pytest.mark.parametrize("layout", [DEFAULT_LAYOUT, FLOAT3_LAYOUT])
def test_scene_cast(layout, cull, query, origin_dtype):
    scene, world, o, d, cands = scene_case(layout)
    t_max = np.float32(7.0)
    truth = oracle.classify(cands, 0.0, t_max, cull)
    what = f"scene {layout} {query} cull={cull} origins {np.dtype(origin_dtype).name}"
    r = scene.cast(o.astype(origin_dtype), d, t_max=t_max, query=query, cull=cull)
    if query == "all":
        assert r["instance"].dtype == np.uint32
        tri = world.global_ids(r["instance"], r["triangle"])
        check_all(truth, r["found"], r["offsets"], r["t"], tri, 16, what, o, d)
        return
    assert r["t"].shape == r["instance"].shape == r["triangle"].shape == (len(o),)
    tri = world.global_ids(r["instance"], r["triangle"])
    if query == "closest":
        check_closest(truth, r["t"], tri, what, o, d)
    else:
        check_any(truth, r["t"], tri, what, o, d)


# ---- RaycastingScene ----------------------------------------------------------

_rc = {}


def raycasting_case():
    """Two geometries: the sphere moved off the origin and the soup."""
    if not _rc:
        sv, sf = shapes.sphere()
        pv, pf = shapes.soup(n=250, seed=9)
        sv = (sv.astype(np.float64) + [1.0, 2.0, -0.5]).astype(np.float32)
        scene = meshcast.RaycastingScene()
        assert scene.add_triangles(sv, sf) == 0
        assert scene.add_triangles(pv, pf) == 1
        world = World([(v, f, None, (0, 0, 0), False, LOSSY_DELTA * oracle.mesh_diagonal(v)) for v, f in ((sv, sf), (pv, pf))])
        o, d = shapes.rays(world.vertices, 2000, seed=21)
        _rc.update(scene=scene, world=world, o=o, d=d, cands=world.candidates(o, d))
    return _rc


def as_array(x):
    """Results answer .numpy() as Open3D tensors do; either way an ndarray."""
    return x.numpy() if hasattr(x, "numpy") else np.asarray(x)


def test_raycasting_cast_rays():
    rc = raycasting_case()
    world, o, d = rc["world"], rc["o"], rc["d"]
    r = rc["scene"].cast_rays(rays6(o, d))
    for key in ("t_hit", "geometry_ids", "primitive_ids", "primitive_uvs", "primitive_normals"):
        plain = r[key].numpy()  # as Open3D's tensors answer
        assert type(plain) is np.ndarray, f"{key}.numpy() is a {type(plain)}"
    t, geo, prim = as_array(r["t_hit"]), as_array(r["geometry_ids"]), as_array(r["primitive_ids"])
    uvs, nrm = as_array(r["primitive_uvs"]), as_array(r["primitive_normals"])
    assert t.dtype == np.float32 and geo.dtype == np.uint32 and prim.dtype == np.uint32
    assert uvs.shape == (len(o), 2) and nrm.shape == (len(o), 3)
    assert meshcast.RaycastingScene.INVALID_ID == NO_HIT
    miss = prim == NO_HIT
    assert np.all(geo[miss] == NO_HIT) and np.all(np.isinf(t[miss]))
    assert np.all(uvs[miss] == 0) and np.all(nrm[miss] == 0)
    truth = oracle.classify(rc["cands"], 0.0, np.inf, "none")
    tri = world.global_ids(geo, prim)
    check_closest(truth, t, tri, "RaycastingScene.cast_rays", o, d)
    # Normals: the unit geometric normal of the triangle hit.
    hit = ~miss
    expect = oracle.normals(world.vertices, world.triangles[tri[hit]])
    np.testing.assert_allclose(np.linalg.norm(nrm[hit], axis=1), 1.0, atol=1e-5)
    assert np.min(np.einsum("ij,ij->i", nrm[hit].astype(np.float64), expect)) > 0.999
    # UVs: the barycentrics of the hit point.
    a, b, c = oracle.triangle_geometry(world.vertices, world.triangles[tri[hit]])
    u, v = uvs[hit, 0:1].astype(np.float64), uvs[hit, 1:2].astype(np.float64)
    p = (1 - u - v) * a + u * b + v * c
    q = o[hit].astype(np.float64) + t[hit, None].astype(np.float64) * d[hit]
    assert np.max(np.linalg.norm(p - q, axis=1)) <= 4 * LOSSY_DELTA * oracle.mesh_diagonal(world.vertices)


def test_raycasting_cast_rays_float64_rays():
    """float64 rays: the same answers (the rays hold float32 values)."""
    rc = raycasting_case()
    r32 = rc["scene"].cast_rays(rays6(rc["o"], rc["d"]))
    r64 = rc["scene"].cast_rays(rays6(rc["o"], rc["d"], np.float64))
    for key in ("t_hit", "geometry_ids", "primitive_ids"):
        np.testing.assert_array_equal(as_array(r32[key]), as_array(r64[key]), err_msg=key)


@pytest.mark.parametrize("tnear, tfar", [(0.0, np.inf), (0.2, 3.0)])
def test_raycasting_test_occlusions(tnear, tfar):
    rc = raycasting_case()
    o, d = rc["o"], rc["d"]
    occ = as_array(rc["scene"].test_occlusions(rays6(o, d), tnear=tnear, tfar=tfar))
    assert occ.dtype == np.bool_ and occ.shape == (len(o),)
    truth = oracle.classify(rc["cands"], tnear, tfar, "none")
    assert truth.clean.mean() > 0.85
    expected = truth.count > 0
    bad = np.nonzero(truth.clean & (occ != expected))[0]
    assert len(bad) == 0, f"{len(bad)} rays wrong, first ray {bad[0]}: expected {expected[bad[0]]}"


def test_raycasting_count_intersections():
    rc = raycasting_case()
    o, d = rc["o"], rc["d"]
    n = as_array(rc["scene"].count_intersections(rays6(o, d)))
    assert n.dtype == np.int32 and n.shape == (len(o),)
    truth = oracle.classify(rc["cands"], 0.0, np.inf, "none")
    bad = np.nonzero(truth.clean & (n != truth.count))[0]
    assert len(bad) == 0, f"{len(bad)} rays wrong, first ray {bad[0]}: {n[bad[0]]}, expected {truth.count[bad[0]]}"
    assert truth.count.max() >= 2, "some ray crosses several triangles"


def test_raycasting_list_intersections():
    rc = raycasting_case()
    world, o, d = rc["world"], rc["o"], rc["d"]
    r = rc["scene"].list_intersections(rays6(o, d))
    splits, ray_ids = as_array(r["ray_splits"]), as_array(r["ray_ids"])
    geo, prim, t = as_array(r["geometry_ids"]), as_array(r["primitive_ids"]), as_array(r["t_hit"])
    uvs = as_array(r["primitive_uvs"])
    assert splits.dtype == np.uint32 and splits.shape == (len(o) + 1,)
    for x in (ray_ids, geo, prim):
        assert x.dtype == np.uint32
    h = len(t)
    assert ray_ids.shape == geo.shape == prim.shape == (h,) and uvs.shape == (h, 2) and t.dtype == np.float32
    assert splits[0] == 0 and splits[-1] == h
    np.testing.assert_array_equal(ray_ids, np.repeat(np.arange(len(o)), np.diff(splits.astype(np.int64))))
    found = np.diff(splits.astype(np.int64))
    truth = oracle.classify(rc["cands"], 0.0, np.inf, "none")
    # Every hit listed (none dropped): found is the count, max_hits the largest count.
    check_all(truth, found, splits.astype(np.int64), t, world.global_ids(geo, prim), max(1, int(found.max())),
              "RaycastingScene.list_intersections", o, d)


@pytest.mark.parametrize("name", MESH_NAMES)
def test_blob_one_origin_packets_answer_as_single_rays(name):
    # Rays of one origin walk as packets on the recommended layout; with
    # packets="off" one at a time: the same bits (the oracle judges the
    # single rays in the tests above).
    c = case(name)
    b = blob(name, DEFAULT_LAYOUT)
    origin = c.origins[0]
    rng = np.random.default_rng(5)
    directions = rng.normal(size=(3000, 3)).astype(np.float32)
    for query in ["closest", "any"]:
        for cull in ["none", "back"]:
            packed = b.cast(origin, directions, query=query, cull=cull, uv=query == "closest")
            alone = b.cast(origin, directions, query=query, cull=cull, uv=query == "closest", packets="off")
            if query == "closest":
                for key in packed:
                    np.testing.assert_array_equal(packed[key], alone[key], err_msg=f"{name} {key} cull={cull}")
            else:
                np.testing.assert_array_equal(packed["triangle"] == NO_HIT, alone["triangle"] == NO_HIT)
    with pytest.raises(ValueError, match="packets \"sometimes\": auto or off"):
        b.cast(origin, directions, packets="sometimes")
