"""Hostile use of the package: rays a geometry's frame cannot take, a blob
file changed under a loaded blob, forked children, sweeps of thread counts,
values named as the caller wrote them, and crossings counted through edges
and vertices of meshes wound every way."""

import multiprocessing
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import meshcast
import shapes
from cases import DEFAULT_LAYOUT


# A geometry about 1.2e30 from the origin (10^16 across: float64 there
# steps by about 3e14): its centre is its instance's translation, within
# 2^100. A ray from -1e29 is fine in the world but lies beyond 2^100
# (about 1.27e30) of that centre.
FAR, SIZE = 1.2e30, 1e16


def far_cube():
    v, f = shapes.cube()
    return v.astype(np.float64) * SIZE + [FAR, 0.0, 0.0], f


def far_rays():
    # Ray 1 cannot be walked in the far geometry's frame; ray 0 and 2 can.
    return np.array([[FAR - 10 * SIZE, 0.1 * SIZE, 0.2 * SIZE, 1, 0, 0],
                     [-1e29, 0.1 * SIZE, 0.2 * SIZE, 1, 0, 0],
                     [FAR + 10 * SIZE, 0.1 * SIZE, 0.2 * SIZE, -1, 0, 0]], dtype=np.float64)


@pytest.mark.parametrize("near_geometry", [False, True])
@pytest.mark.parametrize("call", ["cast_rays", "test_occlusions", "count_intersections", "list_intersections"])
def test_ray_beyond_a_geometrys_frame_is_named(call, near_geometry):
    """Never a miss, never an unwritten answer: the ray is named."""
    scene = meshcast.RaycastingScene()
    scene.add_triangles(*far_cube())
    if near_geometry:  # two geometries: the scene's walk, not the blob's alone
        v, f = shapes.cube()
        scene.add_triangles(v, f)
    with pytest.raises(ValueError, match=r"rays\[1\].*frame of a geometry"):
        getattr(scene, call)(far_rays())
    # Without it, the others are answered.
    rays = far_rays()[[0, 2]]
    assert np.array_equal(scene.count_intersections(rays).numpy(), [2, 2])
    assert np.all(np.isfinite(scene.cast_rays(rays)["t_hit"].numpy()))


def test_scene_instance_beyond_a_rays_frame_is_named():
    v, f = shapes.cube()
    scene = meshcast.Scene()
    scene.add_instance(scene.add_mesh(meshcast.build(v * SIZE, f)), translation=[FAR, 0.0, 0.0])
    scene.commit()
    rays = far_rays()
    for query in ("closest", "any", "all"):
        with pytest.raises(ValueError, match=r"rays\[1\].*frame of a geometry"):
            scene.cast(rays[:, :3], rays[:, 3:], query=query)


