"""Blobs on disk, the module's descriptions of itself, reading meshes."""

import os

import numpy as np
import pytest

import meshcast
import shapes
from cases import DEFAULT_LAYOUT, FLOAT3_LAYOUT


@pytest.fixture(scope="module")
def sphere():
    v, f = shapes.sphere()
    o, d = shapes.rays(v, 800, seed=4)
    return v, f, o, d


def same(a, b):
    for k in a:
        np.testing.assert_array_equal(np.asarray(a[k]), np.asarray(b[k]), err_msg=k)


@pytest.mark.parametrize("layout", [DEFAULT_LAYOUT, FLOAT3_LAYOUT])
def test_save_load_round_trip(sphere, tmp_path, layout):
    v, f, o, d = sphere
    b = meshcast.build(v, f, layout=layout)
    assert b.layout == layout and b.triangle_count == len(f) and not b.mapped
    path = tmp_path / "sphere.mcb"
    b.save(str(path))
    assert os.path.getsize(path) == b.nbytes
    loaded = meshcast.load(str(path))
    assert not loaded.mapped, "load reads the file into memory"
    mapped = meshcast.load(str(path), mmap=True)
    assert mapped.mapped, "load(mmap=True) maps the file"
    for blob in (loaded, mapped):
        assert blob.layout == b.layout and blob.triangle_count == b.triangle_count and blob.nbytes == b.nbytes
        for query in ("closest", "any", "all"):
            same(b.cast(o, d, query=query, uv=True), blob.cast(o, d, query=query, uv=True))
    # Saved again, the same bytes.
    loaded.save(str(tmp_path / "again.mcb"))
    assert (tmp_path / "again.mcb").read_bytes() == path.read_bytes()
    # A loaded blob serves a scene.
    s = meshcast.Scene()
    s.add_instance(s.add_mesh(loaded))
    s.commit()
    r = s.cast(o, d)
    np.testing.assert_array_equal(r["triangle"], b.cast(o, d)["triangle"])


def test_loaded_blob_outlives_its_file_name(sphere, tmp_path):
    """The mapping stays valid after the file is removed (POSIX keeps it)."""
    v, f, o, d = sphere
    b = meshcast.build(v, f)
    path = tmp_path / "gone.mcb"
    b.save(str(path))
    loaded = meshcast.load(str(path), mmap=True)
    os.remove(path)
    same(b.cast(o, d), loaded.cast(o, d))


def test_layouts_and_features():
    names = meshcast.layouts()
    assert isinstance(names, list) and DEFAULT_LAYOUT in names and FLOAT3_LAYOUT in names
    assert "auto" not in names
    assert all(isinstance(n, str) and "/" in n for n in names)
    assert isinstance(meshcast.features, dict)
    for key in ("vulkan", "reader"):
        assert isinstance(meshcast.features[key], bool)
    assert isinstance(meshcast.__version__, str) and meshcast.__version__
    assert meshcast.NO_HIT == 0xFFFFFFFF


def test_auto_layout_is_listed(sphere):
    v, f, o, d = sphere
    b = meshcast.build(v, f, layout="auto")
    assert b.layout in meshcast.layouts()


def test_max_bytes(sphere):
    v, f, o, d = sphere
    b = meshcast.build(v, f, layout="auto", max_bytes=40 * len(f))
    assert b.nbytes <= 40 * len(f)
    with pytest.raises(ValueError):
        meshcast.build(v, f, layout="auto", max_bytes=64)  # nothing fits in 64 bytes


def test_build_threads_same_bytes(sphere, tmp_path):
    v, f, o, d = sphere
    a = meshcast.build(v, f, threads=1)
    b = meshcast.build(v, f, threads=2)
    a.save(str(tmp_path / "a.mcb"))
    b.save(str(tmp_path / "b.mcb"))
    assert (tmp_path / "a.mcb").read_bytes() == (tmp_path / "b.mcb").read_bytes()


def test_read_mesh(tmp_path):
    if not meshcast.features.get("reader"):
        pytest.skip("meshcast built without the mesh reader")
    v, f = shapes.sphere(rings=5, segments=7)
    path = tmp_path / "s.off"
    with open(path, "w") as fh:
        fh.write(f"OFF\n{len(v)} {len(f)} 0\n")
        for p in v:
            fh.write("%.9g %.9g %.9g\n" % tuple(float(x) for x in p))
        for t in f:
            fh.write("3 %d %d %d\n" % tuple(int(x) for x in t))
    rv, rf = meshcast.read_mesh(str(path))
    assert rv.dtype == np.float32 and rv.shape == v.shape
    assert rf.dtype == np.uint32 and rf.shape == f.shape
    np.testing.assert_array_equal(rv, v)  # %.9g round-trips a float32
    np.testing.assert_array_equal(rf, f)  # the file's own triangle order
    with pytest.raises(OSError):
        meshcast.read_mesh(str(tmp_path / "missing.off"))


def test_read_mesh_bunny_matches_plain_reader():
    if not meshcast.features.get("reader") or not os.path.exists(shapes.BUNNY):
        pytest.skip("no reader or no bunny00.off")
    rv, rf = meshcast.read_mesh(shapes.BUNNY)
    pv, pf = shapes.read_off(shapes.BUNNY)
    assert rf.shape == pf.shape
    # The same corners in the file's triangle order (a decimal reader may
    # round the last bit otherwise).
    np.testing.assert_allclose(rv[rf.astype(np.int64)], pv[pf.astype(np.int64)], rtol=1e-6, atol=1e-7)
