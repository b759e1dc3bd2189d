"""meshcast.dask on a LocalCluster of 2 worker processes: every query, the
Scene and the RaycastingScene forms answer as the in-process call on the
same rays, bit for bit; the structure reaches each worker once (counted on
the workers); a worker killed mid-cast changes no answer; bad input and a
blob file missing or another on the workers are errors that name them."""

import os
import signal
import time

import dask
import dask.array as da
import numpy as np
import pytest
from distributed import Client, LocalCluster

import meshcast
import meshcast.dask as mcd
import shapes

RECOMMENDED = "OctTreeCompressed/ClusterBitPackSOA8"


@pytest.fixture(scope="module")
def client():
    # Quiet and small: two processes of one thread, no dashboard. A worker
    # reaching for data on the one the test kills gives up after 5 s, not
    # Dask's 30.
    with dask.config.set({"distributed.logging.distributed": "error", "distributed.comm.timeouts.connect": "5s"}):
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                          silence_logs=40) as cluster, Client(cluster) as c:
            yield c


def _equal(a, b):
    assert sorted(a) == sorted(b)
    for key in a:
        np.testing.assert_array_equal(np.asarray(a[key]), np.asarray(b[key]), err_msg=key)


def _computed(answer):
    return dict(zip(answer, dask.compute(*answer.values())))


def _arrivals(client):
    return client.run(mcd.arrivals)


@pytest.fixture(scope="module")
def bunny_rays():
    v, f = meshcast.read_mesh(shapes.BUNNY)
    o, d = shapes.rays(v, 40000, seed=3)
    return np.asarray(v), np.asarray(f), o, d


def test_every_query_of_a_blob_answers_as_in_process(client, bunny_rays):
    v, f, o, d = bunny_rays
    blob = meshcast.build(v, f, layout=RECOMMENDED, name="bunny")
    # Chunks of very different sizes, one of none.
    chunks = ((0, 7, 25000, 1, 14992), (3,))
    do, dd = da.from_array(o, chunks=chunks), da.from_array(d, chunks=chunks)
    t_min = np.random.default_rng(1).uniform(0, 0.2, len(o)).astype(np.float32)
    t_max = np.full(len(o), np.inf, np.float32)
    t_max[::5] = 0.5
    before = _arrivals(client)
    for options in (dict(), dict(uv=True, cull="back"), dict(query="any", cull="front"),
                    dict(query="all", max_hits=3, uv=True)):
        answer = mcd.cast(blob, do, dd, t_min=da.from_array(t_min, chunks=chunks[0]), t_max=t_max, **options)
        assert all(isinstance(a, da.Array) for a in answer.values())
        if options.get("query") != "all":
            assert all(a.chunks[0] == chunks[0] for a in answer.values())
        _equal(_computed(answer), blob.cast(o, d, t_min=t_min, t_max=t_max, **options))
    # One origin for every ray, a number for t_max; the rays (..., 3) in 2-D chunks.
    grid = d.reshape(200, 200, 3)
    answer = mcd.cast(blob, np.float32([0.0, 0.1, 0.3]), da.from_array(grid, chunks=(64, 50, 3)), t_max=2.0)
    assert answer["t"].chunks == ((64, 64, 64, 8), (50,) * 4)
    _equal(_computed(answer), blob.cast(np.float32([0.0, 0.1, 0.3]), grid, t_max=2.0))
    # The blob reached each worker once, as its bytes, for every cast above.
    after = _arrivals(client)
    assert {w: after[w]["bytes"] - before[w]["bytes"] for w in after} == {w: 1 for w in after}


def test_a_mapped_blob_is_mapped_once_on_each_worker(client, bunny_rays, tmp_path):
    v, f, o, d = bunny_rays
    path = tmp_path / "bunny.blob"
    meshcast.build(v, f, layout=RECOMMENDED).save(str(path))
    blob = meshcast.load(path, mmap=True)
    before = _arrivals(client)
    answer = mcd.cast(blob, da.from_array(o, chunks=(2500, 3)), da.from_array(d, chunks=(2500, 3)), uv=True)
    _equal(_computed(answer), blob.cast(o, d, uv=True))
    _equal(_computed(mcd.cast(blob, o, d, query="any")), blob.cast(o, d, query="any"))
    after = _arrivals(client)
    mapped = [after[w]["mapped"] - before[w]["mapped"] for w in after]
    assert max(mapped) == 1 and sum(mapped) >= 1  # 16 chunks, each worker mapping the file once at most
    assert all(after[w]["bytes"] == before[w]["bytes"] for w in after)


def test_a_scene_answers_as_in_process(client, bunny_rays, tmp_path):
    v, f, o, d = bunny_rays
    path = tmp_path / "sphere.blob"
    sv, sf = shapes.sphere()
    meshcast.build(sv, sf, layout=RECOMMENDED).save(str(path))
    scene = meshcast.Scene()
    bunny = scene.add_mesh(meshcast.build(v, f, layout=RECOMMENDED))
    sphere = scene.add_mesh(meshcast.load(path, mmap=True))
    scene.add_instance(bunny)
    scene.add_instance(sphere, np.diag([0.05, 0.05, 0.02]), [1e7, 0.0, 0.0], mask=2)
    scene.add_instance(bunny, translation=[1e7 + 0.3, 0.0, 0.0], flip_facing=True)
    scene.commit()
    o64 = o.astype(np.float64)
    o64[1::2, 0] += 1e7
    chunks = (6000, 3)
    for options in (dict(uv=True), dict(query="any", mask=2), dict(query="all", max_hits=5, cull="back")):
        answer = mcd.cast(scene, da.from_array(o64, chunks=chunks), da.from_array(d, chunks=chunks), **options)
        _equal(_computed(answer), scene.cast(o64, d, **options))
    scene.set_mask(0, 4)
    with pytest.raises(ValueError, match="commit"):
        mcd.cast(scene, o64, d)


