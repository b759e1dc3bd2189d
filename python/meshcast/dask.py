"""Casts of dask arrays: meshcast on a Dask cluster, or on Dask's local schedulers.

``cast(target, origins, directions, ...)`` casts rays given as dask arrays
(or numpy arrays, chunked here) against a :class:`meshcast.Blob` or a
:class:`meshcast.Scene` and returns a dict of dask arrays chunked like the
rays, with ``Blob.cast``'s (or ``Scene.cast``'s) keys; ``cast_rays``,
``test_occlusions`` and ``count_intersections`` do the same for a
:class:`meshcast.RaycastingScene` on (..., 6) rays. Nothing is cast until
the answer is computed (``dask.compute(answer)`` computes every key of it
with one cast a chunk).

How the structure reaches the workers, with a ``distributed`` Client:

* a Blob mapped from a file every worker can read (``meshcast.load(path,
  mmap=True)``, the file on shared storage or copied to the same path on
  every machine) travels as its path: each worker process maps the file
  once and checks its size and checksum (an error names the worker, the
  path and what differs);
* any other Blob, and a RaycastingScene, is sent to every worker process
  once when first cast, as a worker plugin (``Client.register_worker_plugin``:
  workers that join or restart later get it too), and kept there for later
  casts of the same content (the 16 most recent);
* a Scene travels as its blobs (each as above, once) and its instance
  table; each worker process builds it once.

Without a Client (Dask's threads scheduler) nothing travels. Each chunk is
cast on the worker's threads (its ``nthreads``; ``nthreads=`` overrides)
with the GIL released, so one worker process a machine, with as many
threads as cores, is the deployment to use: ``dask worker ADDRESS
--nworkers 1 --nthreads $(nproc)``. A chunk of 10^5 rays or more keeps the
cluster's overhead a chunk small beside its cast.
"""

import dask.array as da
import numpy as np
from dask.base import tokenize
from distributed import WorkerPlugin

from . import _meshcast, _shipping

__all__ = ["cast", "cast_rays", "test_occlusions", "count_intersections", "arrivals"]

arrivals = _shipping.arrivals


def cast(target, origins, directions, *, t_min=None, t_max=None, query="closest", cull="none", max_hits=16,
         uv=False, mask=0xFF, invalid="raise", nthreads=0):
    """Casts dask arrays of rays against a Blob or a Scene.

    target: a :class:`meshcast.Blob` or a committed :class:`meshcast.Scene`.
    origins: (..., 3), a dask or numpy array (rechunked like the directions),
    or one (3,) origin for every ray. directions: (..., 3), a dask or numpy
    array; its chunks over the leading axes are the casts' (the last axis is
    taken whole). t_min, t_max: None, a number, or an array of the rays'
    shape (rechunked like them). query, cull, max_hits, uv, invalid: as
    ``Blob.cast``; mask: a Scene's (as ``Scene.cast``). nthreads: each
    chunk's threads (0: the worker's).

    Returns a dict of dask arrays. For "closest" and "any": ``Blob.cast``'s
    keys ("t", "triangle", a Scene's "instance", with uv=True "uv"), chunked
    like the rays. For "all" the rays must be (N, 3): "found" (N,) uint32
    chunked like them, "offsets" (N + 1,) int64, and "t", "triangle" (and
    "instance", "uv") of the kept hits, one chunk a chunk of rays (sizes
    known once computed): ray i's hits are offsets[i] to offsets[i + 1] of
    them, as in ``Blob.cast``.
    """
    if isinstance(target, _meshcast.Blob):
        keys = ["t", "triangle"]
        options = dict(query=query, cull=cull, max_hits=max_hits, uv=uv, invalid=invalid)
    elif isinstance(target, _meshcast.Scene):
        keys = ["t", "instance", "triangle"]
        options = dict(query=query, cull=cull, max_hits=max_hits, uv=uv, invalid=invalid, mask=mask)
    else:
        raise TypeError(f"meshcast.dask.cast: a meshcast.Blob or meshcast.Scene, not {type(target).__name__}")
    if query not in ("closest", "any", "all"):
        raise ValueError(f"query: {query!r} is not \"closest\", \"any\" or \"all\"")
    directions = _rays_array(directions, 3, "directions")
    lead = directions.chunks[:-1]
    if query == "all" and directions.ndim != 2:
        raise ValueError(f"directions: shape {directions.shape}; query=\"all\" takes (N, 3) rays")
    origins = _origins(origins, directions)
    bounds = [_per_ray(v, directions, name) for v, name in ((t_min, "t_min"), (t_max, "t_max"))]
    shipped = _ship(target)
    token = tokenize(shipped.token, directions, origins, bounds, options, nthreads)
    answers = _chunk_answers("meshcast-cast-" + token, _cast_chunk, shipped, directions,
                             [origins] + bounds, dict(options, nthreads=nthreads))
    if uv:
        keys.append("uv")
    dtypes = {"t": np.float32, "triangle": np.uint32, "instance": np.uint32, "uv": np.float32}
    if query != "all":
        return {k: _pick(answers, k, dtypes[k], lead, (2,) if k == "uv" else ()) for k in keys}
    found = _pick(answers, "found", np.uint32, lead, ())
    out = {"found": found, "offsets": _offsets(_pick(answers, "kept", np.int64, lead, ()))}
    unknown = ((np.nan,) * len(lead[0]),)
    for k in keys:
        out[k] = _pick(answers, k, dtypes[k], unknown, (2,) if k == "uv" else ())
    return out


