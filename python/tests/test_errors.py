"""Bad input is refused with a ValueError naming it (files: OSError)."""

import re

import numpy as np
import pytest

import meshcast
import shapes
from cases import rays6


@pytest.fixture(scope="module")
def grid():
    v, f = shapes.grid(4, 4)
    o = np.array([[0.5, 0.5, 1], [1.5, 2.5, 1], [3.5, 0.25, 1]], np.float32)
    d = np.array([[0, 0, -1], [0, 0, -1], [0, 0, -1]], np.float32)
    return v, f, o, d, meshcast.build(v, f)


def refused(pattern, fn, *args, **kwargs):
    """fn(*args, **kwargs) raises ValueError whose message matches pattern (any case)."""
    with pytest.raises(ValueError) as e:
        fn(*args, **kwargs)
    msg = str(e.value)
    assert re.search(pattern, msg, re.I), f"message {msg!r} does not name {pattern!r}"


ORIGIN = r"origin"
DIRECTION = r"direction"


def test_ray_shapes(grid):
    v, f, o, d, b = grid
    refused(ORIGIN, b.cast, np.zeros((3, 2), np.float32), d)
    refused(ORIGIN, b.cast, np.zeros((3, 5), np.float32), d)
    refused(DIRECTION, b.cast, o, np.zeros((3, 4), np.float32))
    refused(ORIGIN + "|" + DIRECTION + "|shape", b.cast, o, d[:2])  # leading shapes differ
    refused(ORIGIN, b.cast, np.zeros(2, np.float32), d[0])
    refused(r"t_max|tmax", b.cast, o, d, t_max=np.ones(2, np.float32))
    refused(r"t_min|tmin", b.cast, o, d, t_min=np.zeros((3, 2), np.float32))


def test_raycasting_ray_shapes(grid):
    v, f, o, d, b = grid
    rc = meshcast.RaycastingScene()
    rc.add_triangles(v, f)
    for method in (rc.cast_rays, rc.test_occlusions, rc.count_intersections, rc.list_intersections):
        refused(r"ray", method, np.zeros((3, 5), np.float32))
        refused(r"ray", method, np.zeros((3, 7), np.float32))
    refused(r"vert", rc.add_triangles, v[:, :2], f)
    refused(r"triang|ind", rc.add_triangles, v, f[:, :2])


def test_mesh_shapes(grid):
    v, f, o, d, b = grid
    refused(r"vert", meshcast.build, v[:, :2], f)
    refused(r"vert", meshcast.build, np.zeros((len(v), 4), np.float32), f)
    refused(r"vert", meshcast.build, v.ravel(), f)
    refused(r"triang|ind", meshcast.build, v, f[:, :2])
    refused(r"triang|ind", meshcast.build, v, f.ravel())


@pytest.mark.parametrize("where", ["origins", "directions"])
def test_nan_rays(grid, where):
    v, f, o, d, b = grid
    o2, d2 = o.copy(), d.copy()
    (o2 if where == "origins" else d2)[1, 2] = np.nan
    refused(where[:-1], b.cast, o2, d2)
    o3, d3 = o.copy(), d.copy()
    (o3 if where == "origins" else d3)[2, 0] = -np.inf  # the package's documentation: infinite too
    refused(where[:-1], b.cast, o3, d3)
    for dtype in (np.float32, np.float64):
        refused(where[:-1] + "|ray|nan", b.cast, o2.astype(dtype), d2.astype(dtype), query="all")
    s = meshcast.Scene()
    s.add_instance(s.add_mesh(b))
    s.commit()
    refused(where[:-1], s.cast, o2.astype(np.float64), d2)
    # invalid="miss": those rays miss, the others answer as before
    for dtype in (np.float32, np.float64):
        for cast in (b.cast, s.cast):
            got = cast(o2.astype(dtype), d2, invalid="miss")
            assert np.isinf(got["t"][1]) and got["triangle"][1] == meshcast.NO_HIT
            assert np.isfinite(got["t"][[0, 2]]).all()
    refused(r"invalid", b.cast, o, d, invalid="skip")


def test_zero_direction(grid):
    v, f, o, d, b = grid
    d2 = d.copy()
    d2[2] = 0
    refused(DIRECTION, b.cast, o, d2)
    refused(DIRECTION, b.cast, o, d2, query="any")
    got = b.cast(o, d2, query="all", invalid="miss")
    assert got["found"][2] == 0 and (got["found"][:2] > 0).all()


def test_nan_vertices(grid):
    v, f, o, d, b = grid
    v2 = v.copy()
    v2[3, 1] = np.nan
    refused(r"vert", meshcast.build, v2, f)
    refused(r"vert", meshcast.RaycastingScene().add_triangles, v2.astype(np.float64), f)