def test_a_raycasting_scene_answers_as_in_process(client, bunny_rays):
    v, f, o, d = bunny_rays
    scene = meshcast.RaycastingScene()
    scene.add_triangles(v, f)
    scene.add_triangles(*shapes.sphere(radius=0.02, centre=(0.0, 0.1, 0.0)))
    rays = np.concatenate([o, d], axis=1)
    rays[::50, 3:] = np.nan  # a padded pixel: a miss, as in Open3D
    drays = da.from_array(rays, chunks=(7000, 6))
    _equal(_computed(mcd.cast_rays(scene, drays)), scene.cast_rays(rays))
    _equal(_computed(mcd.cast_rays(scene, drays, uvs=False, normals=False)),
           scene.cast_rays(rays, uvs=False, normals=False))
    tnear = np.random.default_rng(2).uniform(0, 0.1, len(rays))
    np.testing.assert_array_equal(mcd.test_occlusions(scene, drays, tnear=tnear, tfar=1.5).compute(),
                                  scene.test_occlusions(rays, tnear=tnear, tfar=1.5).numpy())
    image = rays[:39000].reshape(130, 300, 6)
    counts = mcd.count_intersections(scene, da.from_array(image, chunks=(40, 100, 6)))
    assert counts.dtype == np.int32 and counts.chunks == ((40, 40, 40, 10), (100,) * 3)
    np.testing.assert_array_equal(counts.compute(), scene.count_intersections(image).numpy())


def test_dasks_local_schedulers_answer_alike(client, bunny_rays):
    # A graph made with the Client current, computed in this process.
    v, f, o, d = bunny_rays
    blob = meshcast.build(v, f, layout="AABBTree/Float3")
    answer = mcd.cast(blob, da.from_array(o, chunks=(9000, 3)), da.from_array(d, chunks=(9000, 3)), query="all")
    expected = blob.cast(o, d, query="all")
    for scheduler in ("threads", "sync"):
        got = dict(zip(answer, dask.compute(*answer.values(), scheduler=scheduler)))
        _equal(got, expected)


def test_a_worker_killed_mid_cast_changes_no_answer(client, bunny_rays):
    v, f, o, d = bunny_rays
    blob = meshcast.build(v, f, layout=RECOMMENDED)
    many_o, many_d = np.tile(o, (20, 1)), np.tile(d, (20, 1))  # 800,000 rays in 80 chunks
    expected = blob.cast(many_o, many_d, query="all", max_hits=8)
    answer = mcd.cast(blob, da.from_array(many_o, chunks=(10000, 3)), da.from_array(many_d, chunks=(10000, 3)),
                      query="all", max_hits=8)
    persisted = client.persist(list(answer.values()))
    victim = None
    deadline = time.monotonic() + 60
    while victim is None and time.monotonic() < deadline:
        busy = [w for w, keys in client.processing().items() if keys]
        if busy:
            victim = busy[0]
        else:
            time.sleep(0.01)
    assert victim is not None, "no worker was casting"
    pid = client.run(os.getpid, workers=[victim])[victim]
    os.kill(pid, signal.SIGKILL)
    got = dict(zip(answer, client.compute(persisted, sync=True)))
    _equal(got, expected)


def test_bad_input_and_missing_or_other_files_are_named(client, bunny_rays, tmp_path):
    v, f, o, d = bunny_rays
    blob = meshcast.build(v, f, layout=RECOMMENDED)
    with pytest.raises(TypeError, match="a meshcast.Blob or meshcast.Scene"):
        mcd.cast("bunny.blob", o, d)
    with pytest.raises(ValueError, match=r"origins: shape \(5, 3\)"):
        mcd.cast(blob, o[:5], d)
    with pytest.raises(ValueError, match=r"directions: shape \(40000, 2\)"):
        mcd.cast(blob, o, d[:, :2])
    with pytest.raises(ValueError, match=r"t_max: shape \(3,\)"):
        mcd.cast(blob, o, d, t_max=np.ones(3))
    with pytest.raises(ValueError, match="query=\"all\" takes"):
        mcd.cast(blob, np.float32([0, 0, 0]), d.reshape(200, 200, 3), query="all")
    with pytest.raises(TypeError, match="RaycastingScene"):
        mcd.cast_rays(blob, np.zeros((4, 6)))
    bad = d.copy()
    bad[12345] = np.nan
    with pytest.raises(ValueError, match="12345|non-finite|NaN"):
        mcd.cast(blob, da.from_array(o, chunks=(20000, 3)), da.from_array(bad, chunks=(20000, 3)))["t"].compute()
    # A mapped blob's file, gone or another on the workers (here: the one machine).
    path = tmp_path / "gone.blob"
    meshcast.build(v, f, layout="AABBTree/Float3").save(str(path))
    mapped = meshcast.load(path, mmap=True)
    meshcast.build(v + np.float32(0.5), f, layout="AABBTree/Float3").save(str(path))
    with pytest.raises(ValueError, match=r"worker tcp://.* on .*: the blob file .*gone\.blob has checksum"):
        mcd.cast(mapped, o, d)["t"].compute()
    os.remove(path)
    # Another graph (t_max): the scheduler may still hold the tasks that
    # failed above under the same keys, and answer with their error.
    with pytest.raises(FileNotFoundError, match=r"worker tcp://.*: the blob file .*gone\.blob is missing"):
        mcd.cast(mapped, o, d, t_max=1e30)["t"].compute()
