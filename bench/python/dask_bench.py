"""meshcast.dask on a LocalCluster against the in-process cast, on the same machine and rays.

    /usr/bin/python3 bench/python/dask_bench.py [--build-dir build] [--out bench/results/dask]
                                                [--chunks 1e4,1e5,1e6,1e7] [--rounds 3]

For each chunk size, a batch of closest-hit casts (4 million rays, or two
chunks where that is more) three ways: in process on every core;
meshcast.dask.cast on a LocalCluster of one worker process with a thread a
core; and on one of a worker process a core with a thread each (the blob
sent to the workers once, before timing). Two kinds of batch: rays "from
the client" (numpy arrays there, t and triangle gathered back: the rays
and answers travel, as when a script casts arrays it holds) and rays "made
on the workers" (each chunk's rays made from its seed where it is cast,
only each chunk's count of hits back, as a dataset's pipeline would; in
process, the same chunks made and cast one after another). Interleaved
rounds, medians. Writes DIR/dask.csv, DIR/dask.png (gnuplot: rays a second
against the chunk size) and prints a Markdown table: rays a second, the
cluster's time over in-process, the time it adds a chunk in milliseconds
((cluster - in process) / chunks), and the smallest chunk at which each
cluster is within 10% of in-process.
"""
import argparse
import csv
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
from bench import interleaved, log, median, processor_name, run_gnuplot  # noqa: E402

LAYOUT = "OctTreeCompressed/ClusterBitPackSOA8"


def rays_at(vertices, n, seed):
    # From a sphere around the mesh toward random points of its box.
    rng = np.random.default_rng(seed)
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    centre, diag = (lo + hi) / 2, float(np.linalg.norm(hi - lo))
    d = rng.normal(size=(n, 3)).astype(np.float32)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    origins = (centre + diag * d).astype(np.float32)
    directions = (rng.uniform(lo, hi, (n, 3)).astype(np.float32) - origins)
    return origins, directions


def chunk_rays(seed, n, box):
    """A chunk's rays, made from its seed: (n, 6) float32."""
    origins, directions = rays_at(np.array(box), n, seed)
    return np.concatenate([origins, directions], axis=1)


def contenders_of(mode, blob, box, n, chunk, clients, dask, da, mcd):
    """[(name, fn)]: fn() casts n rays (closest hits) and returns its seconds.

    "from the client": numpy rays in the client, answered with t and
    triangle gathered back (the rays and answers travel). "made on the
    workers": each chunk's rays made from its seed where it is cast, and
    only each chunk's count of hits back; in process, the same chunks made
    and cast one after another on every core."""
    chunks = n // chunk
    if mode == "from the client":
        rays = np.concatenate([chunk_rays(seed, chunk, box) for seed in range(chunks)])
        origins, directions = rays[:, :3], rays[:, 3:]
        expected = blob.cast(origins, directions)

        def in_process():
            start = time.perf_counter()
            blob.cast(origins, directions)
            return time.perf_counter() - start

        def on(client):
            def run():
                with client.as_current():
                    answer = mcd.cast(blob, da.from_array(origins, chunks=(chunk, 3)),
                                      da.from_array(directions, chunks=(chunk, 3)))
                start = time.perf_counter()
                got = dask.compute(answer["t"], answer["triangle"], scheduler=client)
                seconds = time.perf_counter() - start
                assert np.array_equal(got[0], expected["t"]) and np.array_equal(got[1], expected["triangle"])
                return seconds
            return run
    else:
        expected = sum(int(np.isfinite(blob.cast(r[:, :3], r[:, 3:])["t"]).sum())
                       for r in (chunk_rays(seed, chunk, box) for seed in range(chunks)))

        def in_process():
            start = time.perf_counter()
            hits = 0
            for seed in range(chunks):
                r = chunk_rays(seed, chunk, box)
                hits += int(np.isfinite(blob.cast(r[:, :3], r[:, 3:])["t"]).sum())
            seconds = time.perf_counter() - start
            assert hits == expected
            return seconds

        def on(client):
            def run():
                with client.as_current():
                    seeds = da.arange(chunks, chunks=1)
                    rays = seeds.map_blocks(lambda s: chunk_rays(int(s[0]), chunk, box), dtype=np.float32,
                                            chunks=((chunk,) * chunks, (6,)), new_axis=1)
                    answer = mcd.cast(blob, rays[:, :3], rays[:, 3:])
                    hits = da.isfinite(answer["t"]).sum()
                start = time.perf_counter()
                got = int(dask.compute(hits, scheduler=client)[0])
                seconds = time.perf_counter() - start
                assert got == expected
                return seconds
            return run

    return [("in process", in_process)] + [(name, on(c)) for name, c in clients.items()]


