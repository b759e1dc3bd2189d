"""Array handling: out= buffers, strides and memory orders, dtypes."""

import numpy as np
import pytest

import meshcast
import shapes
from cases import DEFAULT_LAYOUT, NO_HIT, rays6


@pytest.fixture(scope="module")
def soup():
    v, f = shapes.soup(n=200, seed=2)
    o, d = shapes.rays(v, 1000, seed=5)
    return v, f, o, d, meshcast.build(v, f)


def assert_same(a, b, keys=None):
    for k in keys or a.keys():
        np.testing.assert_array_equal(np.asarray(a[k]), np.asarray(b[k]), err_msg=k)


# ---- out= -------------------------------------------------------------------

@pytest.mark.parametrize("query", ["closest", "any"])
@pytest.mark.parametrize("uv", [False, True])
def test_blob_out_written_in_place(soup, query, uv):
    v, f, o, d, b = soup
    n = len(o)
    out = {"t": np.full(n, -7, np.float32), "triangle": np.full(n, 7, np.uint32)}
    if uv:
        out["uv"] = np.full((n, 2), -7, np.float32)
    r = b.cast(o, d, query=query, uv=uv, out=out)
    for k in out:
        assert r[k] is out[k], f"out[{k!r}] not returned as given"
    assert_same(r, b.cast(o, d, query=query, uv=uv))
    assert np.any(out["triangle"] != NO_HIT) and np.any(out["triangle"] == NO_HIT)


def test_blob_out_leading_shape(soup):
    v, f, o, d, b = soup
    o2, d2 = o[:600].reshape(20, 30, 3), d[:600].reshape(20, 30, 3)
    out = {"t": np.empty((20, 30), np.float32), "triangle": np.empty((20, 30), np.uint32)}
    r = b.cast(o2, d2, out=out)
    assert r["t"] is out["t"]
    assert_same(r, b.cast(o2, d2))


@pytest.mark.parametrize("bad", ["short t", "long triangle", "float64 t", "int32 triangle", "2-D t", "short uv",
                                 "float64 uv"])
def test_blob_out_refused(soup, bad):
    v, f, o, d, b = soup
    n = len(o)
    out = {"t": np.empty(n, np.float32), "triangle": np.empty(n, np.uint32)}
    uv = False
    if bad == "short t":
        out["t"] = np.empty(n - 1, np.float32)
    elif bad == "long triangle":
        out["triangle"] = np.empty(n + 1, np.uint32)
    elif bad == "float64 t":
        out["t"] = np.empty(n, np.float64)
    elif bad == "int32 triangle":
        out["triangle"] = np.empty(n, np.int32)
    elif bad == "2-D t":
        out["t"] = np.empty((n, 1), np.float32)
    elif bad == "short uv":
        out["uv"], uv = np.empty((n, 1), np.float32), True
    elif bad == "float64 uv":
        out["uv"], uv = np.empty((n, 2), np.float64), True
    with pytest.raises(ValueError):
        b.cast(o, d, out=out, uv=uv)


def test_blob_out_refused_for_all(soup):
    v, f, o, d, b = soup
    n = len(o)
    with pytest.raises(ValueError):
        b.cast(o, d, query="all", out={"t": np.empty(n, np.float32), "triangle": np.empty(n, np.uint32)})


def test_scene_out_written_in_place(soup):
    v, f, o, d, b = soup
    s = meshcast.Scene()
    s.add_instance(s.add_mesh(b), translation=(0.5, 0.0, 0.0))
    s.commit()
    n = len(o)
    out = {"t": np.empty(n, np.float32), "instance": np.empty(n, np.uint32), "triangle": np.empty(n, np.uint32)}
    r = s.cast(o, d, out=out)
    for k in out:
        assert r[k] is out[k]
    assert_same(r, s.cast(o, d))
    with pytest.raises(ValueError):
        s.cast(o, d, out={"t": np.empty(n, np.float32), "instance": np.empty(n, np.float32),
                          "triangle": np.empty(n, np.uint32)})


