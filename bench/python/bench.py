"""meshcast's Python package against the C++ library and Open3D's RaycastingScene, in one run.

    /usr/bin/python3 bench/python/bench.py [--build-dir build] [--out bench/results/python]
                                           [--rays N] [--rounds R] [--quick]

Writes Markdown tables to stdout and DIR/bench.md, every row to DIR/bench.csv and the all-hits
scaling plot to DIR/all_hits.png (gnuplot). See bench/python/README.md.
"""
import argparse
import csv
import datetime
import gc
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import traceback
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
from open3d_peer import read_rays  # noqa: E402

DEFAULT_LAYOUT = "OctTreeCompressed/ClusterBitPackSOA8"
KINDS = ("long", "probe", "radial")
QUERIES = ("closest", "any", "count", "all")
ALL_HITS_KEPT = 4096  # the most hits a ray keeps (meshcast's limit): "all" lists every hit
CHECK_RAYS = 2000  # rays a set whose answers are compared across peers before timing
T_AGREE = 1e-4  # relative t agreement of two peers' closest hits
POINT_AGREE = 1e-4  # hit point agreement, a fraction of the mesh's diagonal
GENERATED = ("terrain_2M", "city_1M")


STARTED = time.time()


def log(*parts):
    print(f"[{(time.time() - STARTED) / 60:5.1f} min]", *parts, file=sys.stderr, flush=True)


def load_average():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def median(values):
    return statistics.median(values) if values else float("nan")


def interleaved(contenders, rounds):
    """Times every contender once a round, the order rotated by one each round so that none always
    runs first or right after a given other. contenders: [(name, fn)], fn() -> seconds.
    Returns {name: [seconds per round]}."""
    samples = {name: [] for name, _ in contenders}
    for r in range(rounds):
        k = r % len(contenders)
        for name, fn in contenders[k:] + contenders[:k]:
            samples[name].append(fn())
    return samples


def timed(call, keep=None, key=None):
    """fn() for interleaved(): times call(); the answer of the last call kept in keep[key]."""
    def fn():
        gc.collect()
        start = time.perf_counter()
        answer = call()
        seconds = time.perf_counter() - start
        if keep is not None:
            keep[key] = answer
        return seconds
    return fn


class PeerError(RuntimeError):
    pass


class Open3DPeer:
    """Open3D's RaycastingScene in a child process (open3d_peer.py), one JSON request a line."""

    def __init__(self, label, shim=None, malloc_returns_memory=False):
        env = dict(os.environ)
        env.pop("LD_PRELOAD", None)
        if shim:
            env["LD_PRELOAD"] = shim
        if malloc_returns_memory:
            # glibc then maps big blocks and trims freed memory: resident growth is the structure's.
            env["MALLOC_MMAP_THRESHOLD_"] = "65536"
            env["MALLOC_TRIM_THRESHOLD_"] = "0"
        self.label = label
        self.proc = subprocess.Popen([sys.executable, os.path.join(HERE, "open3d_peer.py")], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, text=True, bufsize=1, env=env)
        self.version = self.ask(cmd="hello")["version"]

    def ask(self, **req):
        try:
            self.proc.stdin.write(json.dumps(req) + "\n")
            self.proc.stdin.flush()
            line = self.proc.stdout.readline()
        except BrokenPipeError:
            line = ""
        if not line:
            code = self.proc.wait(timeout=30)
            raise PeerError(f"{self.label}: the child process ended (exit {code}) on {req}")
        reply = json.loads(line)
        if "error" in reply:
            raise PeerError(f"{self.label}: {reply['error']} (request {req})")
        return reply

    def close(self):
        if self.proc.poll() is None:
            try:
                self.ask(cmd="quit")
            except PeerError:
                pass
            try:
                self.proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                self.proc.kill()


def compile_shim(tmp):
    """Builds the Embree ray-mask shim (open3d_embree_raymask_shim.c) into tmp; its path, or None
    and the reason."""
    source = os.path.join(HERE, "open3d_embree_raymask_shim.c")
    so = os.path.join(tmp, "libembree_raymask_shim.so")
    run = subprocess.run(["gcc", "-O2", "-shared", "-fPIC", "-o", so, source, "-ldl"], capture_output=True, text=True)
    if run.returncode != 0:
        return None, f"gcc failed on {source}: {run.stderr.strip()}"
    return so, ""


class Cli:
    """build/bin/meshcast: rays files, generated meshes and the C++ library's own timing."""

    def __init__(self, path, tmp):
        if not os.access(path, os.X_OK):
            sys.exit(f"bench.py: {path} is not an executable (build the meshcast target, or pass --build-dir)")
        self.path, self.tmp = path, tmp
        top = subprocess.run([path, "--help"], capture_output=True, text=True).stdout
        trace = subprocess.run([path, "trace", "--help"], capture_output=True, text=True).stdout
        self.has_generate = any(line.strip().startswith("generate") for line in top.splitlines())
        self.has_threads = "--threads" in trace

    def rays(self, mesh, kind, count, out):
        subprocess.run([self.path, "rays", mesh, "--kind", kind, "--count", str(count), "--seed", "1", "--out", out],
                       check=True, capture_output=True)

    def generate(self, name, out):
        run = subprocess.run([self.path, "generate", name, "--out", out], capture_output=True, text=True)
        if run.returncode != 0:
            raise RuntimeError(f"meshcast generate {name}: {run.stderr.strip() or run.stdout.strip()}")

    def trace(self, blob, rays, query, max_hits, threads, repeat):
        """One `meshcast trace` run: (seconds for the batch from its median ns_per_ray, its JSON)."""
        cmd = [self.path, "trace", blob, "--rays", rays, "--out", os.path.join(self.tmp, "trace.hits"),
               "--repeat", str(repeat), "--json", "--query", query]
        if max_hits:
            cmd += ["--max-hits", str(max_hits)]
        if self.has_threads:
            cmd += ["--threads", str(threads)]
        run = subprocess.run(cmd, capture_output=True, text=True)
        if run.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd)}: {run.stderr.strip()}")
        answer = json.loads([line for line in run.stdout.splitlines() if line.startswith("{")][-1])
        return answer["ns_per_ray"] * answer["rays"] * 1e-9, answer


