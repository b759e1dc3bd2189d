"""Blobs, Scenes and RaycastingScenes through pickle and spawned processes:
the same answers, bit for bit; a mapped blob travels as its path and is
mapped once a process; a file missing or another is named."""

import copy
import multiprocessing
import os
import pickle
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import meshcast
import shapes
from meshcast import _shipping

RECOMMENDED = "OctTreeCompressed/ClusterBitPackSOA8"


def _rays(vertices, n=3000, seed=5):
    o, d = shapes.rays(vertices, n, seed=seed)
    return np.asarray(o, np.float32), np.asarray(d, np.float32)


def _equal(a, b):
    assert a.keys() == b.keys()
    for key in a:
        np.testing.assert_array_equal(np.asarray(a[key]), np.asarray(b[key]), err_msg=key)


def test_a_blob_in_memory_travels_as_its_bytes():
    v, f = shapes.sphere()
    blob = meshcast.build(v, f, name="sphere")
    data = pickle.dumps(blob)
    assert len(data) > blob.nbytes  # the bytes themselves
    twin = pickle.loads(data)
    assert not twin.mapped and twin.name == "sphere" and twin.checksum == blob.checksum
    o, d = _rays(v)
    _equal(twin.cast(o, d, uv=True), blob.cast(o, d, uv=True))
    _equal(copy.deepcopy(blob).cast(o, d, query="all"), blob.cast(o, d, query="all"))


def test_a_mapped_blob_travels_as_its_path_and_is_mapped_once(tmp_path):
    v, f = shapes.soup()
    path = tmp_path / "soup.blob"
    meshcast.build(v, f).save(str(path))
    blob = meshcast.load(path, mmap=True)
    assert blob.path == str(path.resolve())
    data = pickle.dumps(blob)
    assert len(data) < 1000 < blob.nbytes  # the path, not the bytes
    before = _shipping.arrivals()["mapped"]
    twins = [pickle.loads(data) for _ in range(3)]
    assert _shipping.arrivals()["mapped"] == before + 1
    assert all(t is twins[0] for t in twins) and twins[0].mapped
    o, d = _rays(v)
    _equal(twins[0].cast(o, d), blob.cast(o, d))


def test_a_mapped_blob_whose_file_is_gone_or_another_is_refused_by_name(tmp_path):
    v, f = shapes.sphere()
    path = tmp_path / "moved.blob"
    meshcast.build(v, f, layout="AABBTree/Float3").save(str(path))
    data = pickle.dumps(meshcast.load(path, mmap=True))
    # The same size, other bytes: the mesh moved a little.
    meshcast.build(v + np.float32(0.125), f, layout="AABBTree/Float3").save(str(path))
    assert os.path.getsize(path) == len(meshcast.load(path).to_bytes())
    with pytest.raises(ValueError, match=r"process \d+ on .*moved\.blob has checksum .* other bytes"):
        pickle.loads(data)
    meshcast.build(v[:-1], f[f.max(axis=1) < len(v) - 1]).save(str(path))
    with pytest.raises(ValueError, match=r"moved\.blob has \d+ bytes, the file the Blob was pickled from \d+"):
        pickle.loads(data)
    os.remove(path)
    with pytest.raises(FileNotFoundError, match=r"moved\.blob is missing"):
        pickle.loads(data)


def _scene():
    sv, sf = shapes.sphere()
    gv, gf = shapes.grid(10, 8)
    scene = meshcast.Scene()
    sphere = scene.add_mesh(meshcast.build(sv, sf, layout=RECOMMENDED))
    grid = scene.add_mesh(meshcast.build(gv, gf, layout=RECOMMENDED))
    scene.add_instance(sphere)
    scene.add_instance(sphere, np.diag([2.0, 1.0, 0.5]), [1e6 + 0.25, -3.0, 2.0], mask=2, flip_facing=True)
    gone = scene.add_instance(grid, translation=[5.0, 5.0, -1.0])
    scene.add_instance(grid, translation=[0.0, 0.0, -2.0])
    off = scene.add_instance(sphere, translation=[0.0, 4.0, 0.0])
    scene.remove_instance(gone)
    scene.set_enabled(off, False)
    scene.commit()
    return scene, sv


