"""meshcast: ray casts against static triangle meshes, numpy in and out.

Two ways in:

* meshcast's own: ``build(vertices, triangles)`` (or ``load(path)``, read
  into memory or, with ``mmap=True``, mapped) gives a :class:`Blob`, the mesh's whole ray-cast structure in one
  buffer of about 14 bytes a triangle; ``blob.cast(origins, directions)``
  answers the closest hit, any hit or every hit of each ray, with face
  culling, on every core or on the GPU (``backend="vulkan"``). A
  :class:`Scene` places blobs as instances (3x3 rotation-scale, float64
  translation) and casts float32 or float64 rays against them as one world.
* Open3D's: :class:`RaycastingScene` takes the names, shapes, dtypes and
  sentinels of ``open3d.t.geometry.RaycastingScene``.

Rays: a hit needs ``t_min <= t <= t_max``, ``t`` in units of the direction
(which need not be normalized). Triangles are two-sided unless a cast culls
(the front face's corners run counter-clockwise seen from the ray's origin),
and the triangle test is watertight: a ray through a shared edge or vertex
never slips between its triangles. The closest or any hit there is one of
them; ``query="all"`` lists every triangle holding the point, each once,
while RaycastingScene's count_intersections and list_intersections count
a surface the ray crosses there once, decided from the triangles' corners
(as a ray moved off the point by an infinitely small step would count),
never from their winding: once through an edge or any vertex the ray
crosses, twice or not at all where it only touches a closed mesh (a
silhouette edge or vertex), so parity tells inside from outside on any
closed mesh, wound one way, the other or both. A ray with a
NaN or infinite component, a zero direction or ``t_min > t_max`` is refused
with ``ValueError`` naming it by ``Blob.cast`` and ``Scene.cast``
(``invalid="miss"`` answers it as a miss instead); RaycastingScene answers
it as a miss, as Open3D does.

Arrays: float32 or float64 (other real types are converted once); C-
contiguous arrays are read where they lie. Every cast releases the GIL and
splits the batch over meshcast's own threads (``nthreads``: 0 for every
core): one pool for the process, as wide as the most threads a call has
asked for, a call of fewer using that many of them. A child forked from
the process (``multiprocessing`` on Linux) casts on threads and Vulkan
devices of its own, whatever its parent cast. Bad input raises
``ValueError``, files ``OSError``; a thread or device the system refuses,
``RuntimeError`` saying so.

Points: ``blob.closest_points(points)`` and RaycastingScene's
``compute_closest_points`` and ``compute_distance`` answer the nearest point
of the mesh to each (..., 3) point, worked out in double from the stored
triangles (exact on ``OctTreeCompressed/Float3SOA8``, within the recommended
layout's stated bound of the input mesh, a few millionths of its diagonal).

Processes and clusters: a Blob, a Scene and a RaycastingScene pickle (a
blob mapped from a file as the file's path, mapped once a process; any
other as its bytes), and ``meshcast.dask`` casts dask arrays of rays on a
Dask cluster (``help(meshcast.dask)``).

A blob's cast whose rays all start at one point (a sensor, a probe) walks
them as packets on the recommended layout: sorted by direction, 8 at a
time, each node decoded once for them; the answers are the same bits as
one ray at a time (``packets="off"``), only the time differs.
"""

import os as _os
import uuid as _uuid

import numpy as _np

from . import _meshcast, _shipping
from ._scene_ids import InstanceId, MeshId  # noqa: F401
from .images import write_png  # noqa: F401
from ._meshcast import (NO_HIT, Blob, Scene, __version__, features, layouts,  # noqa: F401
                        walker_isa)

# Tensor, the answers' type, is left out: help(meshcast) would repeat
# numpy.ndarray's whole documentation under it.
__all__ = ["Blob", "Scene", "MeshId", "InstanceId", "RaycastingScene", "build", "load", "read_mesh", "layouts",
           "features", "walker_isa", "write_png", "from_bytes", "NO_HIT", "__version__"]

# Blob's pickling: a mapped file's path, or the bytes (meshcast/_shipping.py).
_shipping.install()