def processor_name():
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    return "unknown"


def write_rays(path, rays):
    with open(path, "wb") as f:
        f.write(b"RAYS")
        f.write(np.uint32(len(rays)).tobytes())
        np.ascontiguousarray(rays, np.float32).tofile(f)


class RaySet:
    """One kind of rays on one mesh, in the shapes each peer takes, and its t_max policy:
    closest, count and all are cast with t_max = inf by everybody (Open3D's cast_rays and
    count_intersections take none); any (occlusion) with the file's t_max, which Open3D takes as
    test_occlusions' tfar when it is the same for every ray."""

    def __init__(self, kind, path, tmp_prefix):
        self.kind, self.path = kind, path
        rays = read_rays(path)
        self.count = len(rays)
        self.origins = np.ascontiguousarray(rays[:, 0:3])
        self.directions = np.ascontiguousarray(rays[:, 3:6])
        self.rays6 = np.ascontiguousarray(rays[:, 0:6])
        t_max = np.ascontiguousarray(rays[:, 6])
        finite = np.isfinite(t_max)
        if not finite.any():
            self.inf_path, self.t_max, self.tfar, self.t_max_note = path, np.inf, np.inf, "t_max inf"
        else:
            self.inf_path = tmp_prefix + ".inf.rays"
            inf = rays.copy()
            inf[:, 6] = np.inf
            write_rays(self.inf_path, inf)
            self.t_max = t_max
            same = finite.all() and (t_max == t_max[0]).all()
            self.tfar = float(t_max[0]) if same else None
            self.t_max_note = (f"t_max {t_max[0]:.6g} on every ray" if same else
                               f"t_max {t_max[finite].min():.6g}..{t_max[finite].max():.6g}, {(~finite).sum()} inf")


def rows_writer(path):
    f = open(path, "w", newline="")
    w = csv.writer(f)
    w.writerow(["section", "mesh", "triangles", "rays_kind", "query", "threads", "contender", "rays", "rounds",
                "median_seconds", "rays_per_second", "samples_seconds", "hits", "extra"])
    return f, w


def mrays(rays, seconds):
    return rays / seconds / 1e6 if seconds and seconds == seconds else float("nan")


def fmt(x, digits=3):
    if x is None or (isinstance(x, float) and x != x):
        return "-"
    return f"{x:.{digits}g}" if abs(x) < 1000 else f"{x:.0f}"


def markdown_table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def plot_all_hits(out_dir, series):
    """series: {(mesh, contender): [(rays, seconds)]} -> all_hits.png, log-log, with gnuplot (the
    project's pngcairo terminal, as bench/plot.cpp): a colour a mesh, a dash and point a contender.
    Returns a note on failure, else ""."""
    png = os.path.join(out_dir, "all_hits.png")
    script = png + ".gp"
    meshes = list(dict.fromkeys(mesh for mesh, _ in series))
    contenders = list(dict.fromkeys(contender for _, contender in series))
    with open(script, "w") as gp:
        gp.write("set terminal pngcairo noenhanced size 1100,750 font 'sans,10'\n")
        gp.write(f"set output '{png}'\n")
        gp.write("set title 'Every hit of each ray (long rays, every core): meshcast against Open3D 0.16.1 re-casting "
                 "past each hit'\n")
        gp.write("set xlabel 'rays'\nset ylabel 'seconds (median of the rounds)'\nset grid\nset key top left\n")
        gp.write("set logscale xy\nset format x '%.0e'\nset format y '%g'\nset offsets graph 0.05, graph 0.05, 0, 0\n")
        plots = []
        for (mesh, contender) in series:
            i, j = meshes.index(mesh), contenders.index(contender)
            plots.append(f"'-' using 1:2 with linespoints lc {i + 1} dt {j + 1} pt {(7, 5, 9, 11)[j % 4]} ps 1.3 "
                         f"lw 1.5 title '{mesh}: {contender}'")
        gp.write("plot " + ", ".join(plots) + "\n")
        for points in series.values():
            for x, y in points:
                gp.write(f"{x} {y}\n")
            gp.write("e\n")
    return run_gnuplot(script)