def test_loaded_blob_ignores_its_file_changing(tmp_path):
    """load() keeps the bytes it validated: the file rewritten with another
    blob, corrupted in place or truncated changes no answer."""
    v, f = shapes.sphere()
    o, d = shapes.rays(v, 1000, seed=8)
    path = tmp_path / "mesh.mcb"
    meshcast.build(v, f).save(str(path))
    loaded = meshcast.load(path)
    assert not loaded.mapped
    want = loaded.cast(o, d, uv=True)
    other = meshcast.build(*shapes.octahedron()).to_bytes()
    size = os.path.getsize(path)
    rng = np.random.default_rng(3)
    for change in ("another blob", "corrupted", "truncated"):
        with open(path, "r+b") as file:  # in place: the same inode
            if change == "another blob":
                file.write(other)
            elif change == "corrupted":
                file.write(rng.integers(0, 256, size, dtype=np.uint8).tobytes())
            else:
                file.truncate(size // 3)
        got = loaded.cast(o, d, uv=True)
        for key in want:
            np.testing.assert_array_equal(got[key], want[key], err_msg=f"{change}: {key}")


def test_mapped_blob_is_a_choice(tmp_path):
    v, f = shapes.sphere()
    o, d = shapes.rays(v, 500, seed=9)
    b = meshcast.build(v, f)
    path = tmp_path / "mesh.mcb"
    b.save(str(path))
    mapped = meshcast.load(path, mmap=True)
    assert mapped.mapped and "mapped" in repr(mapped)
    # save() renames a new file over the name: a mapping of the old one is untouched.
    meshcast.build(*shapes.octahedron()).save(str(path))
    np.testing.assert_array_equal(mapped.cast(o, d)["t"], b.cast(o, d)["t"])
    assert "mmap" in meshcast.load.__doc__ and "SIGBUS" in meshcast.load.__doc__


def _vulkan_or_skip(blob, o, d):
    if not meshcast.features.get("vulkan"):
        pytest.skip("meshcast built without Vulkan")
    try:
        return blob.cast(o, d, backend="vulkan")["t"]
    except RuntimeError as e:
        pytest.skip(f"no Vulkan device: {e}")


# What a forked child inherits (set before the fork, read in the child).
_inherited = {}


def _cast_inherited(kind):
    o, d = _inherited["rays"]
    if kind == "vulkan":
        return _inherited["blob"].cast(o, d, backend="vulkan")["t"]
    if kind == "blob":
        return _inherited["blob"].cast(o, d, nthreads=2)["t"]
    if kind == "scene":
        return _inherited["scene"].cast(o, d, nthreads=2)["t"]
    rays = np.concatenate([o, d], axis=1)
    return _inherited["raycasting"].cast_rays(rays, nthreads=2)["t_hit"].numpy()


@pytest.mark.parametrize("kind", ["vulkan", "blob", "scene", "raycasting"])
def test_forked_child_casts_what_the_parent_cast(kind):
    """The parent's casters and worker threads are not the child's: a child
    forked after the parent cast the same object casts with its own."""
    v, f = shapes.sphere()
    o, d = shapes.rays(v, 3000, seed=5)
    blob = meshcast.build(v, f)
    scene = meshcast.Scene()
    scene.add_instance(scene.add_mesh(blob))
    scene.commit()
    raycasting = meshcast.RaycastingScene()
    raycasting.add_triangles(v, f)
    _inherited.update(blob=blob, scene=scene, raycasting=raycasting, rays=(o, d))
    if kind == "vulkan":
        _vulkan_or_skip(blob, o, d)
    want = _cast_inherited(kind)  # the parent's casters and threads now exist
    with multiprocessing.get_context("fork").Pool(1) as pool:
        got = pool.apply_async(_cast_inherited, (kind,)).get(timeout=120)
    np.testing.assert_array_equal(got, want)


def _thread_count():
    return len(os.listdir("/proc/self/task"))


def test_thread_count_sweep_keeps_one_pool():
    v, f = shapes.sphere()
    blob = meshcast.build(v, f)
    o, d = shapes.rays(v, 20000, seed=1)
    want = blob.cast(o, d, nthreads=1)["triangle"]
    before = _thread_count()
    for n in range(1, 49):
        np.testing.assert_array_equal(blob.cast(o, d, nthreads=n)["triangle"], want)
    # One pool as wide as the widest call (48), not one a count (1,176 threads).
    assert _thread_count() <= before + 48


def test_threads_the_system_refuses_are_named():
    """Under an address-space limit, a call of many threads fails in words."""
    script = textwrap.dedent("""
        import resource, numpy as np, meshcast, shapes
        v, f = shapes.sphere()
        blob = meshcast.build(v, f)
        o, d = shapes.rays(v, 200000, seed=1)
        with open("/proc/self/status") as s:
            size = next(int(l.split()[1]) for l in s if l.startswith("VmSize")) * 1024
        resource.setrlimit(resource.RLIMIT_AS, (size + (256 << 20), resource.RLIM_INFINITY))
        try:
            blob.cast(o, d, nthreads=1024)
        except RuntimeError as e:
            print("refused:", e)
        else:
            print("cast")
    """)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([os.path.dirname(__file__), os.environ.get("PYTHONPATH", "")]))
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120, env=env)
    assert run.returncode == 0, run.stderr
    if run.stdout.startswith("cast"):
        pytest.skip("the system started 1,024 threads within the limit")
    assert "refused to start worker thread" in run.stdout and "of 1024" in run.stdout, run.stdout


def test_values_are_named_as_written():
    v, f = shapes.cube()
    with pytest.raises(ValueError, match=r"max_bytes: nan is not a number") as e:
        meshcast.build(v, f, max_bytes=float("nan"))
    assert "negative" not in str(e.value)
    with pytest.raises(ValueError, match=r"max_bytes: -1\.5 is negative"):
        meshcast.build(v, f, max_bytes=-1.5)
    with pytest.raises(ValueError, match=r"above max_bytes 100\.5"):
        meshcast.build(v, f, layout=DEFAULT_LAYOUT, max_bytes=100.5)
    # The automatic layout's limit is a triangle's share: the caller's own figure is named too.
    with pytest.raises(ValueError, match=r"max_bytes 24 over 12 triangles: .*at most 2 bytes a triangle"):
        meshcast.build(v, f, max_bytes=24)
    bad = f.astype(np.uint64)
    bad[3, 1] = np.uint64(2**64 - 1)
    with pytest.raises(ValueError, match=r"triangles\[3, 1\] = 18446744073709551615: "):
        meshcast.build(v, bad)


