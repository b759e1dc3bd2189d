"""Point queries: meshcast's compute_distance and compute_signed_distance
against Open3D's RaycastingScene, in one run.

    /usr/bin/python3 bench/python/points_bench.py [--build-dir build] [--points N] [--rounds R]
                                                  [--meshes a,b] [--out bench/results/point_queries]

For each mesh: a 64^3 grid of cell centres over its box (grown by 5%) and N
points uniform in the box grown by 20% (default 1,000,000). Contenders:
meshcast's RaycastingScene as built by default (exact:
OctTreeCompressed/ClusterFloat3SOA8), and Open3D's RaycastingScene where
``import open3d`` works (Debian 12: python3-open3d). Each is checked
against an exact blob first (distances within 1e-5 of the diagonal; the
signs' disagreements counted), then timed in interleaved rounds (the order
rotated each round), one thread and every core, medians. Open3D runs with
bench.py's Embree ray-mask shim preloaded (Debian's Open3D would miss every
ray of its inside test). The same scene with max_error=1e-5 (the compact,
quantized cluster) is checked and measured for memory, not timed. Memory,
bytes a triangle: the growth of a fresh process's resident memory across
add_triangles and a first query (one process a contender and mesh, the
mesh's arrays read and the library warmed by a scene of 64 of its
triangles before), and meshcast's structures by their nbytes beside it. Writes DIR/points.csv and
DIR/points.png (gnuplot: each time against Open3D's) and prints a Markdown
table.
"""
import argparse
import csv
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))


def rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def make_scene(meshcast, o3d, who, v, t):
    """The contender's scene with the mesh added."""
    if who == "Open3D":
        peer = o3d.t.geometry.RaycastingScene()
        peer.add_triangles(o3d.core.Tensor(v), o3d.core.Tensor(t.astype(np.uint32)))
        return peer
    scene = meshcast.RaycastingScene(max_error=1e-5 if who == "meshcast compact" else 0.0)
    scene.add_triangles(v, t)
    return scene


def memory_of(build_dir, who, path):
    """Run in a process of its own: the resident memory a contender's scene
    adds (add_triangles and a first query of 10 points), in bytes."""
    sys.path.insert(0, os.path.join(build_dir, "python"))
    import meshcast
    o3d = None
    if who == "Open3D":
        import open3d as o3d
    v, t = meshcast.read_mesh(path)
    probe = v[:10].astype(np.float32)

    def query(scene):
        scene.compute_distance(o3d.core.Tensor(probe) if o3d is not None else probe)

    # The library's own start-up outside the figure, for both alike: its
    # code paged in, its threads started, by a scene of the mesh's first 64
    # triangles queried once and dropped.
    few = t[:64]
    used = np.unique(few)
    query(make_scene(meshcast, o3d, who, v[used], np.searchsorted(used, few).astype(t.dtype)))
    before = rss_bytes()
    scene = make_scene(meshcast, o3d, who, v, t)
    query(scene)
    print(json.dumps({"bytes": rss_bytes() - before}))


def plot(out_dir, rows):
    """points.png: each meshcast time over Open3D's on the same row, a bar a
    row, one thread and every core. Returns a note on failure, else ""."""
    png = os.path.join(out_dir, "points.png")
    script = png + ".gp"
    peer = {(r["mesh"], r["points"], r["query"], r["threads"]): r["ns_per_point"]
            for r in rows if r["contender"] == "Open3D"}
    labels, series = [], {}
    for r in rows:
        key = (r["mesh"], r["points"], r["query"], r["threads"])
        if r["contender"] == "Open3D" or key not in peer:
            continue
        label = f"{r['mesh']} {r['points']} {r['query']}"
        if label not in labels:
            labels.append(label)
        series.setdefault((r["contender"], r["threads"]), {})[label] = r["ns_per_point"] / peer[key]
    if not series:
        return "no Open3D rows: points.png not drawn"
    with open(script, "w") as gp:
        gp.write("set terminal pngcairo noenhanced size 1300,750 font 'sans,10'\nset bmargin 13\nset rmargin 12\n")
        gp.write(f"set output '{png}'\n")
        gp.write("set title 'Point queries: time over Open3D 0.16.1 RaycastingScene (below 1: faster; the target 0.5)'\n")
        gp.write("set style data histograms\nset style histogram cluster gap 1\nset style fill solid 0.8 border -1\n")
        gp.write("set boxwidth 0.9\nset xtics rotate by -35 scale 0\nset ylabel 'time / Open3D time'\nset grid ytics\n")
        gp.write("set yrange [0:*]\nset key top left\nset arrow from graph 0, first 1 to graph 1, first 1 nohead lw 2\n")
        gp.write("set arrow from graph 0, first 0.5 to graph 1, first 0.5 nohead dt 2\n")
        gp.write("plot " + ", ".join(f"'-' using 2:xtic(1) title '{who}, {threads} thread(s)'"
                                       for (who, threads) in series) + "\n")
        for values in series.values():
            for label in labels:
                gp.write(f"\"{label}\" {values.get(label, 0)}\n")
            gp.write("e\n")
    sys.path.insert(0, HERE)
    from bench import run_gnuplot
    return run_gnuplot(script)