def cast_rays(scene, rays, *, uvs=True, normals=True, nthreads=0):
    """RaycastingScene.cast_rays on (..., 6) rays (a dask or numpy array,
    the last axis taken whole): a dict of dask arrays chunked like the rays,
    with its keys (t_hit, geometry_ids, primitive_ids, and primitive_uvs,
    primitive_normals unless uvs, normals are False). nthreads: each chunk's
    threads (0: the worker's)."""
    rays = _rays_array(rays, 6, "rays")
    keys = [("t_hit", np.float32, ()), ("geometry_ids", np.uint32, ()), ("primitive_ids", np.uint32, ())]
    if uvs:
        keys.append(("primitive_uvs", np.float32, (2,)))
    if normals:
        keys.append(("primitive_normals", np.float32, (3,)))
    answers = _scene_answers(scene, "cast_rays", rays, [], dict(uvs=uvs, normals=normals), nthreads)
    return {k: _pick(answers, k, dtype, rays.chunks[:-1], tail) for k, dtype, tail in keys}


def test_occlusions(scene, rays, tnear=0.0, tfar=float("inf"), *, nthreads=0):
    """RaycastingScene.test_occlusions on (..., 6) rays: a bool dask array
    chunked like them. tnear, tfar: numbers or arrays of the rays' shape."""
    rays = _rays_array(rays, 6, "rays")
    bounds = [_per_ray(v, rays, name) for v, name in ((tnear, "tnear"), (tfar, "tfar"))]
    answers = _scene_answers(scene, "test_occlusions", rays, bounds, {}, nthreads)
    return _pick(answers, None, np.bool_, rays.chunks[:-1], ())


def count_intersections(scene, rays, *, nthreads=0):
    """RaycastingScene.count_intersections on (..., 6) rays: an int32 dask
    array chunked like them."""
    rays = _rays_array(rays, 6, "rays")
    answers = _scene_answers(scene, "count_intersections", rays, [], {}, nthreads)
    return _pick(answers, None, np.int32, rays.chunks[:-1], ())


# --- the rays ------------------------------------------------------------------


def _rays_array(value, width, name):
    if not isinstance(value, da.Array):
        value = np.asarray(getattr(value, "numpy", lambda: value)())
    if value.ndim < 1 or value.shape[-1] != width:
        raise ValueError(f"{name}: shape {value.shape} is not (..., {width})")
    if value.dtype.kind not in "fiu":
        raise ValueError(f"{name}: dtype {value.dtype} is not a real number type")
    if not isinstance(value, da.Array):
        return da.from_array(value, chunks=("auto",) * (value.ndim - 1) + (width,))
    return value if len(value.chunks[-1]) == 1 else value.rechunk(value.chunks[:-1] + ((width,),))


def _origins(origins, directions):
    if not isinstance(origins, da.Array) and np.shape(origins) == (3,):
        return np.asarray(origins)  # one origin for every ray: the same small array in every task
    return _like(origins, directions.shape, directions.chunks, "origins", "(3,) nor ")