@pytest.mark.parametrize("dtype", [np.int32, np.int64])
def test_negative_index(grid, dtype):
    v, f, o, d, b = grid
    f2 = f.astype(dtype)
    f2[5, 1] = -1
    refused(r"triang|ind", meshcast.build, v, f2)
    refused(r"triang|ind", meshcast.RaycastingScene().add_triangles, v, f2)


@pytest.mark.parametrize("dtype", [np.int32, np.uint32, np.int64])
def test_index_out_of_range(grid, dtype):
    v, f, o, d, b = grid
    f2 = f.astype(dtype)
    f2[7, 2] = len(v)  # one past the last vertex
    refused(r"triang|ind|vert", meshcast.build, v, f2)
    refused(r"triang|ind|vert", meshcast.RaycastingScene().add_triangles, v, f2)
    if dtype == np.int64:
        f2[7, 2] = 1 << 40  # beyond 32 bits
        refused(r"triang|ind|vert", meshcast.build, v, f2)


def test_float_triangles_refused(grid):
    """Indices are int32, uint32 or int64: other dtypes are not guessed at."""
    v, f, o, d, b = grid
    with pytest.raises(ValueError):
        meshcast.build(v, f.astype(np.float32))


@pytest.mark.parametrize("dtype", [np.complex64, np.complex128, "U8", np.bool_, object])
def test_bad_dtypes(grid, dtype):
    v, f, o, d, b = grid
    conv = (lambda x: x.astype(str)) if dtype == "U8" else (lambda x: x.astype(dtype))
    with pytest.raises(ValueError):
        b.cast(conv(o), d)
    with pytest.raises(ValueError):
        b.cast(o, conv(d))
    with pytest.raises(ValueError):
        meshcast.build(conv(v), f)
    with pytest.raises(ValueError):
        meshcast.RaycastingScene().cast_rays(conv(rays6(o, d)))


def test_t_range(grid):
    v, f, o, d, b = grid
    refused(r"t_min|t_max|tmin|tmax", b.cast, o, d, t_min=2.0, t_max=1.0)
    refused(r"t_min|t_max|tmin|tmax", b.cast, o, d, t_min=np.array([0, 3, 0], np.float32), t_max=np.float32(2.0))
    refused(r"t_min|t_max|tmin|tmax", b.cast, o, d, t_min=0.5, t_max=np.array([1, 1, 0.25], np.float32), query="all")
    rc = meshcast.RaycastingScene()
    rc.add_triangles(v, f)
    # Open3D's way: an empty segment is a ray that is not one, a miss
    assert not rc.test_occlusions(rays6(o, d), tnear=2.0, tfar=1.0).numpy().any()
    assert rc.test_occlusions(rays6(o, d), tnear=0.5, tfar=1.0).numpy().all()
    s = meshcast.Scene()
    s.add_instance(s.add_mesh(b))
    s.commit()
    refused(r"t_min|t_max|tmin|tmax", s.cast, o, d, t_min=2.0, t_max=1.0)


def test_max_hits(grid):
    v, f, o, d, b = grid
    for bad in (0, 5000):
        refused(r"max_hits|hits", b.cast, o, d, query="all", max_hits=bad)
    # The ends of the range are taken.
    for good in (1, 4096):
        r = b.cast(o, d, query="all", max_hits=good)
        assert np.all(np.diff(r["offsets"]) <= good)


def test_unknown_names(grid):
    v, f, o, d, b = grid
    refused(r"nearest", b.cast, o, d, query="nearest")
    refused(r"sideways", b.cast, o, d, cull="sideways")
    refused(r"cuda", b.cast, o, d, backend="cuda")
    refused(r"NoSuchTree/Float3", meshcast.build, v, f, layout="NoSuchTree/Float3")
    refused(r"Float7", meshcast.build, v, f, layout="AABBTree/Float7")
    s = meshcast.Scene()
    s.add_instance(s.add_mesh(b))
    s.commit()
    refused(r"nearest", s.cast, o, d, query="nearest")
    refused(r"sideways", s.cast, o, d, cull="sideways")


def test_missing_file(tmp_path):
    with pytest.raises(FileNotFoundError):
        meshcast.load(str(tmp_path / "nothing-here.mcb"))
    with pytest.raises(OSError):
        meshcast.load(str(tmp_path / "no-such-dir" / "x.mcb"))


def test_save_into_missing_directory(grid, tmp_path):
    v, f, o, d, b = grid
    with pytest.raises(OSError):
        b.save(str(tmp_path / "no-such-dir" / "x.mcb"))


@pytest.mark.parametrize("damage", ["flip middle", "flip header", "flip last", "truncate half", "truncate header",
                                    "empty", "zeros"])