# ---- strides, memory order and dtypes of the inputs ---------------------------

def test_noncontiguous_rays(soup):
    v, f, o, d, b = soup
    ref = b.cast(o, d, t_max=np.full(len(o), 5.0, np.float32))
    # Every other row of a larger array, and columns of (3, N) arrays transposed.
    big_o = np.zeros((2 * len(o), 3), np.float32)
    big_o[::2] = o
    big_d = np.zeros((2 * len(o), 5), np.float32)
    big_d[::2, 1:4] = d
    tmax = np.zeros(2 * len(o), np.float32)
    tmax[::2] = 5.0
    strided = b.cast(big_o[::2], big_d[::2, 1:4], t_max=tmax[::2])
    assert_same(ref, strided)
    transposed = b.cast(np.ascontiguousarray(o.T).T, np.asfortranarray(d), t_max=tmax[::2])
    assert_same(ref, transposed)
    reversed_rows = b.cast(o[::-1], d[::-1], t_max=tmax[::2])
    assert_same(ref, {k: x[::-1] for k, x in reversed_rows.items()})


def test_noncontiguous_rays_all(soup):
    v, f, o, d, b = soup
    ref = b.cast(o, d, query="all")
    assert_same(ref, b.cast(np.asfortranarray(o), np.ascontiguousarray(d.T).T, query="all"))


def test_float64_rays_same_as_float32(soup):
    """The rays hold float32 values: float64 copies are the same rays."""
    v, f, o, d, b = soup
    for query in ("closest", "any", "all"):
        assert_same(b.cast(o, d, query=query), b.cast(o.astype(np.float64), d.astype(np.float64), query=query))
    assert_same(b.cast(o, d, t_max=np.float32(3.0)), b.cast(o, d.astype(np.float64), t_max=np.full(len(o), 3.0)))


def test_other_real_dtypes_converted():
    """float16 and integer rays are converted (to float32) and answer as float32 would."""
    v, f = shapes.grid(8, 8)
    b = meshcast.build(v, f, layout="AABBTree/Float3")  # exact corners: t exactly 3 and 2
    o = np.array([[1, 1, 3], [2, 5, 4], [7, 7, -2], [20, 20, 5]], dtype=np.float32) + [0.5, 0.25, 0]
    d = np.array([[0, 0, -1], [0, 0, -2], [0, 0, 1], [0, 0, -1]], dtype=np.float32)
    ref = b.cast(o, d)
    assert_same(ref, b.cast(o.astype(np.float16), d.astype(np.int32)))
    np.testing.assert_array_equal(ref["t"], [3, 2, 2, np.inf])


def test_noncontiguous_raycasting_rays(soup):
    v, f, o, d, b = soup
    rc = meshcast.RaycastingScene()
    rc.add_triangles(v, f)
    r = rays6(o, d)
    ref = rc.cast_rays(r)
    wide = np.zeros((len(o), 9), np.float32)
    wide[:, 2:8] = r
    for rays in (wide[:, 2:8], np.asfortranarray(r), r.astype(np.float64)[:, ::1]):
        got = rc.cast_rays(rays)
        for k in ("t_hit", "primitive_ids", "geometry_ids"):
            np.testing.assert_array_equal(np.asarray(got[k]), np.asarray(ref[k]), err_msg=k)
    np.testing.assert_array_equal(np.asarray(rc.count_intersections(wide[:, 2:8])), np.asarray(rc.count_intersections(r)))


def blob_bytes(b, path):
    b.save(str(path))
    return path.read_bytes()


def test_triangle_index_dtypes_same_blob(soup, tmp_path):
    v, f, o, d, b = soup
    ref = blob_bytes(b, tmp_path / "ref.mcb")
    for dtype in (np.int32, np.uint32, np.int64):
        got = blob_bytes(meshcast.build(v, f.astype(dtype)), tmp_path / f"{np.dtype(dtype).name}.mcb")
        assert got == ref, f"triangles as {np.dtype(dtype).name} built other bytes"
    # Non-contiguous triangles too.
    wide = np.zeros((len(f), 4), np.int64)
    wide[:, 1:] = f
    assert blob_bytes(meshcast.build(v, wide[:, 1:]), tmp_path / "strided.mcb") == ref