def plot(out_dir, rows, cpu):
    png = os.path.join(out_dir, "dask.png")
    script = png + ".gp"
    with open(script, "w") as gp:
        gp.write("set terminal pngcairo noenhanced size 1000,600 font 'sans,10'\n")
        gp.write(f"set output '{png}'\nset logscale x\nset grid\nset key bottom right\n")
        gp.write(f"set title 'meshcast.dask on a LocalCluster against the in-process cast, closest hits ({cpu})'\n")
        gp.write("set xlabel 'rays a chunk'\nset ylabel 'million rays a second (wall time)'\n")
        gp.write("set yrange [0:*]\nset format x '10^%T'\n")
        series = list(dict.fromkeys((r["rays_are"], r["contender"]) for r in rows))
        gp.write("plot " + ", ".join(f"'-' using 1:2 with linespoints lw 2 dt {1 if mode == 'made on the workers' else 2} "
                                     f"title '{who}, rays {mode}'" for mode, who in series) + "\n")
        for key in series:
            for r in rows:
                if (r["rays_are"], r["contender"]) == key:
                    gp.write(f"{r['chunk']} {r['mrays_per_s']}\n")
            gp.write("e\n")
    return run_gnuplot(script)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build-dir", default=os.path.join(REPO, "build"))
    ap.add_argument("--out", default=os.path.join(REPO, "bench", "results", "dask"))
    ap.add_argument("--chunks", default="1e4,1e5,1e6,1e7")
    ap.add_argument("--rays", type=float, default=4e6, help="rays a batch (at least two chunks)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--mesh", default=os.path.join(REPO, "data", "bunny00.off"))
    a = ap.parse_args()
    sys.path.insert(0, os.path.join(a.build_dir, "python"))
    import dask
    import dask.array as da
    from distributed import Client, LocalCluster

    import meshcast
    import meshcast.dask as mcd

    os.makedirs(a.out, exist_ok=True)
    cpu = processor_name()
    cores = os.cpu_count()
    v, t = meshcast.read_mesh(a.mesh)
    blob = meshcast.build(v, t, layout=LAYOUT, name=os.path.basename(a.mesh))
    log(f"{blob}; {cpu}, {cores} cores")
    clusters = {
        f"1 worker x {cores} threads": LocalCluster(n_workers=1, threads_per_worker=cores, dashboard_address=None,
                                                    silence_logs=40),
        f"{cores} workers x 1 thread": LocalCluster(n_workers=cores, threads_per_worker=1, dashboard_address=None,
                                                    silence_logs=40),
    }
    clients = {name: Client(c, set_as_default=False) for name, c in clusters.items()}
    rows = []
    box = (np.asarray(v).min(axis=0), np.asarray(v).max(axis=0))
    for mode in ("from the client", "made on the workers"):
        for chunk in [int(float(c)) for c in a.chunks.split(",")]:
            n = max(int(a.rays) // chunk, 2) * chunk
            contenders = contenders_of(mode, blob, box, n, chunk, clients, dask, da, mcd)
            for _, fn in contenders:  # warm: the blob sent, the pools made
                fn()
            samples = interleaved(contenders, a.rounds)
            base = median(samples["in process"])
            for name, seconds in samples.items():
                s = median(seconds)
                chunks = n // chunk
                rows.append({"rays_are": mode, "chunk": chunk, "rays": n, "chunks": chunks, "contender": name,
                             "seconds": round(s, 4), "mrays_per_s": round(n / s / 1e6, 3),
                             "over_in_process": round(s / base, 3),
                             "ms_added_per_chunk": round(1e3 * (s - base) / chunks, 3) if name != "in process" else 0.0})
                log(rows[-1])
    for c in clients.values():
        c.close()
    for c in clusters.values():
        c.close()
    with open(os.path.join(a.out, "dask.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    note = plot(a.out, rows, cpu)
    print(f"Closest hits on {os.path.basename(a.mesh)} ({blob.triangle_count:,} triangles, {LAYOUT}); {cpu}, "
          f"{cores} cores; medians of {a.rounds} interleaved rounds.\n")
    print("| rays | rays a chunk | rays in all | contender | Mrays/s | time / in process | ms added a chunk |")
    print("|---|---:|---:|---|---:|---:|---:|")
    for r in rows:
        print(f"| {r['rays_are']} | {r['chunk']:,} | {r['rays']:,} | {r['contender']} | {r['mrays_per_s']} | "
              f"{r['over_in_process']} | {r['ms_added_per_chunk']} |")
    for mode in ("from the client", "made on the workers"):
        for name in clients:
            within = [r["chunk"] for r in rows
                      if r["rays_are"] == mode and r["contender"] == name and r["over_in_process"] <= 1 / 0.9]
            print(f"\nRays {mode}, {name}: " + (f"within 10% of in-process from {min(within):,} rays a chunk"
                                                 if within else "never within 10% of in-process here"))
    if note:
        print("\n" + note)


if __name__ == "__main__":
    main()