def run_gnuplot(script):
    """Draws the picture of a gnuplot script named PICTURE.gp; returns a
    note on failure, else ""."""
    picture = os.path.basename(script)[:-len(".gp")]
    if shutil.which("gnuplot") is None:
        return f"gnuplot not installed: {picture} not drawn ({picture}.gp is the script)"
    run = subprocess.run(["gnuplot", script], capture_output=True, text=True)
    return "" if run.returncode == 0 else f"gnuplot failed on {script}: {run.stderr.strip()}"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build-dir", default="build", help="meshcast's build folder: bin/meshcast and python/")
    ap.add_argument("--out", default=os.path.join(REPO, "bench", "results", "python"), help="results folder")
    ap.add_argument("--data", help="folder of bunny00.off and armadillo.off (default: data/ here, else beside "
                                   "the build folder)")
    ap.add_argument("--rays", type=int, default=1_000_000, help="rays a set (default 1,000,000)")
    ap.add_argument("--rounds", type=int, default=5, help="interleaved timing rounds (the median is reported)")
    ap.add_argument("--cpp-repeat", type=int, default=3, help="meshcast trace --repeat (passes a run)")
    ap.add_argument("--meshes", default="bunny00,armadillo,terrain_2M,city_1M", help="comma-separated meshes")
    ap.add_argument("--quick", action="store_true", help="a smoke run: bunny only, 100,000 rays, 3 rounds")
    args = ap.parse_args()
    if args.quick:
        args.meshes, args.rays, args.rounds = "bunny00", min(args.rays, 100_000), min(args.rounds, 3)
    if args.rays < 1 or args.rounds < 1:
        sys.exit("bench.py: --rays and --rounds must be at least 1")

    build_dir = os.path.abspath(args.build_dir)
    if args.data is None:
        args.data = next((d for d in (os.path.join(REPO, "data"), os.path.join(os.path.dirname(build_dir), "data"))
                          if os.path.isdir(d)), os.path.join(REPO, "data"))
    sys.path.insert(0, os.path.join(build_dir, "python"))
    import meshcast
    if not os.path.abspath(meshcast.__file__).startswith(os.path.join(build_dir, "python")):
        log(f"note: meshcast imported from {meshcast.__file__}, not {build_dir}/python")

    started = time.time()
    load_at_start = load_average()
    os.makedirs(args.out, exist_ok=True)
    tmp = tempfile.mkdtemp(prefix="meshcast-pybench-")
    cli = Cli(os.path.join(build_dir, "bin", "meshcast"), tmp)
    cores = os.cpu_count() or 1
    thread_counts = [1] if cores == 1 else [1, cores]
    cpp_threads = thread_counts if cli.has_threads else [1]
    notes = []  # lines for the report's header
    if not cli.has_threads:
        notes.append("`meshcast trace` has no `--threads` in this build: the C++ library is timed on one thread only.")
    csv_file, rows = rows_writer(os.path.join(args.out, "bench.csv"))

    # --- Open3D: the answer checks without and with the shim, and the peers ---------------------------
    correctness = []
    shim, shim_problem = compile_shim(tmp)
    o3d_version = "not installed"
    o3d_timing = o3d_memory = None
    plain_result = None
    try:
        plain = Open3DPeer("Open3D without the shim")
        o3d_version = plain.version
        plain_result = plain.ask(cmd="triangle_check")
    except PeerError as e:
        correctness.append(f"Open3D could not be started: {e}")
        plain = None
    if plain_result is not None:
        if plain_result["ok"]:
            correctness.append(f"Open3D {o3d_version} as installed, without the shim: one-triangle check right "
                               "(no ray-mask problem here)")
        elif plain_result["t_hit"] == float("inf") and plain_result["count"] == 0:
            correctness.append(f"Open3D {o3d_version} as Debian ships it: wrong (every ray a miss: one triangle, a ray "
                               f"at its middle, t_hit inf, count 0)")
        else:
            correctness.append(f"Open3D {o3d_version} as installed: wrong on one triangle, a ray at its middle: "
                               f"{plain_result}")
    shim_note = ("Open3D is timed with the rays' Embree mask set to all ones (LD_PRELOAD of "
                 "bench/python/open3d_embree_raymask_shim.c): Open3D sets ray.mask = 0 and Debian's Embree is "
                 "built with ray masks, so unpatched it misses every ray.")
    if plain is not None:
        if shim is None:
            correctness.append(f"Open3D not timed: the shim did not compile ({shim_problem})")
        else:
            try:
                o3d_timing = Open3DPeer("Open3D with the shim", shim=shim)
                o3d_memory = Open3DPeer("Open3D with the shim (memory)", shim=shim, malloc_returns_memory=True)
                tri = o3d_timing.ask(cmd="triangle_check")
                if tri["ok"]:
                    correctness.append(f"Open3D {o3d_version} with the ray-mask shim: one-triangle check right "
                                       f"(t_hit {tri['t_hit']:g}, triangle {tri['primitive_id']}, occluded, count 1)")
                else:
                    correctness.append(f"Open3D {o3d_version} with the ray-mask shim: one-triangle check wrong "
                                       f"({tri}); Open3D not timed")
                    o3d_timing.close(); o3d_memory.close()
                    o3d_timing = o3d_memory = None
            except PeerError as e:
                correctness.append(f"Open3D with the shim could not be started: {e}")
                o3d_timing = o3d_memory = None

    # --- Meshes -------------------------------------------------------------------------------------
    meshes = []
    for name in [m.strip() for m in args.meshes.split(",") if m.strip()]:
        if name in GENERATED:
            if not cli.has_generate:
                notes.append(f"{name}: skipped (`meshcast generate` is not in this build)")
                continue
            path = os.path.join(tmp, name + ".off")
            try:
                cli.generate(name, path)
            except RuntimeError as e:
                notes.append(f"{name}: skipped ({e})")
                continue
        else:
            path = os.path.join(args.data, name + ".off")
            if not os.path.exists(path):
                notes.append(f"{name}: skipped ({path} is missing)")
                continue
        meshes.append((name, path))

    throughput_md, build_md, scaling_md, overhead_md = [], [], [], []
    ratio_rows = []  # (mesh, kind, query, threads, ratio name, value, target, ok)
    scaling_series = {}
    scaling_meshes = [m for m in meshes if m[0] in GENERATED] or meshes[:1]
    scaling_sizes = [n for n in (10_000, 100_000, 1_000_000) if n <= max(args.rays, 10_000)]
    cpp_vs_python = []  # mismatched hit counts

    def report(meshes_done, final):
        """Writes bench.md (and the plot) from the rows so far: after each mesh, so that a run cut
        short leaves its finished meshes' tables; the last call, after every mesh, is the whole report."""
        plot_note = plot_all_hits(args.out, scaling_series) if scaling_series else "no all-hits rows: no plot"
        elapsed = time.time() - started
        md = ["# meshcast's Python package against the C++ library and Open3D", ""]
        if not final:
            md += [f"**Partial: {meshes_done} of {len(meshes)} meshes done; the run goes on.**", ""]
        md += [f"- Date: {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC; run took {elapsed / 60:.1f} min",
               f"- Load average (1, 5, 15 min) at the start {load_at_start}, at the end {load_average()}: the machine is "
               f"shared, so timings carry other processes' noise",
               f"- meshcast from {build_dir} (bin/meshcast and python/)",
               f"- Processor: {processor_name()}; {cores} logical cores (\"threads {cores}\" = every core: meshcast "
               f"nthreads=0, Open3D nthreads=0{', meshcast trace --threads 0' if cli.has_threads else ''})",
               f"- meshcast {meshcast.__version__} (walker ISA {meshcast.walker_isa()}), "
               f"Blob layout {DEFAULT_LAYOUT}; Python {sys.version.split()[0]}, numpy {np.__version__}",
               f"- Open3D {o3d_version}. {shim_note}",
               f"- {args.rays} rays a set, `meshcast rays --seed 1`; median of {args.rounds} interleaved rounds (each "
               f"round times every contender once, the order rotated each round); C++: `meshcast trace --repeat "
               f"{args.cpp_repeat} --json`, its ns_per_ray (median of its passes), the same blob file and rays file.",
               "- t_max: closest, count and all are cast with t_max = inf by every contender (Open3D's cast_rays and "
               "count_intersections take none; the C++ side reads a copy of the rays file with t_max inf); any "
               "(occlusion) uses the rays file's t_max (Open3D: test_occlusions(tnear=0, tfar=t_max), the same on every ray).",
               "- count: Blob.cast(query=\"all\", max_hits=1)'s \"found\" (every hit counted, a hit on a shared edge once "
               "a triangle), RaycastingScene.count_intersections, `trace --query all --max-hits 1`, Open3D "
               "count_intersections. all: Blob.cast(query=\"all\", max_hits=4096), RaycastingScene.list_intersections, "
               "`trace --query all --max-hits 4096`; Open3D 0.16.1 has no list_intersections (see the re-query table).",
               ""]
        md += [f"- {n}" for n in notes] + [""]
        md += ["## Answers checked before timing", "",
               "Where two answers name the same triangle with t more than 1e-4 apart (relative), the float64 intersection "
               "of the ray with that triangle's plane (its float32 corners as read) says whose t is nearer. The default "
               "layout stores vertices on a grid of 2^-18 of the mesh's extent (its stated error), so hits close to the "
               "ray's origin (probe rays start at the surface) or at grazing angles can differ from float32 answers by more "
               "than 1e-4 relative while the hit points lie within 1e-4 of the diagonal. Open3D is timed on a ray set when "
               "the same hit holds on at least 99.9% of the checked rays.", ""] + [f"- {c}" for c in correctness]
        md += ["- C++ `meshcast trace` against Blob.cast, rays hit (and hits, for count and all) on every timed row: " +
               ("equal on every row" if not cpp_vs_python else "differ on: " + "; ".join(cpp_vs_python)), ""]
        md += ["## Rays a second (millions), median of the rounds", "",
               "Blob.cast / C++: time ratio, the binding's overhead (target <= 1.10, ✗ past it). Open3D / Blob.cast: "
               "Open3D's time over meshcast's (above 1: meshcast faster).", "",
               markdown_table(["mesh", "rays", "query", "threads", "Blob.cast", "RaycastingScene", "C++ trace", "Open3D",
                               "Blob.cast / C++", "RaycastingScene / C++", "Open3D / Blob.cast"], throughput_md), ""]
        md += ["## The binding's overhead, like for like", "",
               f"Long rays, one thread, millions of rays a second. `meshcast trace --repeat {args.cpp_repeat}` reports the "
               f"median of {args.cpp_repeat} passes made one after another; here Blob.cast too makes {args.cpp_repeat} calls "
               f"one after another a round (the median counts), with fresh answer arrays or with out= arrays made once. "
               f"\"single call\": the table above (one call a round, between other contenders' calls).", "",
               markdown_table(["mesh", "query", "Blob.cast, single call", f"Blob.cast, median of {args.cpp_repeat}",
                               f"Blob.cast out=, median of {args.cpp_repeat}", "C++ trace", "single / C++",
                               f"median of {args.cpp_repeat} / C++", "out= / C++"], overhead_md), ""]
        md += ["## Build time and memory", "",
               "Build: meshcast.build (layout " + DEFAULT_LAYOUT + "); meshcast RaycastingScene(nthreads) + add_triangles + "
               "the first cast_rays of one ray; Open3D RaycastingScene(nthreads) + add_triangles + the first cast_rays of "
               "one ray (its BVH is built then). Milliseconds, median of the rounds. meshcast's RaycastingScene(nthreads) "
               "takes nthreads for its casts; its add_triangles builds on every core whatever it is.", "",
               markdown_table(["mesh", "triangles", "threads", "meshcast.build ms", "RaycastingScene ms", "Open3D ms",
                               "Open3D / meshcast.build", "Open3D / RaycastingScene"], [r for r in build_md if r[0] != "memory"]), "",
               "Memory, bytes a triangle: meshcast Blob.nbytes and RaycastingScene.nbytes (exact); Open3D: resident growth "
               "from before add_triangles to after the first cast (child run with MALLOC_MMAP_THRESHOLD_=65536, "
               "MALLOC_TRIM_THRESHOLD_=0; median of 3 builds). Target: meshcast / Open3D <= 0.25.", "",
               markdown_table(["mesh", "triangles", "Blob", "RaycastingScene", "Open3D RSS growth", "Blob / Open3D",
                               "RaycastingScene / Open3D"], [r[1] for r in build_md if r[0] == "memory"]), ""]
        md += ["## Every hit of each ray: meshcast against Open3D's re-query", "",
               f"Long rays, every core. Open3D 0.16.1 has no list_intersections; its users cast_rays, move each ray that hit "
               f"past its hit (o + (t_hit + eps/|d|) d, eps = 1e-5 x the mesh's diagonal), and cast again until every ray "
               f"misses. Hits: list_intersections (a crossing through a shared edge once) / Blob.cast all (every triangle "
               f"holding the point) / re-query; the comparison is per ray against list_intersections. Seconds. "
               f"Plot: all_hits.png.{' ' + plot_note if plot_note else ''}", "",
               markdown_table(["mesh", "rays", "list_intersections s", "Blob.cast all s", "Open3D re-query s",
                               "hits list / Blob / re-query", "re-query / list time", "re-query / Blob time",
                               "re-query against the list"], scaling_md), ""]
        misses = [r for r in ratio_rows if not r[7]]
        md += ["## Ratios against the targets", ""]
        for name, target in (("Blob.cast / C++ time", "<= 1.10"), ("Open3D / Blob.cast time", ">= 1"),
                             ("Open3D / RaycastingScene time", ">= 1"),
                             ("Open3D re-query / list_intersections time", ">= 5"),
                             ("Open3D re-query / Blob.cast all time", ">= 5"),
                             ("blob.nbytes / Open3D RSS growth", "<= 0.25"),
                             ("RaycastingScene.nbytes / Open3D RSS growth", "<= 0.25")):
            these = [r for r in ratio_rows if r[4] == name]
            if not these:
                md.append(f"- {name} (target {target}): no rows")
                continue
            bad = [r for r in these if not r[7]]
            values = [r[5] for r in these]
            md.append(f"- {name} (target {target}): {len(these) - len(bad)}/{len(these)} rows meet it; range "
                      f"{fmt(min(values))}..{fmt(max(values))}" +
                      ("" if not bad else "; misses: " + "; ".join(
                          (f"{r[0]}: {fmt(r[5])}" if r[2] == "memory" else
                           f"{r[0]} {r[1]} {r[2]} threads {r[3]}: {fmt(r[5])}") for r in bad)))
        md.append("")
        text = "\n".join(md)
        if final:
            print(text)
        with open(os.path.join(args.out, "bench.md"), "w") as f:
            f.write(text)
        return misses

    for mesh_index, (mesh_name, mesh_path) in enumerate(meshes):
        try:
            log(f"== {mesh_name}: {mesh_path}")
            V, F = meshcast.read_mesh(mesh_path)
            tris = len(F)
            diag = float(np.linalg.norm(V.max(0).astype(np.float64) - V.min(0)))
            np.save(os.path.join(tmp, "v.npy"), V)
            np.save(os.path.join(tmp, "f.npy"), F)
            for peer, scene in ((o3d_timing, True), (o3d_memory, False)):
                if peer is not None:
                    peer.ask(cmd="mesh", vertices=os.path.join(tmp, "v.npy"), triangles=os.path.join(tmp, "f.npy"),
                             scene=scene)

            # Build time and memory.
            log(f"   build time and memory ({tris} triangles)")
            one_ray = np.array([[0, 0, 0, 1, 0, 0]], np.float32)
            kept = {}
            build_contenders = []
            for T in thread_counts:
                mc_threads = 0 if T == cores and T > 1 else T
                build_contenders.append((f"meshcast.build/{T}", timed(
                    lambda mt=mc_threads: meshcast.build(V, F, layout=DEFAULT_LAYOUT, threads=mt), kept, f"blob/{T}")))

                def rs_build(mt=mc_threads):
                    scene = meshcast.RaycastingScene(nthreads=mt)
                    scene.add_triangles(V, F)
                    scene.cast_rays(one_ray, nthreads=mt)
                    return scene
                build_contenders.append((f"RaycastingScene/{T}", timed(rs_build, kept, f"rs/{T}")))
                if o3d_timing is not None:
                    build_contenders.append((f"Open3D/{T}", lambda mt=mc_threads: o3d_timing.ask(
                        cmd="build", nthreads=mt)["seconds"]))
            samples = interleaved(build_contenders, args.rounds)
            blob_bytes = kept[f"blob/{thread_counts[0]}"].nbytes
            rs_bytes = kept[f"rs/{thread_counts[0]}"].nbytes
            kept.clear()
            for T in thread_counts:
                mc_s = median(samples[f"meshcast.build/{T}"])
                rs_s = median(samples[f"RaycastingScene/{T}"])
                o3d_s = median(samples.get(f"Open3D/{T}", []))
                for contender, key in (("meshcast.build", f"meshcast.build/{T}"), ("RaycastingScene", f"RaycastingScene/{T}"),
                                       ("Open3D", f"Open3D/{T}")):
                    if key in samples:
                        rows.writerow(["build", mesh_name, tris, "", "build", T, contender, "", args.rounds,
                                       median(samples[key]), "", " ".join(f"{s:.6g}" for s in samples[key]), "", ""])
                build_md.append([mesh_name, tris, T, fmt(mc_s * 1e3), fmt(rs_s * 1e3), fmt(o3d_s * 1e3),
                                 fmt(o3d_s / mc_s), fmt(o3d_s / rs_s)])
            memory_line = [mesh_name, tris, fmt(blob_bytes / tris), fmt(rs_bytes / tris)]
            o3d_growth = None
            if o3d_memory is not None:
                # resident growth in a child whose malloc returns freed memory (timed builds: default malloc)
                growth = [o3d_memory.ask(cmd="build", nthreads=0)["rss_growth"] for _ in range(3)]
                o3d_growth = median(growth)
                rows.writerow(["memory", mesh_name, tris, "", "", "", "Open3D rss growth", "", 3, "", "",
                               " ".join(str(g) for g in growth), "", "bytes"])
            rows.writerow(["memory", mesh_name, tris, "", "", "", "meshcast blob.nbytes", "", "", "", "", "", "", blob_bytes])
            rows.writerow(["memory", mesh_name, tris, "", "", "", "RaycastingScene.nbytes", "", "", "", "", "", "", rs_bytes])
            memory_line += [fmt(o3d_growth / tris) if o3d_growth else "-",
                            fmt(blob_bytes / o3d_growth) if o3d_growth else "-",
                            fmt(rs_bytes / o3d_growth) if o3d_growth else "-"]
            build_md.append(("memory", memory_line))
            if o3d_growth:
                ratio_rows.append((mesh_name, "", "memory", "", "blob.nbytes / Open3D RSS growth",
                                   blob_bytes / o3d_growth, "<= 0.25", blob_bytes / o3d_growth <= 0.25))
                ratio_rows.append((mesh_name, "", "memory", "", "RaycastingScene.nbytes / Open3D RSS growth",
                                   rs_bytes / o3d_growth, "<= 0.25", rs_bytes / o3d_growth <= 0.25))

            # The structures timed below.
            blob = meshcast.build(V, F, layout=DEFAULT_LAYOUT)
            blob_path = os.path.join(tmp, mesh_name + ".mcb")
            blob.save(blob_path)
            rs = meshcast.RaycastingScene()
            rs.add_triangles(V, F)
            rs.cast_rays(one_ray)

            ray_sets = {}
            for kind in KINDS:
                path = os.path.join(tmp, f"{mesh_name}.{kind}.rays")
                cli.rays(mesh_path, kind, args.rays, path)
                ray_sets[kind] = RaySet(kind, path, os.path.join(tmp, f"{mesh_name}.{kind}"))
                if o3d_timing is not None:
                    o3d_timing.ask(cmd="rays_file", name=kind, path=path)

            # Answer checks before timing: Open3D (shimmed) and RaycastingScene against Blob.cast's closest
            # hits. Reported: the same t within T_AGREE relative (or both miss), and the same hit (both miss,
            # or the same triangle, or hit points within POINT_AGREE of the mesh's diagonal). The default
            # layout stores vertices on a grid of 2^-18 of the mesh's extent, so on grazing hits its t can
            # differ from a float32 answer by more than 1e-4 relative on the very triangle; where both
            # name that triangle, the float64 plane intersection tells whose t is nearer. Open3D is timed
            # on a kind when the same hit holds on at least 99.9% of the rays.
            o3d_kinds = set()
            for kind, rays in ray_sets.items():
                n = min(CHECK_RAYS, rays.count)
                o, d, r6 = rays.origins[:n], rays.directions[:n], rays.rays6[:n]
                ref_any = blob.cast(o, d, query="any", t_max=rays.t_max if np.ndim(rays.t_max) == 0 else rays.t_max[:n])["t"]
                ref_count = rs.count_intersections(r6).numpy()
                d_len = np.linalg.norm(d.astype(np.float64), axis=1)

                ref_closest = blob.cast(o, d, query="closest")
                ref, ref_tri = ref_closest["t"], ref_closest["triangle"]

                def agree(t, tri):
                    """(same t, same hit, [where the same triangle's t differs: rays whose t is nearer the float64
                    plane intersection with this answer, with meshcast's])"""
                    both_miss = ~np.isfinite(ref) & ~np.isfinite(t)
                    both_hit = np.isfinite(ref) & np.isfinite(t)
                    gap = np.full(n, np.inf)
                    gap[both_hit] = np.abs(t[both_hit].astype(np.float64) - ref[both_hit])
                    same_t = both_hit & (gap <= T_AGREE * np.abs(ref))
                    same_hit = both_hit & ((tri == ref_tri) | (gap * d_len <= POINT_AGREE * diag))
                    split = both_hit & (tri == ref_tri) & ~same_t
                    nearer = [0, 0, int(split.sum())]
                    if split.any():
                        corners = V.astype(np.float64)[F[ref_tri[split]].astype(np.int64)]
                        normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
                        od = o[split].astype(np.float64), d[split].astype(np.float64)
                        exact = (np.einsum("ij,ij->i", corners[:, 0] - od[0], normal) /
                                 np.einsum("ij,ij->i", od[1], normal))
                        theirs, ours = np.abs(t[split] - exact), np.abs(ref[split] - exact)
                        nearer[:2] = [int((theirs < ours).sum()), int((ours < theirs).sum())]
                    return int((both_miss | same_t).sum()), int((both_miss | same_hit).sum()), nearer

                def agreement(who, short, t, tri):
                    same_t, same_hit, nearer = agree(t, tri)
                    text = (f"{who} against Blob.cast: closest t within {T_AGREE:g} relative (or both miss) on {same_t}/{n}; the same hit "
                            f"(the same triangle or hit point within {POINT_AGREE:g} x diagonal, or both miss) on "
                            f"{same_hit}/{n}")
                    if nearer[2]:
                        text += (f"; of the {nearer[2]} rays on the same triangle with t apart, the float64 plane "
                                 f"intersection is nearer {short}'s t on {nearer[0]}, Blob.cast's on {nearer[1]}")
                    return text, same_hit
                rs_answer = rs.cast_rays(r6)
                text, _ = agreement("meshcast RaycastingScene", "RaycastingScene", rs_answer["t_hit"].numpy(),
                                    rs_answer["primitive_ids"].numpy())
                correctness.append(f"{mesh_name}, {kind} rays: {text}")
                if plain is not None and mesh_name == meshes[0][0]:
                    plain.ask(cmd="mesh", vertices=os.path.join(tmp, "v.npy"), triangles=os.path.join(tmp, "f.npy"))
                    plain.ask(cmd="rays_file", name=kind, path=rays.path)
                    miss = plain.ask(cmd="cast", op="closest", rays=kind, first=n)
                    correctness.append(f"{mesh_name}, {kind} rays: Open3D {o3d_version} without the shim hits "
                                       f"{miss['hits']}/{n} (meshcast {int(np.isfinite(ref).sum())})")
                if o3d_timing is None:
                    continue
                out = os.path.join(tmp, "o3d_check.npz")
                o3d_timing.ask(cmd="cast", op="closest", rays=kind, first=n, out=out)
                answer = np.load(out)
                text, same_hit = agreement("Open3D (shim)", "Open3D", answer["t"], answer["primitive"])
                line = (f"{mesh_name}, {kind} rays: {text} (hits: Blob.cast {int(np.isfinite(ref).sum())}, "
                        f"Open3D {int(np.isfinite(answer['t']).sum())})")
                if rays.tfar is not None:
                    o3d_timing.ask(cmd="cast", op="any", rays=kind, first=n, out=out, tfar=rays.tfar)
                    occ = np.load(out)["answer"]
                    line += f"; test_occlusions = Blob.cast any on {int((occ == np.isfinite(ref_any)).sum())}/{n}"
                o3d_timing.ask(cmd="cast", op="count", rays=kind, first=n, out=out)
                cnt = np.load(out)["answer"]
                line += f"; count_intersections = meshcast RaycastingScene's on {int((cnt == ref_count).sum())}/{n}"
                correctness.append(line)
                if same_hit >= n * 0.999:  # a ray or two may graze an edge in float32; more is a wrong answer
                    o3d_kinds.add(kind)
                else:
                    correctness.append(f"{mesh_name}, {kind} rays: Open3D's hits differ from meshcast's on more than "
                                       "0.1% of the rays: not timed")

            # Throughput rows.
            for kind, rays in ray_sets.items():
                n = rays.count
                for query in QUERIES:
                    for T in thread_counts:
                        mt = 0 if T == cores and T > 1 else T
                        log(f"   {kind} {query} threads {T}")
                        got = {}
                        o, d, r6 = rays.origins, rays.directions, rays.rays6
                        if query == "closest":
                            py = lambda: blob.cast(o, d, query="closest", nthreads=mt)
                            scene = lambda: rs.cast_rays(r6, nthreads=mt)
                        elif query == "any":
                            py = lambda: blob.cast(o, d, query="any", t_max=rays.t_max, nthreads=mt)
                            tfar = rays.tfar if rays.tfar is not None else np.inf
                            scene = lambda: rs.test_occlusions(r6, tnear=0.0, tfar=tfar, nthreads=mt)
                        elif query == "count":
                            py = lambda: blob.cast(o, d, query="all", max_hits=1, nthreads=mt)
                            scene = lambda: rs.count_intersections(r6, nthreads=mt)
                        else:
                            py = lambda: blob.cast(o, d, query="all", max_hits=ALL_HITS_KEPT, nthreads=mt)
                            scene = lambda: rs.list_intersections(r6, nthreads=mt)
                        contenders = [("Blob.cast", timed(py, got, "py")), ("RaycastingScene", timed(scene))]
                        if T in cpp_threads:
                            cpp_query, cpp_hits = {"closest": ("closest", 0), "any": ("any", 0), "count": ("all", 1),
                                                   "all": ("all", ALL_HITS_KEPT)}[query]
                            cpp_rays = rays.path if query == "any" else rays.inf_path

                            def cpp(cq=cpp_query, ch=cpp_hits, cr=cpp_rays):
                                seconds, answer = cli.trace(blob_path, cr, cq, ch, mt, args.cpp_repeat)
                                got["cpp"] = answer
                                return seconds
                            contenders.append(("C++ trace", cpp))
                        o3d_op = query if query in ("closest", "any", "count") else None
                        if query == "any" and rays.tfar is None:
                            o3d_op = None  # per-ray t_max Open3D cannot take
                        if kind in o3d_kinds and o3d_op:
                            contenders.append(("Open3D", lambda op=o3d_op: o3d_timing.ask(
                                cmd="cast", op=op, rays=kind, nthreads=mt,
                                tfar=rays.tfar if rays.tfar is not None else float("inf"))["seconds"]))
                        samples = interleaved(contenders, args.rounds)
                        med = {name: median(s) for name, s in samples.items()}
                        # hits, for the C++ / Python consistency line
                        answer = got["py"]
                        if query in ("closest", "any"):
                            py_hits, py_every = int(np.isfinite(answer["t"]).sum()), None
                        else:
                            py_hits, py_every = int((answer["found"] > 0).sum()), int(answer["found"].sum())
                        del got["py"], answer
                        if "cpp" in got:
                            c = got["cpp"]
                            if c["hits"] != py_hits or (py_every is not None and c["every_hit"] != py_every):
                                cpp_vs_python.append(f"{mesh_name} {kind} {query} threads {T}: Python {py_hits} rays hit"
                                                     f"{f', {py_every} hits' if py_every is not None else ''}, "
                                                     f"C++ {c['hits']}, {c['every_hit']}")
                        for name, s in samples.items():
                            rows.writerow(["throughput", mesh_name, tris, kind, query, T, name, n, args.rounds, med[name],
                                           n / med[name], " ".join(f"{x:.6g}" for x in s),
                                           py_hits if name == "Blob.cast" else "", py_every if name == "Blob.cast" else ""])
                        csv_file.flush()
                        py_cpp = med["Blob.cast"] / med["C++ trace"] if "C++ trace" in med else float("nan")
                        rs_cpp = med["RaycastingScene"] / med["C++ trace"] if "C++ trace" in med else float("nan")
                        o3d_speed = med["Open3D"] / med["Blob.cast"] if "Open3D" in med else float("nan")
                        if py_cpp == py_cpp:
                            ratio_rows.append((mesh_name, kind, query, T, "Blob.cast / C++ time", py_cpp, "<= 1.10",
                                               py_cpp <= 1.10))
                        if o3d_speed == o3d_speed and query in ("closest", "any"):
                            ratio_rows.append((mesh_name, kind, query, T, "Open3D / Blob.cast time", o3d_speed, ">= 1",
                                               o3d_speed >= 1.0))
                            rs_speed = med["Open3D"] / med["RaycastingScene"]
                            ratio_rows.append((mesh_name, kind, query, T, "Open3D / RaycastingScene time", rs_speed, ">= 1",
                                               rs_speed >= 1.0))
                        throughput_md.append([mesh_name, kind, query, T] +
                                             [fmt(mrays(n, med.get(c))) for c in ("Blob.cast", "RaycastingScene", "C++ trace",
                                                                                  "Open3D")] +
                                             [fmt(py_cpp) + (" ✗" if py_cpp > 1.10 else ""), fmt(rs_cpp), fmt(o3d_speed)])
            # The binding's overhead like for like: meshcast trace reports the median of its K passes over
            # the batch, one after another (the later ones find the blob in cache); here Blob.cast makes
            # K calls one after another too, with fresh answer arrays and with out= arrays made once.
            rays, K = ray_sets["long"], args.cpp_repeat
            for query in ("closest", "any"):
                log(f"   binding overhead: long {query}, {K} passes a round, one thread")
                n = rays.count
                out = {"t": np.empty(n, np.float32), "triangle": np.empty(n, np.uint32)}

                def passes(call):
                    def fn():
                        gc.collect()
                        seconds = []
                        for _ in range(K):
                            start = time.perf_counter()
                            call()
                            seconds.append(time.perf_counter() - start)
                        return median(seconds)
                    return fn
                contenders = [
                    ("Blob.cast", passes(lambda q=query: blob.cast(rays.origins, rays.directions, query=q, nthreads=1))),
                    ("Blob.cast out=", passes(lambda q=query: blob.cast(rays.origins, rays.directions, query=q, nthreads=1,
                                                                        out=out))),
                    ("C++ trace", lambda q=query: cli.trace(blob_path, rays.inf_path, q, 0, 1, K)[0])]
                samples = interleaved(contenders, args.rounds)
                med = {name: median(x) for name, x in samples.items()}
                for name, x in samples.items():
                    rows.writerow(["overhead", mesh_name, tris, "long", query, 1, f"{name} (median of {K} passes)", n,
                                   args.rounds, med[name], n / med[name], " ".join(f"{v:.6g}" for v in x), "", ""])
                single = next(r for r in throughput_md if r[:4] == [mesh_name, "long", query, 1])
                overhead_md.append([mesh_name, query, single[4], fmt(mrays(n, med["Blob.cast"])),
                                    fmt(mrays(n, med["Blob.cast out="])), fmt(mrays(n, med["C++ trace"])), single[8],
                                    fmt(med["Blob.cast"] / med["C++ trace"]), fmt(med["Blob.cast out="] / med["C++ trace"])])

            notes_kinds = ", ".join(f"{k}: {r.t_max_note}" for k, r in ray_sets.items())
            notes.append(f"{mesh_name} rays ({args.rays} a set, seed 1): {notes_kinds}")

            # All-hits scaling.
            if (mesh_name, mesh_path) in scaling_meshes:
                rays = ray_sets["long"]
                eps = 1e-5 * diag
                for n in [s for s in scaling_sizes if s <= rays.count]:
                    log(f"   all hits, {n} long rays")
                    o, d, r6 = rays.origins[:n], rays.directions[:n], rays.rays6[:n]
                    got = {}
                    contenders = [("RaycastingScene.list_intersections", timed(lambda: rs.list_intersections(r6), got, "list")),
                                  ("Blob.cast all", timed(lambda: blob.cast(o, d, query="all", max_hits=ALL_HITS_KEPT),
                                                          got, "blob"))]
                    if "long" in o3d_kinds:
                        requery_out = os.path.join(tmp, "requery.npz")

                        def requery():
                            reply = o3d_timing.ask(cmd="requery", rays="long", n=n, nthreads=0, eps=eps, out=requery_out)
                            got["requery"] = reply
                            return reply["seconds"]
                        contenders.append(("Open3D re-query", requery))
                    samples = interleaved(contenders, args.rounds)
                    med = {name: median(s) for name, s in samples.items()}
                    listed = got["list"]
                    splits = listed["ray_splits"].numpy().astype(np.int64)
                    list_counts = np.diff(splits)
                    list_hits = int(splits[-1])
                    blob_hits = int(got["blob"]["found"].sum())
                    compare = "-"
                    requery_hits = None
                    if "requery" in got:
                        rq = np.load(requery_out)
                        requery_hits = int(len(rq["ray"]))
                        rq_counts = np.bincount(rq["ray"], minlength=n)
                        pairs = rq["ray"].astype(np.int64) * (tris + 1) + rq["primitive"].astype(np.int64)
                        duplicated = len(pairs) - len(np.unique(pairs))
                        fewer, more = int((rq_counts < list_counts).sum()), int((rq_counts > list_counts).sum())
                        compare = (f"{fewer} rays with fewer hits than the list ({int(np.maximum(list_counts - rq_counts, 0).sum())}"
                                   f" hits missed), {more} with more ({int(np.maximum(rq_counts - list_counts, 0).sum())} extra;"
                                   f" {duplicated} the same triangle twice); {got['requery']['passes']} passes")
                    for name, s in samples.items():
                        hits = {"RaycastingScene.list_intersections": list_hits, "Blob.cast all": blob_hits,
                                "Open3D re-query": requery_hits}[name]
                        rows.writerow(["all_hits", mesh_name, tris, "long", "all", cores, name, n, args.rounds, med[name],
                                       n / med[name], " ".join(f"{x:.6g}" for x in s), hits,
                                       compare if name == "Open3D re-query" else ""])
                        scaling_series.setdefault((mesh_name, name), []).append((n, med[name]))
                    speed_list = med.get("Open3D re-query", float("nan")) / med["RaycastingScene.list_intersections"]
                    speed_blob = med.get("Open3D re-query", float("nan")) / med["Blob.cast all"]
                    if speed_list == speed_list:
                        ratio_rows.append((mesh_name, f"long {n}", "all", cores, "Open3D re-query / list_intersections time",
                                           speed_list, ">= 5", speed_list >= 5))
                        ratio_rows.append((mesh_name, f"long {n}", "all", cores, "Open3D re-query / Blob.cast all time",
                                           speed_blob, ">= 5", speed_blob >= 5))
                    scaling_md.append([mesh_name, n, fmt(med["RaycastingScene.list_intersections"]), fmt(med["Blob.cast all"]),
                                       fmt(med.get("Open3D re-query")), f"{list_hits} / {blob_hits} / "
                                       f"{requery_hits if requery_hits is not None else '-'}", fmt(speed_list), fmt(speed_blob),
                                       compare])
                    del got
        except Exception as e:  # one mesh's failure is reported; the other meshes still run
            traceback.print_exc()
            notes.append(f"{mesh_name}: stopped by {type(e).__name__}: {e}; its rows above are partial")
        finally:
            blob = rs = ray_sets = None
            for f in os.listdir(tmp):
                if f.startswith(mesh_name + "."):
                    os.remove(os.path.join(tmp, f))
        if mesh_index + 1 < len(meshes):
            csv_file.flush()
            report(mesh_index + 1, final=False)

    for peer in (plain, o3d_timing, o3d_memory):
        if peer is not None:
            peer.close()
    csv_file.close()
    misses = report(len(meshes), final=True)
    elapsed = time.time() - started
    shutil.rmtree(tmp, ignore_errors=True)
    log(f"wrote {args.out}/bench.md, bench.csv, all_hits.png ({elapsed / 60:.1f} min); {len(misses)} ratio rows miss")


if __name__ == "__main__":
    main()
