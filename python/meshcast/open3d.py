"""The part of Open3D's API that its ray-casting and distance-query
tutorials use, on meshcast: ``import meshcast.open3d as o3d`` in place of
``import open3d as o3d`` runs them unchanged.

* ``o3d.core``: ``Tensor`` (a numpy array that answers ``.numpy()``),
  ``Dtype`` (``Float32``, ``Float64``, ``Int32``, ``Int64``, ``UInt8``,
  ``UInt32``, ``Bool``).
* ``o3d.geometry.TriangleMesh``: Open3D's legacy mesh (``vertices``,
  ``triangles``), with ``create_box``, ``create_sphere``, ``create_torus``
  (Open3D's parameters and vertex layout) and ``translate``.
* ``o3d.t.geometry``: ``RaycastingScene`` (meshcast's), ``TriangleMesh``
  with ``from_legacy`` and ``vertex.positions``/``triangle.indices``, and
  ``PointCloud`` (its ``point.positions``).
* ``o3d.io.read_triangle_mesh`` (OFF, OBJ, PLY, STL, by meshcast's reader).
* ``o3d.data``: ``ArmadilloMesh`` and ``BunnyMesh`` name the public meshes
  that ``scripts/fetch_meshes.sh`` puts in ``data/`` (CGAL's copies of the
  Stanford models), read from ``$MESHCAST_DATA`` or ``./data``; nothing is
  downloaded.

Nothing else of Open3D is here (no visualization, no other geometry).
"""

import os as _os
import types as _types

import numpy as _np

from . import RaycastingScene as _RaycastingScene
from . import Tensor as _Tensor
from . import read_mesh as _read_mesh


def _tensor(data, dtype=None):
    return _np.array(data, dtype=dtype).view(_Tensor)


core = _types.SimpleNamespace(
    Tensor=_tensor,
    Dtype=_types.SimpleNamespace(Float32=_np.float32, Float64=_np.float64, Int32=_np.int32, Int64=_np.int64,
                                 UInt8=_np.uint8, UInt32=_np.uint32, Bool=_np.bool_),
)


class _LegacyTriangleMesh:
    """Open3D's legacy ``geometry.TriangleMesh``: float64 ``vertices`` (V, 3)
    and int32 ``triangles`` (T, 3), numpy arrays."""

    def __init__(self, vertices=None, triangles=None):
        self.vertices = _np.zeros((0, 3)) if vertices is None else _np.asarray(vertices, _np.float64)
        self.triangles = _np.zeros((0, 3), _np.int32) if triangles is None else _np.asarray(triangles, _np.int32)

    def translate(self, translation, relative=True):
        """Moves the mesh by ``translation`` (or its centre to it with
        relative=False); returns the mesh, as Open3D does."""
        translation = _np.asarray(translation, _np.float64).reshape(3)
        if not relative:
            translation = translation - self.vertices.mean(axis=0)
        self.vertices = self.vertices + translation
        return self

    def get_min_bound(self):
        return self.vertices.min(axis=0)

    def get_max_bound(self):
        return self.vertices.max(axis=0)

    @staticmethod
    def create_box(width=1.0, height=1.0, depth=1.0):
        """The box [0, width] x [0, height] x [0, depth]: 8 vertices, 12
        triangles wound outward."""
        v = _np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], _np.float64)
        v *= [width, height, depth]
        # corners: index = x + 2 y + 4 z
        faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
        t = [tri for a, b, c, d in faces for tri in ((a, b, c), (a, c, d))]
        return _LegacyTriangleMesh(v, t)

    @staticmethod
    def create_sphere(radius=1.0, resolution=20):
        """A UV sphere about the origin: the poles on z, resolution rings of
        2 * resolution vertices between them, wound outward."""
        n = int(resolution)
        if n < 1:
            raise ValueError(f"create_sphere: resolution {resolution} is below 1")
        v = [(0.0, 0.0, radius), (0.0, 0.0, -radius)]
        for i in range(1, n):
            theta = _np.pi * i / n
            for j in range(2 * n):
                phi = 2 * _np.pi * j / (2 * n)
                v.append((radius * _np.sin(theta) * _np.cos(phi), radius * _np.sin(theta) * _np.sin(phi),
                          radius * _np.cos(theta)))
        t = []
        ring = lambda i, j: 2 + (i - 1) * 2 * n + j % (2 * n)  # noqa: E731
        for j in range(2 * n):
            t.append((0, ring(1, j), ring(1, j + 1)))
            t.append((1, ring(n - 1, j + 1), ring(n - 1, j)))
        for i in range(1, n - 1):
            for j in range(2 * n):
                t.append((ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)))
                t.append((ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)))
        return _LegacyTriangleMesh(v, t)

    @staticmethod
    def create_torus(torus_radius=1.0, tube_radius=0.5, radial_resolution=30, tubular_resolution=20):
        """A torus about the z axis: radial_resolution rings of
        tubular_resolution vertices, wound outward."""
        rings, around = int(radial_resolution), int(tubular_resolution)
        if rings < 3 or around < 3:
            raise ValueError(f"create_torus: resolutions {radial_resolution}, {tubular_resolution} (3 at least)")
        v, t = [], []
        for i in range(rings):
            u = 2 * _np.pi * i / rings
            centre = _np.array([_np.cos(u), _np.sin(u), 0.0]) * torus_radius
            for j in range(around):
                w = 2 * _np.pi * j / around
                v.append(centre + tube_radius * (_np.cos(w) * _np.array([_np.cos(u), _np.sin(u), 0.0]) +
                                                 _np.sin(w) * _np.array([0.0, 0.0, 1.0])))
        for i in range(rings):
            for j in range(around):
                a, b = i * around + j, ((i + 1) % rings) * around + j
                c, d = ((i + 1) % rings) * around + (j + 1) % around, i * around + (j + 1) % around
                t.append((a, b, c))
                t.append((a, c, d))
        return _LegacyTriangleMesh(v, t)