def test_vertex_dtypes_same_blob(soup, tmp_path):
    v, f, o, d, b = soup
    ref = blob_bytes(b, tmp_path / "ref.mcb")
    assert blob_bytes(meshcast.build(v.astype(np.float64), f), tmp_path / "f64.mcb") == ref
    assert blob_bytes(meshcast.build(np.asfortranarray(v), f), tmp_path / "fortran.mcb") == ref
    # Float3 stores the float32 vertices: the answers match too.
    b32 = meshcast.build(v, f, layout="AABBTree/Float3")
    b64 = meshcast.build(v.astype(np.float64), f, layout="AABBTree/Float3")
    assert_same(b32.cast(o, d), b64.cast(o, d))


def test_inputs_copied_not_kept(soup):
    """build and add_triangles read the arrays during the call: changing
    them afterwards changes nothing."""
    v, f, o, d, b = soup
    ref = b.cast(o, d)
    v2, f2 = v.copy(), f.copy()
    b2 = meshcast.build(v2, f2)
    rc = meshcast.RaycastingScene()
    rc.add_triangles(v2, f2)
    ref_rc = rc.cast_rays(rays6(o, d))
    v2[:] = 0
    f2[:] = 0
    assert_same(ref, b2.cast(o, d))
    got = rc.cast_rays(rays6(o, d))
    for k in ("t_hit", "primitive_ids"):
        np.testing.assert_array_equal(np.asarray(got[k]), np.asarray(ref_rc[k]), err_msg=k)


def test_other_byte_orders_are_converted():
    """Big-endian arrays (a '>f4' file read with np.fromfile) answer as the
    native ones: read in their byte order, not reinterpreted."""
    v, f = shapes.grid(4, 4)
    blob = meshcast.build(v, f, layout=DEFAULT_LAYOUT)
    big = meshcast.build(np.asarray(v, ">f4"), np.asarray(f, ">i8"), layout=DEFAULT_LAYOUT)
    assert big.to_bytes() == blob.to_bytes()
    o = np.array([[0.5, 0.5, 2.0], [1.5, 2.5, 3.0]])
    d = np.array([[0, 0, -1.0], [0, 0, -2.0]])
    want = blob.cast(o, d)
    for order in (">f4", ">f8"):
        got = blob.cast(o.astype(order), d.astype(order), t_max=np.array([5, 5], order))
        np.testing.assert_array_equal(got["t"], want["t"])
        np.testing.assert_array_equal(got["triangle"], want["triangle"])
    rc = meshcast.RaycastingScene()
    rc.add_triangles(np.asarray(v, ">f8"), f)
    np.testing.assert_array_equal(np.asarray(rc.cast_rays(np.concatenate([o, d], 1).astype(">f4"))["t_hit"]), want["t"])


def test_whole_numbers_as_segment_ends():
    """t_min and t_max as Python ints or numpy scalars of any real type are
    numbers for every ray, not one-element arrays."""
    v, f = shapes.grid(4, 4)
    blob = meshcast.build(v, f, layout=DEFAULT_LAYOUT)
    o = np.array([[0.5, 0.5, 2.0], [1.5, 2.5, 3.0], [2.5, 0.5, 9.0]])
    d = np.array([[0, 0, -1.0], [0, 0, -1.0], [0, 0, -1.0]])
    for t_max in (5, np.float16(5), np.int32(5), 5.0):
        got = blob.cast(o, d, t_max=t_max, t_min=1)
        np.testing.assert_array_equal(got["t"], [2.0, 3.0, np.inf])
    rc = meshcast.RaycastingScene()
    rc.add_triangles(v, f)
    np.testing.assert_array_equal(np.asarray(rc.test_occlusions(np.concatenate([o, d], 1), tnear=0, tfar=5)),
                                  [True, True, False])