def _per_ray(value, rays, name):
    # None or a number as it is; an array chunked like the rays.
    if value is None or np.ndim(value) == 0 and not isinstance(value, da.Array):
        return value
    return _like(value, rays.shape[:-1], rays.chunks[:-1], name)


def _like(value, shape, chunks, name, also=""):
    """`value` (a dask or numpy array) of `shape`, chunked as `chunks`."""
    if np.shape(value) != shape:
        raise ValueError(f"{name}: shape {np.shape(value)}, not {also}the rays' {shape}")
    if isinstance(value, da.Array):
        return value.rechunk(chunks)
    return da.from_array(np.asarray(value), chunks=chunks)


# --- how the target travels ----------------------------------------------------


class _Shipped:
    """A target as the tasks carry it: `value` (the object itself; None for
    one held by every worker; for a Scene, its blobs so and its instance
    table) and a token naming its content."""

    def __init__(self, kind, value, token):
        self.kind, self.value, self.token = kind, value, token


class _Held(WorkerPlugin):
    """A structure sent to every worker process once, joining or restarted
    ones too, and kept there under its token until the plugin is removed.
    A worker plugin, not data scattered with broadcast=True: Dask's active
    memory manager drops copies of scattered data that no task waits for,
    so each cast after the first would send it again."""

    def __init__(self, token, obj):
        self.token, self.obj = token, obj

    def setup(self, worker):
        _held[self.token] = self.obj

    def teardown(self, worker):
        _held.pop(self.token, None)


_held = {}  # in a worker: content token -> the structure a _Held plugin brought
_registered = {}  # in the client: (client id, token) -> the plugin's name, oldest first
_KEEP_REGISTERED = 16


def _client():
    try:
        from distributed import get_client
        return get_client()
    except (ImportError, ValueError):
        return None


class _File:
    """A mapped blob as a task carries it: its pickled form (the file's
    path, size and checksum), undone when the task runs, so a file missing
    or another on a worker fails that task with the error, not the
    worker's receipt of it."""

    def __init__(self, blob):
        self.undo, self.args = _shipping.reduce_blob(blob)

    def blob(self):
        return self.undo(*self.args)


def _ship_object(obj, token):
    # A mapped blob as its file's name; anything else held by every worker
    # of the current Client, if there is one (else itself).
    if isinstance(obj, _meshcast.Blob) and obj.mapped:
        return _File(obj)
    client = _client()
    if client is None:
        return obj
    key = (client.id, token)
    if key not in _registered:
        name = "meshcast-" + token
        client.register_worker_plugin(_Held(token, obj), name=name)
        _registered[key] = name
        while len(_registered) > _KEEP_REGISTERED:  # the oldest let go on the workers
            old = next(iter(_registered))
            old_name = _registered.pop(old)
            if old[0] == client.id:
                client.unregister_worker_plugin(old_name)
            if not any(k[1] == old[1] for k in _registered):
                _held.pop(old[1], None)
    # Held here too: a graph made with a Client current may still be
    # computed by Dask's threads scheduler in this process.
    _held[token] = obj
    return None


def _ship(target):
    if isinstance(target, _meshcast.Blob):
        token = tokenize(target)
        return _Shipped("blob", _ship_object(target, token), token)
    # The rest of the state (the number its ids carry) travels, and stays
    # out of the token: workers cast, never edit, so scenes of the same
    # blobs and instances share one built scene there.
    version, blobs, instances, *rest = target.__getstate__()  # ValueError for uncommitted edits
    tokens = [tokenize(b) for b in blobs]
    token = tokenize("meshcast.Scene", version, tokens, instances)
    shipped = [(t, _ship_object(b, t)) for b, t in zip(blobs, tokens)]
    return _Shipped("scene", (version, shipped, instances, *rest), token)


_scenes = {}  # in a worker: content token -> the Scene built from its blobs there


def _resolved(value, token):
    if isinstance(value, _File):
        return value.blob()
    if value is not None:
        return value
    try:
        return _held[token]
    except KeyError:
        raise RuntimeError(f"{_shipping.where()}: meshcast's structure {token} never reached this worker "
                           "(its plugin was removed: cast again)") from None


def _target_of(kind, value, token):
    # The object a chunk casts against, in the worker's process.
    if kind != "scene":
        return _resolved(value, token)
    scene = _scenes.get(token)
    if scene is None:
        version, blobs, instances, *rest = value
        scene = _meshcast.Scene.__new__(_meshcast.Scene)
        scene.__setstate__((version, [_resolved(b, t) for t, b in blobs], instances, *rest))
        _scenes[token] = scene
    return scene