geometry = _types.SimpleNamespace(TriangleMesh=_LegacyTriangleMesh)


class _TensorMesh:
    """Open3D's ``t.geometry.TriangleMesh``: ``vertex.positions`` (float32
    Tensor) and ``triangle.indices`` (int64 Tensor)."""

    def __init__(self, positions=None, indices=None):
        positions = _np.zeros((0, 3), _np.float32) if positions is None else positions
        indices = _np.zeros((0, 3), _np.int64) if indices is None else indices
        self.vertex = _types.SimpleNamespace(positions=_np.asarray(positions, _np.float32).view(_Tensor))
        self.triangle = _types.SimpleNamespace(indices=_np.asarray(indices, _np.int64).view(_Tensor))

    @staticmethod
    def from_legacy(mesh_legacy, vertex_dtype=_np.float32, triangle_dtype=_np.int64):
        mesh = _TensorMesh(mesh_legacy.vertices, mesh_legacy.triangles)
        mesh.vertex.positions = _np.asarray(mesh_legacy.vertices, vertex_dtype).view(_Tensor)
        mesh.triangle.indices = _np.asarray(mesh_legacy.triangles, triangle_dtype).view(_Tensor)
        return mesh

    def to_legacy(self):
        return _LegacyTriangleMesh(self.vertex.positions, self.triangle.indices)


class _PointCloud:
    """Open3D's ``t.geometry.PointCloud``: ``point.positions``."""

    def __init__(self, positions):
        self.point = _types.SimpleNamespace(positions=_np.asarray(positions).view(_Tensor))


t = _types.SimpleNamespace(
    geometry=_types.SimpleNamespace(RaycastingScene=_RaycastingScene, TriangleMesh=_TensorMesh,
                                    PointCloud=_PointCloud))


def _read_triangle_mesh(filename, *args, **kwargs):
    vertices, triangles = _read_mesh(filename)
    return _LegacyTriangleMesh(vertices, triangles)


io = _types.SimpleNamespace(read_triangle_mesh=_read_triangle_mesh)


def _data_mesh(file):
    def dataset(data_root=""):
        folder = data_root or _os.environ.get("MESHCAST_DATA") or "data"
        path = _os.path.join(folder, file)
        if not _os.path.isfile(path):
            raise FileNotFoundError(f"{path}: meshcast's o3d.data reads the public meshes from $MESHCAST_DATA or "
                                    "./data (bash scripts/fetch_meshes.sh fetches them); it downloads nothing")
        return _types.SimpleNamespace(path=path)
    return dataset


data = _types.SimpleNamespace(ArmadilloMesh=_data_mesh("armadillo.off"), BunnyMesh=_data_mesh("bunny00.off"))
