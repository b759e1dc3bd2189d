"""Python threads casting at once, worker counts, and the GIL released."""

import threading
import time

import numpy as np
import pytest

import meshcast
import shapes
from cases import rays6


@pytest.fixture(scope="module")
def sphere_soup():
    v, f = shapes.sphere(rings=16, segments=24)
    pv, pf = shapes.soup(n=300, seed=8)
    v = np.concatenate([v, pv])
    f = np.concatenate([f, pf + len(v) - len(pv)]).astype(np.uint32)
    o, d = shapes.rays(v, 4000, seed=12)
    return v, f, o, d


def run_threads(n, work):
    """work(k) on n threads started together; their results (exceptions raised here)."""
    results, errors = [None] * n, []
    barrier = threading.Barrier(n)

    def body(k):
        try:
            barrier.wait()
            results[k] = work(k)
        except BaseException as e:  # reported below, not lost in the thread
            errors.append(e)

    threads = [threading.Thread(target=body, args=(k,)) for k in range(n)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    if errors:
        raise errors[0]
    return results


def same(a, b):
    for k in a:
        np.testing.assert_array_equal(np.asarray(a[k]), np.asarray(b[k]), err_msg=k)


def test_threads_share_one_blob(sphere_soup):
    v, f, o, d = sphere_soup
    b = meshcast.build(v, f)
    queries = ["closest", "any", "all", "closest"]
    ref = [b.cast(o, d, query=q, nthreads=1) for q in queries]
    got = run_threads(8, lambda k: [b.cast(o, d, query=queries[(k + j) % 4]) for j in range(3)])
    for k, answers in enumerate(got):
        for j, r in enumerate(answers):
            same(ref[(k + j) % 4], r)


def test_threads_share_one_raycasting_scene(sphere_soup):
    v, f, o, d = sphere_soup
    rc = meshcast.RaycastingScene()
    rc.add_triangles(v, f)
    rays = rays6(o, d)
    ref_hits = rc.cast_rays(rays, nthreads=1)
    ref_count = np.asarray(rc.count_intersections(rays, nthreads=1))

    def work(k):
        return rc.cast_rays(rays) if k % 2 == 0 else rc.count_intersections(rays)

    for k, r in enumerate(run_threads(6, work)):
        if k % 2 == 0:
            for key in ("t_hit", "primitive_ids", "geometry_ids", "primitive_uvs", "primitive_normals"):
                np.testing.assert_array_equal(np.asarray(r[key]), np.asarray(ref_hits[key]), err_msg=key)
        else:
            np.testing.assert_array_equal(np.asarray(r), ref_count)


def test_threads_share_one_scene(sphere_soup):
    v, f, o, d = sphere_soup
    s = meshcast.Scene()
    m = s.add_mesh(meshcast.build(v, f))
    s.add_instance(m)
    s.add_instance(m, translation=(0.5, 0.25, -0.125))
    s.commit()
    ref = s.cast(o, d, nthreads=1)
    for r in run_threads(4, lambda k: s.cast(o.astype(np.float64), d)):
        same(ref, r)


@pytest.mark.parametrize("query", ["closest", "any", "all"])
def test_nthreads_same_answers(sphere_soup, query):
    v, f, o, d = sphere_soup
    b = meshcast.build(v, f)
    one = b.cast(o, d, query=query, nthreads=1, uv=True)
    for n in (0, 2, 3):
        same(one, b.cast(o, d, query=query, nthreads=n, uv=True))
    rc = meshcast.RaycastingScene(nthreads=1)
    rc.add_triangles(v, f)
    rays = rays6(o, d)
    a = rc.list_intersections(rays)
    b2 = rc.list_intersections(rays, nthreads=0)
    for key in ("ray_splits", "primitive_ids", "t_hit"):
        np.testing.assert_array_equal(np.asarray(a[key]), np.asarray(b2[key]), err_msg=key)


def test_threads_build_at_once(sphere_soup):
    """Builds on several threads at once give the same bytes (the build also
    runs outside the GIL)."""
    v, f, o, d = sphere_soup
    ref = meshcast.build(v, f).cast(o, d)
    for r in run_threads(3, lambda k: meshcast.build(v, f, threads=k + 1).cast(o, d)):
        same(ref, r)


def spinner_rate(during):
    """Iterations a second of a pure-Python loop on another thread while
    during() runs on this one. The spinner notes the time every 4096
    iterations; the iterations between during()'s start and end are read off
    those notes (so its start-up and the end do not count)."""
    notes = []
    started = threading.Event()
    stop = threading.Event()

    def spinner():
        n = 0
        started.set()
        while not stop.is_set():
            n += 1
            if n & 0xFFF == 0:
                notes.append((time.perf_counter(), n))

    th = threading.Thread(target=spinner)
    th.start()
    started.wait()
    t0 = time.perf_counter()
    during()
    t1 = time.perf_counter()
    stop.set()
    th.join()
    inside = [n for t, n in notes if t0 <= t <= t1]
    return ((max(inside) - min(inside)) if len(inside) >= 2 else 0) / (t1 - t0)


@pytest.mark.parametrize("api", ["Blob.cast", "Scene.cast", "RaycastingScene.cast_rays"])
def test_gil_released_during_cast(api):
    """While this thread casts a large batch on one worker, a pure-Python loop
    on another thread keeps running. Were the GIL held for the whole call, the
    loop would stall for the cast's duration (a GIL-holding C call of the same
    length, sorted() of a long list, cuts its rate about a hundredfold). The
    bound is loose (a tenth of the loop's rate while this thread sleeps): the
    machine is shared."""
    v, f = shapes.sphere(rings=40, segments=60)
    b = meshcast.build(v, f)
    o, d = shapes.rays(v, 100_000, seed=1)
    if api == "Blob.cast":
        def cast():
            b.cast(o, d, nthreads=1)
    elif api == "Scene.cast":
        s = meshcast.Scene()
        s.add_instance(s.add_mesh(b), translation=(1.0, 2.0, 3.0))
        s.commit()
        o64 = o.astype(np.float64) + [1.0, 2.0, 3.0]

        def cast():
            s.cast(o64, d, nthreads=1)
    else:
        rc = meshcast.RaycastingScene(nthreads=1)
        rc.add_triangles(v, f)
        rays = rays6(o, d)

        def cast():
            rc.cast_rays(rays)
    cast()  # warm up
    # Enough casts for about 0.2 s.
    t0 = time.perf_counter()
    cast()
    reps = max(1, min(50, int(0.2 / max(time.perf_counter() - t0, 1e-4))))

    def casts():
        for _ in range(reps):
            cast()

    alone = spinner_rate(lambda: time.sleep(0.2))
    during = spinner_rate(casts)
    assert during > 0.1 * alone, (f"a Python thread ran {during:.0f} iterations/s during {api} against "
                                  f"{alone:.0f} while this thread slept: the cast seems to hold the GIL")


def test_a_forked_child_casts():
    """multiprocessing's fork on Linux: the child has the parent's worker
    pools but none of their threads; its casts make pools of its own."""
    import multiprocessing
    v, f = shapes.sphere()
    blob = meshcast.build(v, f)
    o, d = shapes.rays(v, 4000, seed=2)
    want = blob.cast(o, d, nthreads=2)["triangle"]
    ctx = multiprocessing.get_context("fork")
    with ctx.Pool(1) as pool:
        got = pool.apply_async(_cast_in_child, (blob.to_bytes(), o, d)).get(timeout=60)
    np.testing.assert_array_equal(got, want)


def _cast_in_child(data, o, d):
    return meshcast.from_bytes(data).cast(o, d, nthreads=2)["triangle"]