def test_a_scene_travels_as_its_blobs_and_instances():
    scene, v = _scene()
    twin = pickle.loads(pickle.dumps(scene))
    assert twin.instance_count == scene.instance_count
    o, d = _rays(v, 4000)
    o = o.astype(np.float64)
    o[::2, 0] += 1e6  # toward the far instance, in double
    for mask in (0xFF, 2):
        _equal(twin.cast(o, d, uv=True, mask=mask), scene.cast(o, d, uv=True, mask=mask))
    _equal(twin.cast(o, d, query="all"), scene.cast(o, d, query="all"))
    _equal(twin.closest_points(o[:500]), scene.closest_points(o[:500]))
    # One blob pickled once, whatever its meshes: the two scenes share it.
    shared = meshcast.build(v, shapes.sphere()[1])
    a, b = meshcast.Scene(), meshcast.Scene()
    a.add_mesh(shared), b.add_mesh(shared)
    a.commit(), b.commit()
    one = len(pickle.dumps(a))
    assert len(pickle.dumps((a, b))) < 1.5 * one


def test_a_scene_with_edits_not_committed_is_not_pickled():
    scene, _ = _scene()
    scene.set_mask(0, 4)
    with pytest.raises(ValueError, match="commit"):
        pickle.dumps(scene)


def test_a_raycasting_scene_of_several_geometries_travels_whole():
    scene = meshcast.RaycastingScene()
    sv, sf = shapes.sphere()
    gv, gf = shapes.grid(9, 7)
    scene.add_triangles(sv, sf)
    scene.add_triangles(gv.astype(np.float64) + 1e5, gf)
    twin = pickle.loads(pickle.dumps(scene))
    o, d = _rays(sv, 4000)
    rays = np.concatenate([o, d], axis=1)
    rays[::3, :3] += 1e5
    _equal(twin.cast_rays(rays), scene.cast_rays(rays))
    _equal(twin.list_intersections(rays), scene.list_intersections(rays))
    points = rays[:300, :3]
    _equal(twin.compute_closest_points(points), scene.compute_closest_points(points))
    np.testing.assert_array_equal(twin.compute_signed_distance(points).numpy(),
                                  scene.compute_signed_distance(points).numpy())
    assert twin.nbytes == scene.nbytes
    # The compact layout too: its normals are the input mesh's, kept as they were.
    compact = meshcast.RaycastingScene(max_error=1e-5)
    compact.add_triangles(sv, sf)
    _equal(pickle.loads(pickle.dumps(compact)).cast_rays(rays), compact.cast_rays(rays))
    # Later geometries go to the copy alone.
    twin.add_triangles(gv, gf)
    assert scene.count_intersections(rays).shape == twin.count_intersections(rays).shape