def main():
    if len(sys.argv) == 5 and sys.argv[1] == "--memory-of":
        return memory_of(sys.argv[2], sys.argv[3], sys.argv[4])
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
        path = os.path.join(a.data, name + ".off")
        for who in ("meshcast", "meshcast compact") + (("Open3D",) if o3d is not None else ()):
            measured = subprocess.run([sys.executable, __file__, "--memory-of", a.build_dir, who, path],
                                      capture_output=True, text=True, check=True)
            memory = json.loads(measured.stdout.strip().splitlines()[-1])["bytes"]
            scene = make_scene(meshcast, o3d, who, v, t)
            if who == "Open3D":
                contenders[who] = {
                    "bytes": memory, "nbytes": 0,
                    "distance": lambda p, n, s=scene: s.compute_distance(o3d.core.Tensor(p), nthreads=n).numpy(),
                    "signed": lambda p, n, s=scene: s.compute_signed_distance(o3d.core.Tensor(p), nthreads=n).numpy()}
            else:
                # The compact layout's rows: its memory and error (its time
                # differs from the exact one's as on the ray rows).
                contenders[who] = {"bytes": memory, "nbytes": scene.nbytes, "timed": who == "meshcast",
                                   "distance": lambda p, n, s=scene: s.compute_distance(p, nthreads=n).numpy(),
                                   "signed": lambda p, n, s=scene: s.compute_signed_distance(p, nthreads=n).numpy()}
        # Correctness first, on a sample of both sets, against an exact blob.
        exact = meshcast.build(v, t, layout="OctTreeCompressed/Float3SOA8")
        sample = np.concatenate([grid[::97], scattered[:3000]])
        truth = exact.closest_points(sample)["distance"]
        inside = contenders["meshcast"]["signed"](sample, 0) < 0
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
                    who = [w for w, c in contenders.items() if query in c and c.get("timed", True)]
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
                                     "process_bytes_per_triangle": round(contenders[w]["bytes"] / len(t), 1),
                                     "nbytes_per_triangle": round(contenders[w]["nbytes"] / len(t), 1),
                                     "max_error_of_diagonal": checks[w][0], "sign_disagreements": checks[w][1]})
                        print(f"{name} {set_name} {query} {threads} thread(s): {w} {ns:.0f} ns a point",
                              file=sys.stderr)
        for w, c in contenders.items():
            if not c.get("timed", True):
                rows.append({"mesh": name, "triangles": len(t), "points": "", "query": "memory and error", "threads": 0,
                             "contender": w, "ns_per_point": 0.0,
                             "process_bytes_per_triangle": round(c["bytes"] / len(t), 1),
                             "nbytes_per_triangle": round(c["nbytes"] / len(t), 1),
                             "max_error_of_diagonal": checks[w][0], "sign_disagreements": checks[w][1]})
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "points.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    note = plot(a.out, rows)
    if note:
        print(note, file=sys.stderr)
    peer = {(r["mesh"], r["points"], r["query"], r["threads"]): r["ns_per_point"]
            for r in rows if r["contender"] == "Open3D"}
    print("| mesh | points | query | threads | contender | ns/point | / Open3D | B/tri (process) | B/tri (nbytes) |")
    print("|---|---|---|---:|---|---:|---:|---:|---:|")
    for r in rows:
        key = (r["mesh"], r["points"], r["query"], r["threads"])
        ratio = f"{r['ns_per_point'] / peer[key]:.2f}" if key in peer else ""
        print(f"| {r['mesh']} | {r['points']} | {r['query']} | {r['threads']} | {r['contender']} | "
              f"{r['ns_per_point']:.0f} | {ratio} | {r['process_bytes_per_triangle']} | {r['nbytes_per_triangle'] or ''} |")


if __name__ == "__main__":
    main()