def build(vertices, triangles, layout="auto", max_bytes=0, leaf_size=0, threads=0, name="mesh"):
    """Builds a mesh's :class:`Blob`.

    vertices: (V, 3) float32 or float64 (stored as float32: a mesh far from
    the origin is best built about its own centre and placed with a Scene
    instance's float64 translation, as RaycastingScene does by itself).
    triangles: (T, 3) int32, uint32 or int64 vertex indices.
    layout: "auto" (chosen for the mesh, fastest first, within max_bytes) or
    a name of :func:`layouts`, e.g. "OctTreeCompressed/ClusterBitPackSOA8",
    the recommended one. max_bytes: the blob's size at most (0: no limit).
    leaf_size: a named layout's largest leaf (0: its own). threads: the
    build's threads (0: every core); the bytes are the same on any number.
    """
    return _meshcast._build(vertices, triangles, layout, max_bytes, leaf_size, threads, name)


def load(path, mmap=False):
    """A blob file (``Blob.save``), validated.

    By default the file is read whole into memory: the Blob holds its own
    copy of the bytes that were validated, and rewriting, truncating or
    deleting the file afterwards changes nothing it answers.

    ``mmap=True`` maps the file read-only instead (``Blob.mapped``): no copy,
    and the pages are shared with every process that maps the same file
    (many workers on one machine). The bytes are validated once, when the
    file is loaded, and then read where they lie, so the file must not
    change while the Blob lives: replace it with a new file (``Blob.save``
    writes a new file and renames it over the old name, which a mapping of
    the old file does not see). A file rewritten in place is read as it now
    is, unvalidated: wrong answers, or a crash on corrupted bytes; a file
    truncated under the map kills the process with SIGBUS on the next cast.

    Pickled (``pickle``, ``multiprocessing``, Dask), a mapped Blob travels
    as its file's absolute path, size and checksum: the process that
    unpickles it maps the file once (later ones are the same mapping) and
    raises an error naming itself, the path and what differs where the file
    is missing or another. A Blob in memory travels as its bytes.
    """
    path = _os.fspath(path)
    with open(path, "rb"):  # the system's own error for a missing or unreadable file
        pass
    # A mapped file is named by its absolute path: a pickled Blob names it so.
    return _meshcast._load(_os.path.abspath(path) if mmap else path, bool(mmap), path)


def from_bytes(data, name="bytes"):
    """A blob from its bytes (``Blob.to_bytes()``, a file read whole), validated."""
    return _meshcast._from_bytes(bytes(data), name)


def read_mesh(path):
    """A mesh file (OFF, OBJ, PLY, STL) as (vertices float32 (V, 3),
    triangles uint32 (T, 3)), the file's vertex and triangle order kept."""
    if not features["reader"]:
        raise RuntimeError("meshcast.read_mesh: this meshcast was built without its mesh reader (Assimp)")
    path = _os.fspath(path)
    with open(path, "rb"):
        pass
    return _meshcast._read_mesh(path)


class Tensor(_np.ndarray):
    """A numpy array that also answers ``.numpy()``, as Open3D's tensors do,
    so code written for Open3D's RaycastingScene runs unchanged."""

    def numpy(self):
        return self.view(_np.ndarray)

    def isfinite(self):
        """Element-wise: neither inf nor NaN (bool), as Open3D's ``Tensor.isfinite``."""
        return _np.isfinite(self.view(_np.ndarray)).view(Tensor)


def _tensors(answer):
    if isinstance(answer, dict):
        return {key: value.view(Tensor) for key, value in answer.items()}
    return answer.view(Tensor)


def _array(value):
    # Open3D's tensors (and anything else exposing .numpy()) as numpy arrays.
    numpy = getattr(value, "numpy", None)
    return numpy() if callable(numpy) and not isinstance(value, _np.ndarray) else value