def test_a_corrupted_pickle_of_a_raycasting_scene_is_refused():
    scene = meshcast.RaycastingScene()
    v, f = shapes.sphere()
    scene.add_triangles(v, f)
    scene.compute_closest_points(v[:3])  # primitive_normals: made now, and still not pickled
    state = scene._scene.__getstate__()
    assert state[0] == 2 and state[4][0][1] == b""  # made from the blob again where it arrives
    blob, normals, centre, checksum = state[4][0]
    broken = bytearray(blob)
    broken[len(broken) // 2] ^= 0xFF
    # The compact layout's normals are the mesh's: pickled, and checked.
    compact = meshcast.RaycastingScene(max_error=1e-5)
    compact.add_triangles(v, f)
    cstate = compact._scene.__getstate__()
    cblob, cnormals, ccentre, cchecksum = cstate[4][0]
    assert len(cnormals) == 4 * len(f)
    for given, geometries, message in ((state, [(bytes(broken), normals, centre, checksum)], "checksum"),
                                       (state, [(blob, normals, (0.0, float("nan"), 0.0), checksum)], "centre"),
                                       (cstate, [(cblob, cnormals[:-4], ccentre, cchecksum)], "checksum"),
                                       # a state of the version before the checksum
                                       ((1,) + cstate[1:4], [(cblob, cnormals[:-4], ccentre)], "bytes of normals")):
        twin = meshcast._meshcast._RaycastingScene.__new__(meshcast._meshcast._RaycastingScene)
        with pytest.raises(ValueError, match=message):
            twin.__setstate__(given[:4] + (geometries,))


def _raycasting_twin(state):
    twin = meshcast.RaycastingScene()
    twin._scene = meshcast._meshcast._RaycastingScene.__new__(meshcast._meshcast._RaycastingScene)
    twin._scene.__setstate__(state)
    return twin


def test_normals_altered_in_a_raycasting_scene_pickle_are_never_answered():
    v, f = shapes.sphere()
    o, d = _rays(v, 2000)
    rays = np.concatenate([o, d], axis=1)
    # Every triangle's normal said to be +z (packed as two zero codes): the
    # sphere's are mostly not.
    up = b"\0" * (4 * len(f))
    for max_error in (0.0, 1e-5):  # the exact layout, and the compact one (the mesh's normals kept)
        scene = meshcast.RaycastingScene(max_error=max_error)
        scene.add_triangles(v, f)
        truth = scene.cast_rays(rays)["primitive_normals"].numpy()  # made now: a pickle could hold them
        assert (np.abs(truth[:, 2]) < 0.9).sum() > 100
        state = scene._scene.__getstate__()
        geometry = state[4][0]
        altered = state[:4] + ([(geometry[0], up) + tuple(geometry[2:])],)
        with pytest.raises(ValueError, match=r"geometry 0 of the pickled state has normals"):
            _raycasting_twin(altered)
    # A state of the version before: the exact layout's normals pickled, not
    # read (made from the blob); the compact one's taken as pickled.
    exact = meshcast.RaycastingScene()
    exact.add_triangles(v, f)
    state = exact._scene.__getstate__()
    blob, _, centre = state[4][0][:3]
    twin = _raycasting_twin((1,) + state[1:4] + ([(blob, up, centre)],))
    np.testing.assert_array_equal(twin.cast_rays(rays)["primitive_normals"].numpy(),
                                  exact.cast_rays(rays)["primitive_normals"].numpy())
    compact = meshcast.RaycastingScene(max_error=1e-5)
    compact.add_triangles(v, f)
    state = compact._scene.__getstate__()
    twin = _raycasting_twin((1,) + state[1:4] + ([state[4][0][:3]],))
    _equal(twin.cast_rays(rays), compact.cast_rays(rays))


def test_a_pickled_state_of_other_types_is_refused_naming_them():
    scene, _ = _scene()
    version, blobs, instances, number = scene.__getstate__()
    for state, message in (((version, ["a blob"] + blobs[1:], instances, number),
                            r"Scene: the pickled state's blob 0: a meshcast\.Blob expected, str 'a blob' found"),
                           ((version, blobs, [("0",) + tuple(instances[0][1:])] + instances[1:], number),
                            r"Scene: the pickled state's instance 0 mesh: a mesh index \(an int\) expected, str '0' "),
                           ((version, tuple(blobs), instances, number),
                            r"Scene: the pickled state's blobs: a list expected, tuple found"),
                           ((version, blobs, instances, "7"),
                            r"Scene: the pickled state's number: an int expected, str '7' found"),
                           (list((version, blobs, instances, number)),
                            r"Scene: the pickled state: a tuple expected, list found")):
        twin = meshcast.Scene.__new__(meshcast.Scene)
        with pytest.raises(TypeError, match=message):
            twin.__setstate__(state)
    rc = meshcast.RaycastingScene()
    rc.add_triangles(*shapes.sphere())
    state = rc._scene.__getstate__()
    geometry = state[4][0]
    for given, message in ((state[:4] + ([("text",) + tuple(geometry[1:])],),
                            r"RaycastingScene: the pickled state's geometry 0's blob: bytes expected, str 'text' found"),
                           (state[:1] + ("8",) + state[2:],
                            r"the pickled state's build threads: an int from 0 to 2\^32 - 1 expected, str '8' found"),
                           (state[:4] + (None,), r"the pickled state's geometries: a list expected, NoneType None found")):
        with pytest.raises(TypeError, match=message):
            _raycasting_twin(given)


def test_every_pickle_protocol_carries_blobs_and_scenes():
    """Protocols 0 and 1 (and __reduce__ called directly) as well as 2 to 5:
    the same answers, or a Python exception; run in a child process, so a
    process that ends itself fails the test rather than the test run."""
    script = textwrap.dedent("""
        import pickle
        import numpy as np
        import meshcast, shapes
        v, f = shapes.sphere()
        blob = meshcast.build(v, f)
        scene = meshcast.Scene()
        scene.add_instance(scene.add_mesh(blob), translation=[0.5, 0.0, 0.0])
        scene.commit()
        rcs = meshcast.RaycastingScene()
        rcs.add_triangles(v, f)
        o, d = (np.asarray(a, np.float32) for a in shapes.rays(v, 500, seed=3))
        rays = np.concatenate([o, d], axis=1)
        answers = (lambda x: x.cast(o, d, uv=True), lambda x: x.cast(o, d, uv=True),
                   lambda x: x.cast_rays(rays))
        scene.__reduce__(), rcs._scene.__reduce__(), blob.__reduce__()
        for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
            for x, answer in zip((blob, scene, rcs), answers):
                twin = pickle.loads(pickle.dumps(x, protocol))
                a, b = answer(twin), answer(x)
                assert a.keys() == b.keys()
                for key in a:
                    assert np.array_equal(np.asarray(a[key]), np.asarray(b[key])), (protocol, type(x), key)
            print("protocol", protocol)
    """)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([os.path.dirname(__file__), os.environ.get("PYTHONPATH", "")]))
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300, env=env)
    assert run.returncode == 0, f"exit {run.returncode}: {run.stderr[-2000:]}"
    assert run.stdout.split("\n")[:-1] == [f"protocol {p}" for p in range(pickle.HIGHEST_PROTOCOL + 1)]


