"""The package answers as the C++ library does, ray for ray: the same blob
file and the same rays cast by `meshcast trace` (the command-line program
of the same build, one thread and split over threads) give exactly the t
and the triangle of Blob.cast and of RaycastingScene.cast_rays.

The program is MESHCAST_CLI, or build/bin/meshcast of the repository; where
neither exists (a package installed alone) the tests are skipped."""

import os
import subprocess

import numpy as np
import pytest

import shapes
import meshcast

LAYOUT = "OctTreeCompressed/ClusterBitPackSOA8"

HERE = os.path.dirname(os.path.abspath(__file__))
CLI = os.environ.get("MESHCAST_CLI", os.path.join(HERE, "..", "..", "build", "bin", "meshcast"))


def write_rays(path, origins, directions, t_max):
    records = np.concatenate([origins, directions, t_max[:, None]], axis=1).astype(np.float32)
    with open(path, "wb") as f:
        f.write(b"RAYS" + np.uint32(len(records)).tobytes() + records.tobytes())


def read_hits(path):
    data = open(path, "rb").read()
    assert data[:4] == b"HITS", data[:4]
    count = int(np.frombuffer(data[4:8], np.uint32)[0])
    records = np.frombuffer(data[8:], dtype=[("t", np.float32), ("triangle", np.uint32)], count=count)
    return records["t"], records["triangle"]


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    if not os.access(CLI, os.X_OK):
        pytest.skip(f"no meshcast program at {CLI} (set MESHCAST_CLI)")
    tmp = tmp_path_factory.mktemp("library")
    vertices, triangles = shapes.sphere(rings=24, segments=40)
    extra_v, extra_t = shapes.soup(n=400, seed=5)
    triangles = np.concatenate([triangles, extra_t + len(vertices)])
    vertices = np.concatenate([vertices, extra_v]).astype(np.float32)
    blob = meshcast.build(vertices, triangles, layout=LAYOUT)
    blob.save(str(tmp / "mesh.mcb"))
    origins, directions = shapes.rays(vertices, 6000, seed=11)
    t_max = np.random.default_rng(3).choice(np.array([np.inf, 2.0, 5.0], np.float32), len(origins))
    write_rays(str(tmp / "rays.rays"), origins, directions, t_max)
    return tmp, vertices, triangles, blob, origins, directions, t_max


def trace(tmp, query, threads, rays="rays.rays"):
    out = str(tmp / f"{query}-{threads}-{rays}.hits")
    subprocess.run([CLI, "trace", str(tmp / "mesh.mcb"), "--rays", str(tmp / rays), "--out", out,
                    "--query", query, "--threads", str(threads), "--repeat", "1"], check=True,
                   stdout=subprocess.DEVNULL)
    return read_hits(out)


@pytest.mark.parametrize("query", ["closest", "any"])
def test_blob_cast_is_the_library(case, query):
    tmp, _, _, blob, origins, directions, t_max = case
    t, triangle = trace(tmp, query, 1)
    assert np.count_nonzero(triangle != meshcast.NO_HIT) > 1000
    for nthreads in (1, 0):
        got = blob.cast(origins, directions, t_max=t_max, query=query, nthreads=nthreads)
        np.testing.assert_array_equal(got["triangle"], triangle)
        np.testing.assert_array_equal(got["t"], t)
    # The loaded file, and the program splitting the batch over threads.
    loaded = meshcast.load(str(tmp / "mesh.mcb")).cast(origins, directions, t_max=t_max, query=query)
    np.testing.assert_array_equal(loaded["triangle"], triangle)
    t2, triangle2 = trace(tmp, query, 2)
    np.testing.assert_array_equal(triangle2, triangle)
    np.testing.assert_array_equal(t2, t)


def test_cast_rays_is_the_library(case):
    """RaycastingScene goes through a scene, the mesh stored about a centre
    rounded to a power of two at or above its extent: 0 for this mesh about
    the origin, so in the saved blob's layout the same walk gives the same
    answers."""
    tmp, vertices, triangles, _, origins, directions, _ = case
    write_rays(str(tmp / "unbounded.rays"), origins, directions, np.full(len(origins), np.inf, np.float32))
    t, triangle = trace(tmp, "closest", 1, "unbounded.rays")
    scene = meshcast.RaycastingScene(layout=LAYOUT)
    scene.add_triangles(vertices, triangles)
    got = scene.cast_rays(np.concatenate([origins, directions], axis=1))
    np.testing.assert_array_equal(np.asarray(got["primitive_ids"]), triangle)
    np.testing.assert_array_equal(np.asarray(got["t_hit"]), t)