class RaycastingScene:
    """Open3D's ``open3d.t.geometry.RaycastingScene``, on meshcast.

    Port with a rename: the methods, argument names, result keys, dtypes and
    sentinels are Open3D's (``t_hit`` inf and ``INVALID_ID`` on a miss; a
    ray with a NaN or infinite component or a zero direction is a miss, as
    padded pixels of a camera's rays are in Open3D). Rays
    are (..., 6) arrays, [ox, oy, oz, dx, dy, dz], float32 or float64: float64
    origins keep their precision, and each geometry is stored about its own
    float64 centre, so scenes far from the origin answer as at the origin.

    Pickled (``pickle``, Dask, ``multiprocessing``), a scene travels as its
    geometries' structures, every byte as it is: nothing is built again, and
    the copy answers the same bits.

    Each geometry is stored exactly by default: its float32 vertices
    themselves, in clusters under an 8-wide tree (the layout
    "OctTreeCompressed/ClusterFloat3SOA8", about 19 bytes a triangle all
    included), so hits, uvs and distances are the float mesh's, within float
    rounding, as Open3D's are.
    """

    INVALID_ID = _meshcast.INVALID_ID

    def __init__(self, nthreads=0, *, layout=None, max_error=0.0):
        """nthreads: add_triangles' build threads, and the casts' unless a
        call names its own (0: every core).

        max_error: the error allowed, a fraction of each mesh's diagonal (0:
        exact). Where the compact layout's stated bound is within it, a
        geometry is stored in "OctTreeCompressed/ClusterBitPackSOA8": about
        13.5 bytes a triangle instead of 19, its vertices moved to a grid
        whose power-of-two step is at most 2^-17 of the mesh's extent on
        each axis, so a vertex moves at most half a step and hits, uvs and
        distances move with it (the stated bound, a few 1e-6 of the
        diagonal; max_error=1e-5 takes it on any mesh).

        layout: a layout name of :func:`layouts` to store every geometry in
        (point queries and winding numbers need an "OctTreeCompressed/..."
        one; backend="vulkan" a cluster one). With max_error too, a layout
        whose stated bound is over it is refused."""
        self._scene = _meshcast._RaycastingScene(nthreads, layout=layout, max_error=max_error)
        self._nthreads = nthreads
        self._new_content()

    def _new_content(self):
        # What meshcast.dask names the scene's content by: a new name for
        # each geometry added (a pickled copy keeps it: the same content).
        self._token = _uuid.uuid4().hex

    def _content_token(self):
        return ("meshcast.RaycastingScene", self._token)

    def _threads(self, nthreads):
        return nthreads if nthreads else self._nthreads

    def add_triangles(self, vertex_positions=None, triangle_indices=None, mesh=None):
        """Adds a mesh: vertex_positions (V, 3) float32 or float64 and
        triangle_indices (T, 3) integers, or ``mesh=`` (or the first
        argument) an object with ``.vertex.positions`` and
        ``.triangle.indices`` (Open3D's ``t.geometry.TriangleMesh``).
        Returns its geometry id (0, 1, ...)."""
        if mesh is None and triangle_indices is None:
            mesh = vertex_positions
        if mesh is not None:
            if vertex_positions is not None and vertex_positions is not mesh or triangle_indices is not None:
                raise TypeError("add_triangles: a mesh, or vertex_positions and triangle_indices, not both")
            vertex_positions, triangle_indices = mesh.vertex.positions, mesh.triangle.indices
        if vertex_positions is None:
            raise TypeError("add_triangles: vertex_positions and triangle_indices, or a mesh")
        geometry_id = self._scene.add_triangles(_array(vertex_positions), _array(triangle_indices))
        self._new_content()
        return geometry_id

    def __copy__(self):
        """A scene of the same geometries (their structures copied): adding to
        one leaves the other as it was."""
        twin = type(self).__new__(type(self))
        twin._scene = self._scene.copy()
        twin._nthreads = self._nthreads
        twin._new_content()
        return twin

    def __deepcopy__(self, memo):
        return self.__copy__()

    def cast_rays(self, rays, nthreads=0, *, uvs=True, normals=True, out=None, backend="cpu"):
        """The closest hit of each ray.

        rays: (..., 6) float32 or float64, [ox, oy, oz, dx, dy, dz]; t is in
        units of the direction. nthreads: the cast's threads (0: the scene's).
        uvs, normals: False leaves primitive_uvs, primitive_normals out (and
        their work). out: a dict of arrays to write the answer into, keyed as
        below (C-contiguous, the answer's dtype and shape); the others are
        made. backend: "cpu" or "vulkan" (the GPU; RuntimeError where the
        machine has none), the same answers.

        Returns (Tensors in the rays' shape): t_hit (float32, inf on a miss),
        geometry_ids, primitive_ids (uint32, INVALID_ID on a miss),
        primitive_uvs (..., 2) float32, the barycentrics of corners 1 and 2,
        primitive_normals (..., 3) float32, the unit normal (b - a) x (c - a)
        (within 6e-5 radians; zeros on a miss)."""
        return _tensors(self._scene.cast_rays(_array(rays), self._threads(nthreads), uvs, normals, out, backend))

    def test_occlusions(self, rays, tnear=0.0, tfar=float("inf"), nthreads=0, *, out=None, backend="cpu"):
        """Whether anything lies on each ray with tnear <= t <= tfar: a bool
        Tensor in the rays' shape. rays: (..., 6), as cast_rays. tnear, tfar:
        numbers or arrays of the rays' shape. nthreads: the cast's threads (0:
        the scene's). out: a bool array to write into. backend: "cpu" or
        "vulkan"."""
        return _tensors(self._scene.test_occlusions(_array(rays), tnear, tfar, self._threads(nthreads), out, backend))

    def count_intersections(self, rays, nthreads=0):
        """How many times each ray crosses the meshes for t >= 0: an int32
        Tensor in the rays' shape. rays: (..., 6), as cast_rays; nthreads:
        the call's threads (0: the scene's). A crossing
        through a shared edge or a vertex counts once, whichever way the
        triangles are wound, so the parity tells inside from outside of a
        closed mesh; every crossing is counted, however many."""
        return _tensors(self._scene.count_intersections(_array(rays), self._threads(nthreads)))

    def list_intersections(self, rays, nthreads=0):
        """Every crossing of every ray (rays: (..., 6), as cast_rays; nthreads:
        the call's threads, 0: the scene's), Open3D 0.18's layout: ray i's are [ray_splits[i], ray_splits[i + 1]) of
        ray_ids, geometry_ids, primitive_ids (uint32), primitive_uvs (H, 2)
        and t_hit (float32), nearest first; ray_splits has one entry more
        than the rays. A crossing through an edge or vertex is listed as
        count_intersections counts it, by one of its triangles. Every
        crossing is listed, however many a ray has (only beyond 4096 of one
        ray at one t would some be left out, with a RuntimeWarning)."""
        return _tensors(self._scene.list_intersections(_array(rays), self._threads(nthreads)))

    def compute_closest_points(self, query_points, nthreads=0):
        """The nearest point of the scene's meshes to each query point.

        query_points: (..., 3) float32 or float64 (finite). nthreads: the
        call's threads (0: the scene's). Returns Tensors in the points'
        shape: points (..., 3) float32, geometry_ids and primitive_ids
        (uint32), primitive_uvs (..., 2) (the barycentrics of corners 1 and
        2 of the nearest point), primitive_normals (..., 3) (the triangle's
        unit normal), Open3D's keys; for a scene without geometry, NaN
        points and INVALID_ID. Worked out in double from each triangle as
        stored (the recommended layout's corners lie within its stated
        bound of the mesh's, a few millionths of its diagonal); at one
        distance the lower geometry id, then the lower triangle."""
        return _tensors(self._scene.compute_closest_points(_array(query_points), self._threads(nthreads)))

    def compute_distance(self, query_points, nthreads=0):
        """The distance from each query point to the nearest point of the
        scene's meshes: a float32 Tensor in the points' shape (inf for a
        scene without geometry). query_points: (..., 3) float32 or float64;
        nthreads: the call's threads (0: the scene's)."""
        return _tensors(self._scene.compute_distance(_array(query_points), self._threads(nthreads)))

    def _inside(self, query_points, nsamples, nthreads, sign="parity"):
        # Parity of the crossings of rays from each point: exact on a closed
        # mesh (a crossing through an edge or vertex counts once), so one ray
        # decides; nsamples rays vote, as Open3D's do. Or the winding number.
        if sign == "winding":
            return self._scene.winding_inside(_array(query_points), self._threads(nthreads))
        if sign != "parity":
            raise ValueError(f"sign: {sign!r} is neither \"parity\" nor \"winding\"")
        if not isinstance(nsamples, (int, _np.integer)) or nsamples < 1 or nsamples % 2 == 0:
            raise ValueError(f"nsamples: {nsamples!r} is not an odd number of rays (1, 3, 5, ...)")
        points = _np.asarray(_array(query_points))
        if points.ndim < 1 or points.shape[-1] != 3:
            raise ValueError(f"query_points: shape {points.shape} is not (..., 3): each point is x, y, z")
        dtype = _np.float64 if points.dtype == _np.float64 else _np.float32
        flat = points.reshape(-1, 3).astype(dtype, copy=False)
        bad = _np.flatnonzero(~_np.isfinite(flat).all(axis=1))
        if len(bad):
            raise ValueError(f"query_points[{bad[0]}]: {flat[bad[0]].tolist()} is not a finite point")
        votes = _np.zeros(len(flat), _np.int32)
        for direction in _SIGN_DIRECTIONS[:nsamples] if nsamples <= len(_SIGN_DIRECTIONS) else _sign_directions(nsamples):
            rays = _np.empty((len(flat), 6), dtype)
            rays[:, :3] = flat
            rays[:, 3:] = direction
            votes += self._scene.count_intersections(rays, self._threads(nthreads)) % 2
        return (2 * votes > nsamples).reshape(points.shape[:-1])

    def compute_signed_distance(self, query_points, nthreads=0, nsamples=1, sign="parity"):
        """compute_distance, negative inside: a float32 Tensor in the points'
        shape. query_points: (..., 3) float32 or float64 (finite); nthreads:
        the call's threads (0: the scene's); nsamples: how many rays (odd)
        decide inside, by majority.

        sign="parity" (Open3D's way): inside is an odd number of crossings of
        a ray from the point, exact on a closed mesh wound either way (a
        crossing through an edge or vertex counts once, never missed); on a
        mesh with holes the rays may disagree, and more of them vote.

        sign="winding": inside is a generalized winding number above 1/2 in
        magnitude (compute_winding_number), right on meshes with holes, gaps
        and self-intersections where parity and votes are not; decided on
        the exact sum wherever the expansion's bound leaves it in doubt, so
        the sign is the exact winding number's. nsamples is not used."""
        distance = self.compute_distance(query_points, nthreads).numpy()
        inside = self._inside(query_points, nsamples, nthreads, sign)
        return _tensors(_np.where(inside, -distance, distance).astype(_np.float32))

    def compute_occupancy(self, query_points, nthreads=0, nsamples=1, sign="parity"):
        """1.0 inside, 0.0 outside: a float32 Tensor in the points' shape,
        decided as the sign of compute_signed_distance is, with the same
        query_points, nthreads, nsamples and sign."""
        return _tensors(self._inside(query_points, nsamples, nthreads, sign).astype(_np.float32))

    def compute_winding_number(self, query_points, nthreads=0, tolerance=1e-2):
        """The generalized winding number of the scene's meshes at each point
        (Jacobson et al. 2013; every geometry's summed): 1 inside a closed
        mesh wound outward, -1 wound inward, 0 outside, in between near
        holes. Evaluated on each geometry's tree with Barill et al.'s
        second-order far-field expansion (2018).

        query_points: (..., 3) float32 or float64 (finite), each rounded to
        float in its geometry's frame as for distances. nthreads: the call's
        threads (0: the scene's). Returns float64 Tensors in the points'
        shape: winding_number, and bound, such that |winding_number - exact|
        <= bound, where exact is the sum of every stored triangle's solid
        angle (Van Oosterom and Strackee) over 4 pi, seen from the point.
        tolerance, in (0, 1): a cluster of triangles is expanded only where
        its error is at most this share of the most it could add, so the
        bound is at most that share of the sum of those (for the default
        1e-2, a few thousandths for a point seeing a closed mesh from
        outside); a looser tolerance opens fewer clusters."""
        return _tensors(self._scene.winding_numbers(_array(query_points), self._threads(nthreads), tolerance))

    @staticmethod
    def create_rays_pinhole(*args, **kwargs):
        """Rays of a pinhole camera, Open3D's two forms, (height_px,
        width_px, 6) float32, one ray a pixel through its centre:

        ``create_rays_pinhole(intrinsic_matrix, extrinsic_matrix, width_px,
        height_px)``: the 3x3 intrinsic matrix K and the 4x4 world-to-camera
        matrix [R t]; each ray starts at the camera's centre -R^T t, its
        direction R^T K^-1 (x + 0.5, y + 0.5, 1).

        ``create_rays_pinhole(fov_deg, center, eye, up, width_px,
        height_px)``: a horizontal field of view in degrees, the camera at
        ``eye`` looking at ``center``, ``up`` the up vector, made into K and
        [R t] as Open3D makes them."""
        look_at = "fov_deg" in kwargs or (args and _np.ndim(_array(args[0])) == 0)
        given = _pinhole_arguments(_PINHOLE_FORMS[1] if look_at else _PINHOLE_FORMS[0], args, kwargs)
        if look_at:
            return _pinhole_rays(*_look_at(**given))
        return _pinhole_rays(_array(given["intrinsic_matrix"]), _array(given["extrinsic_matrix"]),
                             given["width_px"], given["height_px"])

    @property
    def nbytes(self):
        """The memory the scene's structures hold: every geometry's blob, the
        top level, and what calls have made since: the triangles' normals (4
        bytes a triangle; kept from the start for a compact geometry, made by
        the first call answering primitive_normals for an exact one), the
        winding numbers' clusters, and the corners' table of list and count
        calls."""
        return self._scene.nbytes


