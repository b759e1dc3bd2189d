"""A simulated LiDAR dataset, cast over a Dask cluster.

A sensor of 64 x 1,024 beams (64 elevations from -25 to +15 degrees, 1,024
azimuths) rides a path over a generated terrain of 2,097,152 triangles; at
each of N poses it sweeps once. Each pose is one chunk of rays, made and
cast on a worker; its depth (inf where a beam misses) and hit triangle are
written to OUT/pose_00000.npz, ... as they finish.

  /usr/bin/python3 examples/python/lidar_dataset.py --poses 64 --out out/lidar
  /usr/bin/python3 examples/python/lidar_dataset.py --scheduler tcp://HOST:8786 --blob /shared/terrain.blob

Without --scheduler a LocalCluster of one worker process with a thread per
core runs here. The terrain's blob reaches the workers one of two ways: with
--blob PATH it is saved there (if missing) and mapped by each worker from
that path (a file on storage every worker reads); without it, it is built
here and sent to every worker once, as its bytes.
"""

import argparse
import os
import time

import dask
import dask.array as da
import numpy as np
from distributed import Client, LocalCluster, progress, wait

import meshcast
import meshcast.dask as mcd

ELEVATIONS, AZIMUTHS = 64, 1024


def terrain(cells=1024):
    """A heightfield of cells x cells squares, two triangles each: rolling
    hills of four octaves of sines, one unit a cell."""
    x = np.arange(cells + 1, dtype=np.float64)
    height = np.zeros((cells + 1, cells + 1))
    for octave, (wx, wy, px, py) in enumerate([(71, 59, 0.3, 1.9), (37, 29, 2.1, 0.7), (17, 19, 4.0, 3.1),
                                              (9, 7, 5.2, 2.4)]):
        height += 8.0 / 2**octave * np.outer(np.sin(2 * np.pi * x / wy + py), np.sin(2 * np.pi * x / wx + px))
    gx, gy = np.meshgrid(x, x)
    vertices = np.stack([gx, gy, height], axis=-1).reshape(-1, 3).astype(np.float32)
    corner = (np.arange(cells)[:, None] * (cells + 1) + np.arange(cells)[None, :]).ravel()
    a, b, c, d = corner, corner + 1, corner + cells + 2, corner + cells + 1
    triangles = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)]).astype(np.uint32)
    return vertices, triangles, height


def poses(count, height, cells=1024):
    """x, y, z, yaw of each pose: a loop around the terrain's middle, the
    sensor 2 units above the ground under it."""
    angle = np.linspace(0, 2 * np.pi, count, endpoint=False)
    x = cells / 2 + 0.35 * cells * np.cos(angle)
    y = cells / 2 + 0.35 * cells * np.sin(angle)
    ground = height[np.round(y).astype(int), np.round(x).astype(int)]
    return np.stack([x, y, ground + 2.0, angle + np.pi / 2], axis=1)


def beams(pose):
    """The sweep's origins and directions at a pose (x, y, z, yaw, in any
    shape of 4 numbers): (1, 64, 1024, 3) each."""
    x, y, z, yaw = np.asarray(pose, np.float64).reshape(4)
    elevation = np.radians(np.linspace(-25.0, 15.0, ELEVATIONS))[:, None]
    azimuth = yaw + np.linspace(0, 2 * np.pi, AZIMUTHS, endpoint=False)[None, :]
    directions = np.stack(np.broadcast_arrays(np.cos(elevation) * np.cos(azimuth),
                                              np.cos(elevation) * np.sin(azimuth), np.sin(elevation)), axis=-1)
    origins = np.broadcast_to(np.array([x, y, z]), directions.shape)
    return origins[None].astype(np.float32), directions[None].astype(np.float32)


def save(path, depth, triangle):
    np.savez_compressed(path, depth=depth[0], triangle=triangle[0])
    return path


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--poses", type=int, default=32, help="sensor poses along the path (default 32)")
    parser.add_argument("--out", default="out/lidar", help="folder for the poses' .npz files (default out/lidar)")
    parser.add_argument("--scheduler", help="a Dask scheduler's address (default: a LocalCluster here)")
    parser.add_argument("--blob", help="the terrain's blob file, mapped by every worker (made if missing)")
    parser.add_argument("--max-range", type=float, default=200.0, help="the beams' range (default 200)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)

    vertices, triangles, height = terrain()
    if args.blob:
        if not os.path.exists(args.blob):
            meshcast.build(vertices, triangles, name="terrain").save(args.blob)
        blob = meshcast.load(args.blob, mmap=True)  # travels as its path
    else:
        blob = meshcast.build(vertices, triangles, name="terrain")  # travels as its bytes, once a worker

    with (Client(args.scheduler) if args.scheduler else
          Client(LocalCluster(n_workers=1, threads_per_worker=os.cpu_count(), dashboard_address=None))) as client:
        workers = client.scheduler_info()["workers"]
        print(f"{blob}; {len(workers)} worker(s), {sum(w['nthreads'] for w in workers.values())} threads")
        # The poses travel (16 bytes each); each worker makes its poses' rays.
        pose_array = da.from_array(poses(args.poses, height), chunks=(1, 4))
        shape = (args.poses, ELEVATIONS, AZIMUTHS, 3)
        chunks = ((1,) * args.poses, (ELEVATIONS,), (AZIMUTHS,), (3,))
        origins = da.map_blocks(lambda p: beams(p)[0], pose_array[:, None, None, :], dtype=np.float32, chunks=chunks)
        directions = da.map_blocks(lambda p: beams(p)[1], pose_array[:, None, None, :], dtype=np.float32,
                                   chunks=chunks)
        assert directions.shape == shape
        answer = mcd.cast(blob, origins, directions, t_max=args.max_range)
        writes = [dask.delayed(save)(os.path.join(args.out, f"pose_{i:05d}.npz"), t, tri)
                  for i, (t, tri) in enumerate(zip(answer["t"].to_delayed().ravel(),
                                                   answer["triangle"].to_delayed().ravel()))]
        start = time.perf_counter()
        futures = client.compute(writes)
        progress(futures)
        wait(futures)
        paths = client.gather(futures)
        seconds = time.perf_counter() - start
    rays = args.poses * ELEVATIONS * AZIMUTHS
    first = np.load(paths[0])
    print(f"\n{args.poses} poses, {rays:,} rays in {seconds:.2f} s: {rays / seconds / 1e6:.2f} million rays a second; "
          f"{np.isfinite(first['depth']).mean():.0%} of the first pose's beams hit; files in {args.out}/")


if __name__ == "__main__":
    main()