def _cast_in_child(blob, origins, directions):
    return blob.cast(origins, directions), _shipping.arrivals()


def test_spawned_processes_take_blobs_directly(tmp_path):
    v, f = shapes.sphere()
    path = tmp_path / "spawned.blob"
    meshcast.build(v, f).save(str(path))
    mapped, in_memory = meshcast.load(path, mmap=True), meshcast.build(v, f, layout="AABBTree/Float3")
    o, d = _rays(v, 2000)
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        for blob, kind in ((mapped, "mapped"), (in_memory, "bytes")):
            answer, arrivals = pool.apply(_cast_in_child, (blob, o, d))
            _equal(answer, blob.cast(o, d))
            assert arrivals[kind] == 1


def test_a_scene_pickled_keeps_its_ids_and_refuses_others():
    scene, v = _scene()
    state = scene.__getstate__()
    twin = pickle.loads(pickle.dumps(scene))
    sphere = meshcast.Scene().add_mesh(meshcast.build(v, shapes.sphere()[1]))
    mine = twin.add_instance(0, translation=[0.0, 0.0, 9.0])
    assert state[0] == 2 and mine.scene == state[3] == scene.add_instance(0).scene  # the copy's ids are the scene's
    twin.set_mask(mine, 4)  # good with the copy
    with pytest.raises(ValueError, match="another scene"):
        twin.add_instance(sphere)
    for carried in (pickle.loads(pickle.dumps(mine)), copy.deepcopy(mine)):
        assert type(carried) is meshcast.InstanceId and (carried, carried.scene) == (mine, mine.scene)
    # A state of the version before numbers loads as a scene of its own.
    old = meshcast.Scene.__new__(meshcast.Scene)
    old.__setstate__((1,) + state[1:3])
    assert old.instance_count == 4
    with pytest.raises(ValueError, match="another scene"):
        old.set_mask(mine, 1)
    old.set_mask(int(mine) - 1, 1)