def _sign_directions(n):
    # Fixed directions for the inside test's rays: none along an axis or a
    # diagonal (a mesh's edges often are), the same on every call.
    rng = _np.random.default_rng(20261129)
    d = rng.normal(size=(n, 3))
    return d / _np.linalg.norm(d, axis=1, keepdims=True)


_SIGN_DIRECTIONS = _sign_directions(9)


def _pinhole_rays(intrinsic, extrinsic, width_px, height_px):
    width, height = int(width_px), int(height_px)
    if width < 1 or height < 1:
        raise ValueError(f"create_rays_pinhole: {width} x {height} pixels")
    k = _np.asarray(intrinsic, _np.float64)
    e = _np.asarray(extrinsic, _np.float64)
    if k.shape != (3, 3) or e.shape != (4, 4):
        raise ValueError(f"create_rays_pinhole: intrinsic_matrix {k.shape} and extrinsic_matrix {e.shape}, "
                         "not (3, 3) and (4, 4)")
    r_t = e[:3, :3].T
    to_world = r_t @ _np.linalg.inv(k)
    x, y = _np.meshgrid(_np.arange(width) + 0.5, _np.arange(height) + 0.5)
    pixels = _np.stack([x, y, _np.ones_like(x)], axis=-1)
    rays = _np.empty((height, width, 6), _np.float32)
    rays[..., :3] = -r_t @ e[:3, 3]
    rays[..., 3:] = pixels @ to_world.T
    return rays.view(Tensor)


