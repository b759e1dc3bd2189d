"""The inside test by winding number beside parity, and the winding
number's own cost and bound, on one thread (RaycastingScene).

    PYTHONPATH=build/python /usr/bin/python3 bench/python/winding_bench.py [--mesh data/bunny00.off]

Points are uniform through the mesh's box grown by a tenth a side; each
figure is the median of --rounds interleaved rounds, in microseconds a
point."""

import argparse
import statistics
import time

import numpy as np

import meshcast


def timed(fn, points):
    start = time.perf_counter()
    answer = fn(points)
    return (time.perf_counter() - start) / len(points) * 1e6, answer


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh", default="data/bunny00.off")
    parser.add_argument("--points", type=int, default=20000)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    vertices, triangles = meshcast.read_mesh(args.mesh)
    scene = meshcast.RaycastingScene(nthreads=1)
    scene.add_triangles(vertices, triangles)
    scene.count_intersections(np.zeros((1, 6), np.float32) + [0, 0, 0, 1, 0, 0])
    before = scene.nbytes
    lo, hi = vertices.min(0), vertices.max(0)
    rng = np.random.default_rng(1)
    points = (lo + rng.uniform(-0.1, 1.1, (args.points, 3)) * (hi - lo)).astype(np.float32)
    calls = {
        "inside by parity": lambda p: scene.compute_occupancy(p).numpy(),
        "inside by winding number": lambda p: scene.compute_occupancy(p, sign="winding").numpy(),
        "winding number, tolerance 0.3": lambda p: scene.compute_winding_number(p, tolerance=0.3),
        "winding number, tolerance 1e-2": lambda p: scene.compute_winding_number(p),  # on a tenth of the points
        "closest points": lambda p: scene.compute_distance(p).numpy(),
    }
    times = {name: [] for name in calls}
    answers = {}
    for _ in range(args.rounds):
        for name, fn in calls.items():
            subset = points[: len(points) // 10] if name.endswith("1e-2") else points
            seconds, answers[name] = timed(fn, subset)
            times[name].append(seconds)
    print(f"{args.mesh}: {len(triangles)} triangles, {args.points} points, {args.rounds} rounds, one thread")
    for name in calls:
        print(f"  {name}: {statistics.median(times[name]):.2f} us a point")
    for name in ("winding number, tolerance 0.3", "winding number, tolerance 1e-2"):
        bound = answers[name]["bound"].numpy()
        print(f"  {name}: bound median {np.median(bound):.2g}, largest {bound.max():.2g}")
    differ = int((answers["inside by parity"] != answers["inside by winding number"]).sum())
    print(f"  inside: {differ} of {args.points} points differ between parity and winding number")
    print(f"  memory: the scene {before / len(triangles):.1f} B/tri, "
          f"the winding clusters {(scene.nbytes - before) / len(triangles):.1f} B/tri more")


if __name__ == "__main__":
    main()
