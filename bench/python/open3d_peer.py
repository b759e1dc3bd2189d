"""Open3D's RaycastingScene as a benchmark peer, in a child process.

bench.py starts this file as a child (with or without the Embree ray-mask
shim in LD_PRELOAD) and drives it over a pipe: one JSON object a line in
(a request with "cmd"), one JSON object a line out (the answer, or
{"error": ...}). A child of its own lets the shim be preloaded for Open3D
alone, and lets the parent interleave Open3D's timed calls with meshcast's
round by round. Large arrays travel as .npy files, never over the pipe.

The protocol's lines go to the original stdout; everything else the child
or its libraries print goes to stderr, so a library's banner cannot break
the protocol.
"""
import json
import os
import sys
import time

import numpy as np


def rss_bytes():
    """This process's resident set (VmRSS) in bytes."""
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) * 1024
    raise RuntimeError("/proc/self/status has no VmRSS line")


def read_rays(path):
    """A RAYS file: b"RAYS", uint32 count, then 7 float32 a ray (origin, direction, t_max)."""
    with open(path, "rb") as f:
        head = f.read(8)
    if head[:4] != b"RAYS":
        raise ValueError(f"{path}: not a RAYS file (starts {head[:4]!r})")
    rays = np.fromfile(path, np.float32, offset=8).reshape(-1, 7)
    if len(rays) != int(np.frombuffer(head[4:], np.uint32)[0]):
        raise ValueError(f"{path}: header says {int(np.frombuffer(head[4:], np.uint32)[0])} rays, file holds {len(rays)}")
    return rays