def _worker_threads(nthreads):
    if nthreads:
        return nthreads
    try:
        from distributed import get_worker
        worker = get_worker()
    except (ImportError, ValueError):
        return 0
    state = getattr(worker, "state", None)  # distributed 2022.12 and later; before, the worker itself
    return getattr(state, "nthreads", None) or getattr(worker, "nthreads", 0)


# --- the chunks ----------------------------------------------------------------


def _cast_chunk(kind, value, token, directions, origins, t_min, t_max, options):
    options = dict(options)
    options["nthreads"] = _worker_threads(options["nthreads"])
    target = _target_of(kind, value, token)
    answer = target.cast(origins, directions, t_min=t_min, t_max=t_max, **options)
    if options["query"] == "all":
        answer["kept"] = np.diff(answer["offsets"])
    return answer


def _scene_chunk(kind, value, token, rays, *rest):
    per_ray, (method, options, nthreads) = rest[:-1], rest[-1]
    target = _target_of(kind, value, token)
    return getattr(target, method)(rays, *per_ray, nthreads=_worker_threads(nthreads), **options)


def _chunk_answers(name, function, shipped, rays, per_ray, options):
    """A dask array whose blocks are the chunks' answers (dicts or arrays),
    one a chunk of rays, picked apart by _pick. The target is in every
    task as it was shipped: a token where every worker holds it already, a
    mapped blob's path, or the object itself for Dask's local schedulers."""
    lead = "abcdefghijklmnopqrstuvwxy"[: rays.ndim - 1]
    args = [rays, lead + "z"]
    for value in per_ray:
        if isinstance(value, da.Array):
            args += [value, lead + "z" if value.ndim == rays.ndim else lead]
        else:
            args += [value, None]
    return da.blockwise(function, lead, shipped.kind, None, shipped.value, None, shipped.token, None, *args, options, None,
                        name=name, dtype=object, meta=np.empty((0,) * len(lead), object), concatenate=True)


def _scene_answers(scene, method, rays, per_ray, options, nthreads):
    from . import RaycastingScene
    if not isinstance(scene, RaycastingScene):
        raise TypeError(f"meshcast.dask.{method}: a meshcast.RaycastingScene, not {type(scene).__name__}")
    token = tokenize(scene._content_token())
    shipped = _Shipped("raycasting", _ship_object(scene._scene, token), token)
    name = f"meshcast-{method.replace('_', '-')}-" + tokenize(token, rays, per_ray, options, nthreads)
    return _chunk_answers(name, _scene_chunk, shipped, rays, per_ray, (method, options, nthreads))


def _pick(answers, key, dtype, chunks, tail):
    """The dask array of `key` of each block's answer (the block itself for
    key None), with `chunks` over the rays' axes and `tail` after them."""
    return da.map_blocks(_item, answers, key, dtype=dtype, chunks=chunks + tuple((n,) for n in tail),
                         new_axis=list(range(len(chunks), len(chunks) + len(tail))) or None,
                         meta=np.empty((0,) * (len(chunks) + len(tail)), dtype))


def _item(answer, key):
    return answer if key is None else answer[key]


def _offsets(kept):
    """The (N + 1,) offsets of the hits kept by each of N rays: each chunk's
    start (a prefix sum of the chunks' totals, in one small task) plus the
    running sum within it. (dask's own cumsum took minutes on a
    LocalCluster of Dask 2022.12 for a few chunks.)"""
    totals = kept.map_blocks(_total, chunks=((1,) * kept.numblocks[0],), dtype=np.int64)
    starts = totals.rechunk(-1).map_blocks(_starts, dtype=np.int64).to_delayed()[0]
    body = da.map_blocks(_running_sum, kept, starts, dtype=np.int64)
    return da.concatenate([da.zeros(1, dtype=np.int64, chunks=1), body])


def _total(kept):
    return np.array([kept.sum()], np.int64)


def _starts(totals):
    return np.concatenate([[0], np.cumsum(totals)[:-1]]).astype(np.int64)


def _running_sum(kept, starts, block_info=None):
    return starts[block_info[0]["chunk-location"][0]] + np.cumsum(kept, dtype=np.int64)
