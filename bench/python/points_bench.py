"""Point queries: meshcast's compute_distance and compute_signed_distance
against Open3D's RaycastingScene, in one run.

    /usr/bin/python3 bench/python/points_bench.py [--build-dir build] [--points N] [--rounds R]
                                                  [--meshes a,b] [--out bench/results/point_queries]

For each mesh: a 64^3 grid of cell centres over its box (grown by 5%) and N
points uniform in the box grown by 20% (default 1,000,000). Contenders:
meshcast's RaycastingScene (the recommended, quantized layout), a meshcast
Blob in the exact OctTreeCompressed/Float3SOA8 layout (compute_distance
alone: Blob.closest_points), and Open3D's RaycastingScene where
``import open3d`` works (Debian 12: python3-open3d). Each is checked
against the exact blob first (distances within 1e-5 of the diagonal; the
signs' disagreements counted), then timed in interleaved rounds (the order
rotated each round), one thread and every core, medians. Open3D runs with
bench.py's Embree ray-mask shim preloaded (Debian's Open3D would miss every
ray of its inside test). Memory: bytes a
triangle, meshcast's structures by their nbytes, Open3D's by the growth
of the process's resident memory across add_triangles and a first query.
Writes DIR/points.csv and prints a Markdown table.
"""
import argparse
import csv
import os
import statistics
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))


def rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build-dir", default=os.path.join(REPO, "build"))
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--meshes", default="bunny00,armadillo,refined_elephant,ChineseDragon-10kv")
    ap.add_argument("--data", default=os.path.join(REPO, "data"))
    ap.add_argument("--out", default=os.path.join(REPO, "bench", "results", "point_queries"))
    a = ap.parse_args()
    # Debian's Open3D hands Embree rays of mask 0, which its Embree honours:
    # every ray misses, so every sign would be positive. The ray-mask shim
    # bench.py builds sets the mask; this process runs again with it.
    if "MESHCAST_POINTS_SHIM" not in os.environ:
        sys.path.insert(0, HERE)
        from bench import compile_shim
        import tempfile
        so, why = compile_shim(tempfile.mkdtemp())
        if so:
            env = dict(os.environ, MESHCAST_POINTS_SHIM="1", LD_PRELOAD=so)
            os.execve(sys.executable, [sys.executable] + sys.argv, env)
        print(f"Open3D's signs without the ray-mask shim ({why}): every ray misses", file=sys.stderr)
    sys.path.insert(0, os.path.join(a.build_dir, "python"))
    import meshcast
    try:
        import open3d as o3d
    except ImportError:
        o3d = None
        print("Open3D is not installed: its rows are left out", file=sys.stderr)
    cores = os.cpu_count()
    rows = []
    for name in a.meshes.split(","):
        v, t = meshcast.read_mesh(os.path.join(a.data, name + ".off"))
        lo, hi = v.min(0).astype(np.float64), v.max(0).astype(np.float64)
        size = hi - lo
        diagonal = float(np.linalg.norm(size))
        axes = [lo[k] - 0.05 * size[k] + (np.arange(64) + 0.5) * 1.1 * size[k] / 64 for k in range(3)]
        grid = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3).astype(np.float32)
        rng = np.random.default_rng(1)
        scattered = (lo - 0.2 * size + rng.uniform(0, 1.4, (a.points, 3)) * size).astype(np.float32)
        contenders = {}
        scene = meshcast.RaycastingScene()
        scene.add_triangles(v, t)
        contenders["meshcast"] = {"bytes": scene.nbytes,
                                  "distance": lambda p, n: scene.compute_distance(p, nthreads=n).numpy(),
                                  "signed": lambda p, n: scene.compute_signed_distance(p, nthreads=n).numpy()}
        exact = meshcast.build(v, t, layout="OctTreeCompressed/Float3SOA8")
        contenders["meshcast exact"] = {"bytes": exact.nbytes,
                                        "distance": lambda p, n: exact.closest_points(p, nthreads=n)["distance"]}
        if o3d is not None:
            before = rss_bytes()
            peer = o3d.t.geometry.RaycastingScene()
            peer.add_triangles(o3d.core.Tensor(v), o3d.core.Tensor(t.astype(np.uint32)))
            peer.compute_distance(o3d.core.Tensor(grid[:10]))
            contenders["Open3D"] = {
                "bytes": rss_bytes() - before,
                "distance": lambda p, n: peer.compute_distance(o3d.core.Tensor(p), nthreads=n).numpy(),
                "signed": lambda p, n: peer.compute_signed_distance(o3d.core.Tensor(p), nthreads=n).numpy()}
        # Correctness first, on a sample of both sets, against the exact blob.
        sample = np.concatenate([grid[::97], scattered[:3000]])
        truth = exact.closest_points(sample)["distance"]
        inside = scene.compute_signed_distance(sample).numpy() < 0
        checks = {}
        for who, c in contenders.items():
            d = c["distance"](sample, 0)
            error = float(np.max(np.abs(d - truth)) / diagonal)
            signs = int(np.sum((c["signed"](sample, 0) < 0) != inside)) if "signed" in c else 0
            checks[who] = (error, signs)
            print(f"{name}: {who} distances within {error:.2e} of the diagonal of the exact blob's; "
                  f"{signs} of {len(sample)} signs differ from meshcast's", file=sys.stderr)
        for set_name, points in (("64^3 grid", grid), (f"{a.points:,} scattered", scattered)):
            for query in ("distance", "signed"):
                for threads in (1, cores):
                    who = [w for w, c in contenders.items() if query in c]
                    times = {w: [] for w in who}
                    for r in range(a.rounds):
                        for w in who[r % len(who):] + who[:r % len(who)]:
                            t0 = time.perf_counter()
                            contenders[w][query](points, threads)
                            times[w].append(time.perf_counter() - t0)
                    for w in who:
                        ns = statistics.median(times[w]) / len(points) * 1e9
                        rows.append({"mesh": name, "triangles": len(t), "points": set_name, "query": query,
                                     "threads": threads, "contender": w, "ns_per_point": round(ns, 1),
                                     "bytes_per_triangle": round(contenders[w]["bytes"] / len(t), 1),
                                     "max_error_of_diagonal": checks[w][0], "sign_disagreements": checks[w][1]})
                        print(f"{name} {set_name} {query} {threads} thread(s): {w} {ns:.0f} ns a point",
                              file=sys.stderr)
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "points.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    print("| mesh | points | query | threads | contender | ns/point | B/tri |")
    print("|---|---|---|---:|---|---:|---:|")
    for r in rows:
        print(f"| {r['mesh']} | {r['points']} | {r['query']} | {r['threads']} | {r['contender']} | "
              f"{r['ns_per_point']:.0f} | {r['bytes_per_triangle']} |")


if __name__ == "__main__":
    main()
