"""Meshes and rays far from the origin, in float64.

T = (1e7, -3e7, 2e7) is a multiple of 128 on each axis, and the test mesh's
and rays' origins are float32 values below 2^6 on a grid of 2^-16, so v + T
and o + T are exact in float64: the shifted problem is the same problem, and
a double-precision path must give the same answers."""

import numpy as np

import meshcast
import shapes
from cases import NO_HIT, rays6

T = np.array([1e7, -3e7, 2e7])
assert np.all(T % 128 == 0)


def dyadic(x):
    """On a grid of 2^-16: below 2^6 that is 22 significant bits (exact in
    float32), and 2^25 + x needs 41 (exact in float64)."""
    return (np.round(np.asarray(x, dtype=np.float64) * 65536) / 65536).astype(np.float32)


def problem():
    sv, sf = shapes.sphere(rings=10, segments=16, radius=1.5, centre=(0.25, -0.5, 0.75))
    pv, pf = shapes.soup(n=120, seed=4, extent=3.0, size=0.5)
    v = dyadic(np.concatenate([sv, pv]))
    f = np.concatenate([sf, pf + len(sv)]).astype(np.uint32)
    o, d = shapes.rays(v, 1500, seed=17)
    return v, f, dyadic(o), d


def shifted(x):
    y = np.asarray(x, dtype=np.float64) + T
    assert np.array_equal(y - T, np.asarray(x, dtype=np.float64)), "the shift is not exact"
    return y


def as_array(x):
    return x.numpy() if hasattr(x, "numpy") else np.asarray(x)


def test_raycasting_scene_far_float64():
    v, f, o, d = problem()
    near = meshcast.RaycastingScene()
    near.add_triangles(v.astype(np.float64), f)
    far = meshcast.RaycastingScene()
    far.add_triangles(shifted(v), f)
    a = near.cast_rays(rays6(o, d, np.float64))
    b = far.cast_rays(np.concatenate([shifted(o), d.astype(np.float64)], axis=1))
    pa, pb = as_array(a["primitive_ids"]), as_array(b["primitive_ids"])
    assert np.mean(pa != NO_HIT) > 0.3
    np.testing.assert_array_equal(pa, pb)
    ta, tb = as_array(a["t_hit"]), as_array(b["t_hit"])
    hit = pa != NO_HIT
    np.testing.assert_allclose(tb[hit], ta[hit], rtol=1e-6, atol=0)
    # The other queries agree too.
    ra = rays6(o, d, np.float64)
    rb = np.concatenate([shifted(o), d.astype(np.float64)], axis=1)
    np.testing.assert_array_equal(as_array(near.count_intersections(ra)), as_array(far.count_intersections(rb)))
    np.testing.assert_array_equal(as_array(near.test_occlusions(ra, tfar=2.0)), as_array(far.test_occlusions(rb, tfar=2.0)))


def test_float32_rays_lose_far_out():
    """The float32 peer: the same far rays rounded to float32 (a spacing of 1
    to 2 units at 1e7..3e7, while the mesh is 3 units across) land elsewhere,
    so most hits change. This is what the float64 path is for."""
    v, f, o, d = problem()
    far = meshcast.RaycastingScene()
    far.add_triangles(shifted(v), f)
    r64 = np.concatenate([shifted(o), d.astype(np.float64)], axis=1)
    exact = as_array(far.cast_rays(r64)["primitive_ids"])
    lossy = as_array(far.cast_rays(r64.astype(np.float32))["primitive_ids"])
    assert np.mean(exact != lossy) > 0.3


def test_scene_instance_far_translation():
    v, f, o, d = problem()
    b = meshcast.build(v, f)
    near, far = meshcast.Scene(), meshcast.Scene()
    for s, tr in ((near, (0.0, 0.0, 0.0)), (far, tuple(T))):
        s.add_instance(s.add_mesh(b), translation=tr)
        s.commit()
    for query in ("closest", "all"):
        a = near.cast(o.astype(np.float64), d, query=query)
        c = far.cast(shifted(o), d, query=query)
        if query == "all":
            np.testing.assert_array_equal(a["found"], c["found"])
            np.testing.assert_array_equal(a["offsets"], c["offsets"])
        else:
            assert np.mean(a["triangle"] != NO_HIT) > 0.3
            np.testing.assert_array_equal(a["instance"], c["instance"])
        np.testing.assert_array_equal(a["triangle"], c["triangle"])
        np.testing.assert_allclose(c["t"], a["t"], rtol=1e-6, atol=0)
    # float32 origins far out: rounded, so the answers move (see above).
    lossy = far.cast(shifted(o).astype(np.float32), d)
    exact = far.cast(shifted(o), d)
    assert np.mean(lossy["triangle"] != exact["triangle"]) > 0.3


def test_raycasting_scene_two_far_geometries():
    """Two geometries far apart, each about its own centre: rays at each
    answer as the geometry alone at the origin does."""
    v, f, o, d = problem()
    t2 = np.array([-2e7, 1e7, 3e7])  # multiples of 128 too
    near = meshcast.RaycastingScene()
    near.add_triangles(v.astype(np.float64), f)
    far = meshcast.RaycastingScene()
    assert far.add_triangles(shifted(v), f) == 0
    assert far.add_triangles(v.astype(np.float64) + t2, f) == 1
    ref = near.cast_rays(rays6(o, d, np.float64))
    for shift, geometry in ((T, 0), (t2, 1)):
        r = far.cast_rays(np.concatenate([o.astype(np.float64) + shift, d.astype(np.float64)], axis=1))
        prim = as_array(r["primitive_ids"])
        np.testing.assert_array_equal(prim, as_array(ref["primitive_ids"]))
        hit = prim != NO_HIT
        np.testing.assert_array_equal(as_array(r["geometry_ids"])[hit], geometry)
        np.testing.assert_allclose(as_array(r["t_hit"])[hit], as_array(ref["t_hit"])[hit], rtol=1e-6, atol=0)