class Peer:
    def __init__(self):
        import open3d as o3d
        self.o3d = o3d
        self.RS = o3d.t.geometry.RaycastingScene
        self.Tensor = o3d.core.Tensor
        self.scene = None
        self.vertices = self.triangles = None
        self.rays = {}  # name -> (N, 6) float32 numpy, C-contiguous
        self.tensors = {}  # name -> the same rays as an Open3D tensor

    def hello(self, req):
        return {"version": self.o3d.__version__,
                "shim": os.environ.get("LD_PRELOAD", ""),
                "malloc_mmap_threshold": os.environ.get("MALLOC_MMAP_THRESHOLD_", "")}

    def triangle_check(self, req):
        """One triangle (0,0,0),(1,0,0),(0,1,0); a ray down at its centroid from z=1: t=1, triangle 0,
        occluded, one crossing."""
        s = self.RS()
        s.add_triangles(self.Tensor(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)),
                        self.Tensor(np.array([[0, 1, 2]], np.uint32)))
        ray = self.Tensor(np.array([[1 / 3, 1 / 3, 1, 0, 0, -1]], np.float32))
        ans = s.cast_rays(ray)
        t = float(ans["t_hit"].numpy()[0])
        prim = int(ans["primitive_ids"].numpy()[0])
        occluded = bool(s.test_occlusions(ray).numpy()[0])
        count = int(s.count_intersections(ray).numpy()[0])
        ok = abs(t - 1.0) < 1e-6 and prim == 0 and occluded and count == 1
        return {"ok": ok, "t_hit": t, "primitive_id": prim, "occluded": occluded, "count": count}

    def mesh(self, req):
        """The mesh the later requests use; a scene of it, its BVH built by a first cast."""
        self.scene = None
        self.vertices = self.Tensor(np.ascontiguousarray(np.load(req["vertices"]), np.float32))
        self.triangles = self.Tensor(np.ascontiguousarray(np.load(req["triangles"]), np.uint32))
        if req.get("scene", True):
            self.scene = self.RS()
            self.scene.add_triangles(self.vertices, self.triangles)
            self.scene.cast_rays(self.Tensor(np.array([[0, 0, 0, 1, 0, 0]], np.float32)))
        self.rays.clear()
        self.tensors.clear()
        return {"triangles": int(self.triangles.shape[0])}

    def rays_file(self, req):
        rays = np.ascontiguousarray(read_rays(req["path"])[:, :6])
        self.rays[req["name"]] = rays
        self.tensors[req["name"]] = self.Tensor(rays)
        return {"rays": len(rays)}

    def cast(self, req):
        """One timed call: closest (cast_rays), any (test_occlusions, tnear 0, tfar given) or count
        (count_intersections) on a loaded rays set, or on its first `first` rays with the answer
        saved to `out` (for the answer checks)."""
        op, nthreads = req["op"], int(req.get("nthreads", 0))
        rays = self.tensors[req["rays"]]
        if req.get("first"):
            rays = self.Tensor(np.ascontiguousarray(self.rays[req["rays"]][:req["first"]]))
        tfar = float(req.get("tfar", np.inf))
        start = time.perf_counter()
        if op == "closest":
            ans = self.scene.cast_rays(rays, nthreads=nthreads)
        elif op == "any":
            ans = self.scene.test_occlusions(rays, tnear=0.0, tfar=tfar, nthreads=nthreads)
        elif op == "count":
            ans = self.scene.count_intersections(rays, nthreads=nthreads)
        else:
            raise ValueError(f"cast: op {op!r} is not closest, any or count")
        seconds = time.perf_counter() - start
        reply = {"seconds": seconds}
        if req.get("out"):
            if op == "closest":
                np.savez(req["out"], t=ans["t_hit"].numpy(), primitive=ans["primitive_ids"].numpy())
            else:
                np.savez(req["out"], answer=ans.numpy())
        if op == "closest":
            reply["hits"] = int(np.isfinite(ans["t_hit"].numpy()).sum())
        elif op == "any":
            reply["hits"] = int(ans.numpy().sum())
        else:
            reply["hits"] = int((ans.numpy() > 0).sum())
            reply["crossings"] = int(ans.numpy().sum())
        return reply

    def build(self, req):
        """A fresh scene: RaycastingScene(nthreads) + add_triangles + the first cast_rays of one ray
        (Open3D builds the BVH lazily, on the first query). Its time, and the resident growth from
        before add_triangles to after the first cast (honest with MALLOC_MMAP_THRESHOLD_ set, so
        that freed memory goes back to the system). The scene of `mesh` is kept."""
        nthreads = int(req.get("nthreads", 0))
        one = self.Tensor(np.array([[0, 0, 0, 1, 0, 0]], np.float32))
        before = rss_bytes()
        start = time.perf_counter()
        scene = self.RS(nthreads=nthreads)
        scene.add_triangles(self.vertices, self.triangles)
        added = time.perf_counter()
        scene.cast_rays(one, nthreads=nthreads)
        seconds = time.perf_counter() - start
        after = rss_bytes()
        del scene
        return {"seconds": seconds, "add_seconds": added - start, "rss_growth": after - before}

    def requery(self, req):
        """Every hit as Open3D 0.16.1's users find them: cast_rays, move each ray that hit past its hit
        (o + (t_hit + eps / |d|) d, eps a distance), cast again the rays that hit, until none hits.
        Hits' t are along the original ray. Saved to `out` (ray, t, primitive) when asked."""
        rays = np.array(self.rays[req["rays"]][:int(req["n"])], np.float32)
        nthreads, eps = int(req.get("nthreads", 0)), float(req["eps"])
        limit = int(req.get("max_rounds", 100000))
        start = time.perf_counter()
        eps_t = (eps / np.linalg.norm(rays[:, 3:], axis=1)).astype(np.float32)
        ids = np.arange(len(rays))
        travelled = np.zeros(len(rays), np.float32)
        found_ray, found_t, found_prim = [], [], []
        passes = 0
        while len(ids) and passes < limit:
            ans = self.scene.cast_rays(self.Tensor(rays), nthreads=nthreads)
            t = ans["t_hit"].numpy()
            hit = np.isfinite(t)
            ids, rays, t, travelled = ids[hit], rays[hit], t[hit], travelled[hit]
            found_ray.append(ids)
            found_t.append(travelled + t)
            found_prim.append(ans["primitive_ids"].numpy()[hit])
            step = t + eps_t[ids]
            rays[:, :3] += step[:, None] * rays[:, 3:]
            travelled = travelled + step
            passes += 1
        seconds = time.perf_counter() - start
        ray = np.concatenate(found_ray) if found_ray else np.zeros(0, np.int64)
        if req.get("out"):
            np.savez(req["out"], ray=ray, t=np.concatenate(found_t) if found_t else np.zeros(0, np.float32),
                     primitive=np.concatenate(found_prim) if found_prim else np.zeros(0, np.uint32))
        return {"seconds": seconds, "hits": int(len(ray)), "passes": passes, "unfinished": int(len(ids))}

    def quit(self, req):
        return {"bye": True}


COMMANDS = ("hello", "triangle_check", "mesh", "rays_file", "cast", "build", "requery", "quit")


def main():
    protocol = os.fdopen(os.dup(1), "w", buffering=1)
    os.dup2(2, 1)  # anything else printed to stdout (Python or C) lands on stderr
    peer = Peer()
    for line in sys.stdin:
        if not line.strip():
            continue
        req = json.loads(line)
        try:
            if req.get("cmd") not in COMMANDS:
                raise ValueError(f"unknown command {req.get('cmd')!r} (one of {', '.join(COMMANDS)})")
            reply = getattr(peer, req["cmd"])(req)
        except Exception as e:  # the parent reports it with the request
            reply = {"error": f"{type(e).__name__}: {e}"}
        protocol.write(json.dumps(reply) + "\n")
        if req.get("cmd") == "quit":
            break


if __name__ == "__main__":
    main()