def test_corrupt_blob_file(grid, tmp_path, damage):
    v, f, o, d, b = grid
    path = tmp_path / "b.mcb"
    b.save(str(path))
    data = bytearray(path.read_bytes())
    assert meshcast.load(str(path)).triangle_count == len(f)
    if damage.startswith("flip"):
        at = {"flip middle": len(data) // 2, "flip header": 20, "flip last": len(data) - 1}[damage]
        data[at] ^= 0x5A
        data[at - 1] ^= 0xFF
    elif damage == "truncate half":
        data = data[:len(data) // 2]
    elif damage == "truncate header":
        data = data[:100]
    elif damage == "empty":
        data = bytearray()
    else:
        data = bytearray(len(data))
    path.write_bytes(bytes(data))
    for mmap in (False, True):
        with pytest.raises(ValueError):
            meshcast.load(str(path), mmap=mmap)


def test_scene_bad_ids(grid):
    v, f, o, d, b = grid
    s = meshcast.Scene()
    m = s.add_mesh(b)
    with pytest.raises(ValueError):
        s.add_instance(m + 1)
    i = s.add_instance(m)
    with pytest.raises(ValueError):
        s.set_mask(i + 1, 0x1)
    with pytest.raises(ValueError):
        s.add_instance(m, rotation_scale=np.zeros((3, 3)))  # not invertible
    with pytest.raises(ValueError):
        s.add_instance(m, rotation_scale=np.eye(2))


def test_negative_counts(grid):
    """Negative thread counts and leaf sizes are bad input (ValueError naming
    them), not a type error."""
    v, f, o, d, b = grid
    s = meshcast.Scene()
    s.add_instance(s.add_mesh(b))
    s.commit()
    calls = {
        "Blob.cast(nthreads=-1)": (r"thread", lambda: b.cast(o, d, nthreads=-1)),
        "Scene.cast(nthreads=-1)": (r"thread", lambda: s.cast(o, d, nthreads=-1)),
        "build(threads=-1)": (r"thread", lambda: meshcast.build(v, f, threads=-1)),
        "build(leaf_size=-1)": (r"leaf", lambda: meshcast.build(v, f, layout="AABBTree/Float3", leaf_size=-1)),
        "RaycastingScene(nthreads=-1)": (r"thread", lambda: meshcast.RaycastingScene(nthreads=-1)),
        "Blob.cast(query='all', max_hits=-1)": (r"max_hits", lambda: b.cast(o, d, query="all", max_hits=-1)),
    }
    wrong = []
    for what, (pattern, call) in calls.items():
        try:
            call()
            wrong.append(f"{what}: accepted")
        except ValueError as e:
            if not re.search(pattern, str(e), re.I):
                wrong.append(f"{what}: ValueError {str(e)!r} does not name {pattern!r}")
        except Exception as e:
            wrong.append(f"{what}: {type(e).__name__} ({str(e).splitlines()[0]})")
    assert not wrong, "\n".join(wrong)


def test_out_of_range_options(grid):
    v, f, o, d, b = grid
    refused(r"leaf", meshcast.build, v, f, layout="AABBTree/Float3", leaf_size=1000)
    refused(r"max_bytes", meshcast.build, v, f, max_bytes=-5)
    s = meshcast.Scene()
    m = s.add_mesh(b)
    refused(r"mask", s.add_instance, m, mask=256)
    refused(r"translation", s.add_instance, m, translation=(np.nan, 0.0, 0.0))
    refused(r"rotation", s.add_instance, m, rotation_scale=np.full((3, 3), np.inf))
    s.add_instance(m)
    s.commit()
    refused(r"mask", s.cast, o, d, mask=256)
    for edit in (lambda: s.remove_instance(5), lambda: s.set_enabled(5, True), lambda: s.set_flip_facing(5, True),
                 lambda: s.set_transform(5, translation=(1.0, 2.0, 3.0))):
        refused(r"instance", edit)


def test_uv_out_needs_uv():
    """An out= array the cast would not write is refused, not left as it was."""
    v, f = shapes.grid(2, 2)
    blob = meshcast.build(v, f)
    o, d = np.array([[0.5, 0.5, 1.0]]), np.array([[0, 0, -1.0]])
    with pytest.raises(ValueError, match="uv"):
        blob.cast(o, d, out={"uv": np.zeros((1, 2), np.float32)})
    out = {"uv": np.zeros((1, 2), np.float32)}
    assert blob.cast(o, d, uv=True, out=out)["uv"] is out["uv"]


def test_refusal_names_the_ray_and_its_numbers():
    """The refused ray is the one the walk refused (a blob rounds origins to
    float32: 2^100 (1 + 2^-40) becomes 2^100, which it takes), and small
    numbers are printed as numbers, not 0.000000."""
    v, f = shapes.grid(2, 2)
    blob = meshcast.build(v, f)
    o = np.array([[2.0**100 * (1 + 2.0**-40), 0, 0], [np.nan, 0, 0]])
    d = np.array([[0, 0, -1.0], [0, 0, -1.0]])
    with pytest.raises(ValueError, match=r"rays\[1\]: origin"):
        blob.cast(o, d)
    with pytest.raises(ValueError, match=r"t_max -1\.0+1?e-10 is NaN or negative"):
        blob.cast(o[:1] * 0, d[:1], t_max=-1e-10)