# A solid of unit voxels, its boundary squares each cut into two triangles
# along a random diagonal: faces, edges and vertices (saddles among them)
# lie on the integer lattice, where rays of directions in {1, 2} hit them
# exactly, and where two voxels meet along an edge four triangles share it.
def voxel_solid(filled, winding, rng):
    triangles, index = [], {}

    def vertex(p):
        return index.setdefault(tuple(p), len(index))

    for cell in zip(*np.nonzero(filled)):
        for axis in range(3):
            for side in (0, 1):
                step = np.zeros(3, int)
                step[axis] = 1 if side else -1
                n = np.array(cell) + step
                if all(0 <= n[k] < filled.shape[k] for k in range(3)) and filled[tuple(n)]:
                    continue
                u, w = [k for k in range(3) if k != axis]
                base = np.array(cell)
                base[axis] += side
                square = []
                for du, dw in ((0, 0), (1, 0), (1, 1), (0, 1)):
                    p = base.copy()
                    p[u] += du
                    p[w] += dw
                    square.append(p)
                cut = rng.integers(2)
                for tri in ((0, 1, 2), (0, 2, 3)) if cut == 0 else ((0, 1, 3), (1, 2, 3)):
                    a, b, c = (square[i] for i in tri)
                    outward = np.cross(b - a, c - a) @ step > 0
                    flip = {"outward": not outward, "inward": outward, "mixed": rng.integers(2) == 1}[winding]
                    if flip:
                        b, c = c, b
                    triangles.append([vertex(a), vertex(b), vertex(c)])
    vertices = np.array(sorted(index, key=index.get), dtype=np.float64)
    return vertices, np.array(triangles, dtype=np.int64)


@pytest.mark.parametrize("winding", ["outward", "inward", "mixed"])
def test_parity_through_edges_and_vertices_of_any_winding(winding):
    rng = np.random.default_rng(11)
    filled = rng.random((4, 4, 4)) < 0.55
    v, f = voxel_solid(filled, winding, rng)
    scene = meshcast.RaycastingScene()
    scene.add_triangles(v, f)
    # Rays through lattice vertices, edge midpoints and square centres,
    # from dyadic distances (every origin exact, none on the lattice's planes).
    n = 6000
    target = rng.integers(-1, 6, (n, 3)).astype(np.float64)
    kind = rng.integers(3, size=n)  # 0 vertex, 1 edge midpoint, 2 square centre
    for row, k in enumerate(kind):
        target[row, rng.choice(3, size=k, replace=False)] += 0.5
    direction = rng.choice([-2.0, -1.0, 1.0, 2.0], (n, 3))
    origin = target - rng.choice([0.375, 1.375, 2.625, 4.125], (n, 1)) * direction
    rays = np.concatenate([origin, direction], axis=1)
    cell = np.floor(origin).astype(int)
    in_grid = np.all((cell >= 0) & (cell < 4), axis=1)
    inside = np.zeros(n, bool)
    inside[in_grid] = filled[tuple(cell[in_grid].T)]
    counts = scene.count_intersections(rays).numpy()
    wrong = np.nonzero(counts % 2 != inside)[0]
    assert len(wrong) == 0, (f"{len(wrong)} of {n} rays' parity is wrong, e.g. ray {rays[wrong[0]]} "
                             f"counts {counts[wrong[0]]}, inside {inside[wrong[0]]}")
    listed = scene.list_intersections(rays)
    np.testing.assert_array_equal(np.diff(listed["ray_splits"].numpy()), counts)
    # A second geometry through the same points (the solid moved by one
    # voxel along x, stored about another centre): each counts its own.
    moved = v + [1.0, 0.0, 0.0]
    alone, both = meshcast.RaycastingScene(), meshcast.RaycastingScene()
    alone.add_triangles(moved, f)
    both.add_triangles(v, f)
    both.add_triangles(moved, f)
    np.testing.assert_array_equal(both.count_intersections(rays).numpy(),
                                  counts + alone.count_intersections(rays).numpy())