# create_rays_pinhole's two forms, Open3D's overloads.
_PINHOLE_FORMS = (("intrinsic_matrix", "extrinsic_matrix", "width_px", "height_px"),
                  ("fov_deg", "center", "eye", "up", "width_px", "height_px"))


def _pinhole_arguments(names, args, kwargs):
    # The arguments of one form by name: TypeError naming what is wrong and
    # both forms' arguments, as Open3D's overload resolution does, for an
    # argument too many, one unknown, given twice or missing.
    given = dict(zip(names, args))
    wrong = [f"{len(args)} positional arguments"] if len(args) > len(names) else []
    wrong += [f"{key}= given twice" if key in given else f"an unknown keyword {key}="
              for key in kwargs if key in given or key not in names]
    given.update((key, value) for key, value in kwargs.items() if key in names)
    wrong += [f"no {name}" for name in names if name not in given]
    if wrong:
        forms = " or ".join(f"({', '.join(form)})" for form in _PINHOLE_FORMS)
        raise TypeError(f"create_rays_pinhole: {', '.join(wrong)}; it takes {forms}")
    return given


def _look_at(fov_deg, center, eye, up, width_px, height_px):
    center, eye, up = (_np.asarray(_array(v), _np.float64).reshape(3) for v in (center, eye, up))
    focal = 0.5 * width_px / _np.tan(_np.radians(0.5 * fov_deg))
    k = _np.array([[focal, 0, 0.5 * width_px], [0, focal, 0.5 * height_px], [0, 0, 1]])
    front = (center - eye) / _np.linalg.norm(center - eye)
    right = _np.cross(up / _np.linalg.norm(up), front)
    right /= _np.linalg.norm(right)
    r = _np.stack([right, _np.cross(front, right), front])
    e = _np.eye(4)
    e[:3, :3] = r
    e[:3, 3] = -r @ eye
    return k, e, width_px, height_px
