"""Open3D's ray-casting and distance-query tutorials (open3d.org, "Ray
Casting" and "Distance Queries", Open3D 0.18), their code as written there
but for the import line, run on meshcast.open3d; every number they print
or draw checked against an independent float64 answer (oracle.py,
point_oracle.py). matplotlib is stood in for by a recorder of what the
tutorials draw, and the cells that open a viewer window are left out."""

import sys
import types

import numpy as np
import pytest

import meshcast
import oracle
import shapes
from point_oracle import nearest, winding_number

RAY_CASTING = '''
import meshcast.open3d as o3d
import numpy as np
import matplotlib.pyplot as plt

# Create meshes and convert to open3d.t.geometry.TriangleMesh
cube = o3d.geometry.TriangleMesh.create_box().translate([0, 0, 0])
cube = o3d.t.geometry.TriangleMesh.from_legacy(cube)
torus = o3d.geometry.TriangleMesh.create_torus().translate([0, 0, 2])
torus = o3d.t.geometry.TriangleMesh.from_legacy(torus)
sphere = o3d.geometry.TriangleMesh.create_sphere(radius=0.5).translate(
    [1, 2, 3])
sphere = o3d.t.geometry.TriangleMesh.from_legacy(sphere)

scene = o3d.t.geometry.RaycastingScene()
scene.add_triangles(cube)
scene.add_triangles(torus)
_ = scene.add_triangles(sphere)

rays = o3d.core.Tensor([[0.5, 0.5, 10, 0, 0, -1], [-1, -1, -1, 0, 0, -1]],
                       dtype=o3d.core.Dtype.Float32)

ans = scene.cast_rays(rays)

print(ans.keys())

print(ans['t_hit'].numpy(), ans['geometry_ids'].numpy())

# We create a camera with the following parameters
rays = o3d.t.geometry.RaycastingScene.create_rays_pinhole(
    fov_deg=90,
    center=[0, 0, 2],
    eye=[2, 3, 0],
    up=[0, 1, 0],
    width_px=640,
    height_px=480,
)
# We can directly pass the rays tensor to the cast_rays function.
ans = scene.cast_rays(rays)

plt.imshow(ans['t_hit'].numpy())

plt.imshow(np.abs(ans['primitive_normals'].numpy()))

plt.imshow(ans['geometry_ids'].numpy(), vmax=3)

hit = ans['t_hit'].isfinite()
points = rays[hit][:,:3] + rays[hit][:,3:]*ans['t_hit'][hit].reshape((-1,1))
pcd = o3d.t.geometry.PointCloud(points)
'''

DISTANCE_QUERIES = '''
import meshcast.open3d as o3d
import numpy as np
import matplotlib.pyplot as plt

# Load mesh and convert to open3d.t.geometry.TriangleMesh
armadillo_data = o3d.data.ArmadilloMesh()
mesh = o3d.io.read_triangle_mesh(armadillo_data.path)
mesh = o3d.t.geometry.TriangleMesh.from_legacy(mesh)

# Create a scene and add the triangle mesh
scene = o3d.t.geometry.RaycastingScene()
_ = scene.add_triangles(mesh)  # we do not need the geometry ID for mesh

query_point = o3d.core.Tensor([[10, 10, 10]], dtype=o3d.core.Dtype.Float32)

# Compute distance of the query point from the surface
unsigned_distance = scene.compute_distance(query_point)
signed_distance = scene.compute_signed_distance(query_point)
occupancy = scene.compute_occupancy(query_point)

print("unsigned distance", unsigned_distance.numpy())
print("signed_distance", signed_distance.numpy())
print("occupancy", occupancy.numpy())

min_bound = mesh.vertex.positions.min(0).numpy()
max_bound = mesh.vertex.positions.max(0).numpy()

N = 256
query_points = np.random.uniform(low=min_bound, high=max_bound,
                                 size=[N, 3]).astype(np.float32)

# Compute the signed distance for N random points
signed_distance = scene.compute_signed_distance(query_points)

xyz_range = np.linspace(min_bound, max_bound, num=32)

# query_points is a [32,32,32,3] array ..
query_points = np.stack(np.meshgrid(*xyz_range.T), axis=-1).astype(np.float32)

# signed distance is a [32,32,32] array
signed_distance = scene.compute_signed_distance(query_points)

# We can visualize a slice of the distance field directly with matplotlib
plt.imshow(signed_distance.numpy()[:, :, 15])

occupancy = scene.compute_occupancy(query_points)
plt.imshow(occupancy.numpy()[:, :, 15])

cube = o3d.t.geometry.TriangleMesh.from_legacy(
    o3d.geometry.TriangleMesh.create_box().translate([-1.2, -1.2, 0]))
sphere = o3d.t.geometry.TriangleMesh.from_legacy(
    o3d.geometry.TriangleMesh.create_sphere(0.5).translate([0.7, 0.8, 0]))

scene = o3d.t.geometry.RaycastingScene()
# Add triangle meshes and remember ids
mesh_ids = {}
mesh_ids[scene.add_triangles(cube)] = 'cube'
mesh_ids[scene.add_triangles(sphere)] = 'sphere'

query_point = o3d.core.Tensor([[0, 0, 0]], dtype=o3d.core.Dtype.Float32)

# We compute the closest point on the surface for the point at position [0,0,0].
ans = scene.compute_closest_points(query_point)

# Compute_closest_points provides the point on the surface, the geometry id,
# and the primitive id.
# The dictionary keys are
#.    points
#.    geometry_ids
#.    primitive_ids
print('The closest point on the surface is', ans['points'].numpy())
print('The closest point is on the surface of the',
      mesh_ids[ans['geometry_ids'][0].item()])
print('The closest point belongs to triangle', ans['primitive_ids'][0].item())
'''


class Recorder:
    """matplotlib.pyplot as the tutorials call it: imshow keeps its image."""

    def __init__(self):
        self.images = []

    def imshow(self, image, **kwargs):
        self.images.append(np.array(image))

    def __getattr__(self, name):
        return lambda *args, **kwargs: None


def run_tutorial(code, monkeypatch, capsys):
    plt = Recorder()
    matplotlib = types.ModuleType("matplotlib")
    pyplot = types.ModuleType("matplotlib.pyplot")
    pyplot.imshow = plt.imshow
    matplotlib.pyplot = pyplot
    monkeypatch.setitem(sys.modules, "matplotlib", matplotlib)
    monkeypatch.setitem(sys.modules, "matplotlib.pyplot", pyplot)
    namespace = {}
    exec(compile(code, "tutorial", "exec"), namespace)
    return namespace, plt.images, capsys.readouterr().out


def legacy_meshes(o3d, *meshes):
    """The geometries as one float64 mesh, and each triangle's geometry."""
    vertices, triangles, owner = [], [], []
    base = 0
    for g, m in enumerate(meshes):
        vertices.append(np.asarray(m.vertex.positions, np.float64))
        triangles.append(np.asarray(m.triangle.indices) + base)
        owner.append(np.full(len(m.triangle.indices), g))
        base += len(m.vertex.positions)
    return np.concatenate(vertices), np.concatenate(triangles), np.concatenate(owner)


def check_hits(scene_answer, rays, vertices, triangles, owner, what):
    """t_hit and geometry_ids against the oracle's nearest hit, on the rays
    whose answer the oracle is sure of."""
    rays = np.asarray(rays, np.float64).reshape(-1, 6)
    candidates = oracle.brute_force(vertices, triangles, rays[:, :3], rays[:, 3:],
                                    delta=4e-6 * oracle.mesh_diagonal(vertices))
    t, tri, tol, unique = oracle.classify(candidates).nearest()
    clean = oracle.classify(candidates).clean & unique
    got_t = np.asarray(scene_answer["t_hit"]).reshape(-1)
    got_g = np.asarray(scene_answer["geometry_ids"]).reshape(-1)
    assert clean.mean() > 0.95, what
    miss = clean & np.isinf(t)
    assert np.isinf(got_t[miss]).all() and (got_g[miss] == meshcast.RaycastingScene.INVALID_ID).all(), what
    hit = clean & np.isfinite(t)
    assert (np.abs(got_t[hit] - t[hit]) <= tol[hit] + 1e-6 * np.abs(t[hit])).all(), what
    assert np.array_equal(got_g[hit], owner[tri[hit]]), what
    return hit.sum()


def test_ray_casting_tutorial(monkeypatch, capsys):
    ns, images, printed = run_tutorial(RAY_CASTING, monkeypatch, capsys)
    o3d = ns["o3d"]
    vertices, triangles, owner = legacy_meshes(o3d, ns["cube"], ns["torus"], ns["sphere"])
    assert "t_hit" in printed and "geometry_ids" in printed
    # The two rays of its first cell: down through the torus's tube at
    # (0.5, 0.5) (through a ring of its vertices: the nearest of the
    # oracle's candidates there), and one that misses.
    first = np.array([[0.5, 0.5, 10, 0, 0, -1], [-1, -1, -1, 0, 0, -1]], np.float64)
    answer = ns["scene"].cast_rays(first.astype(np.float32))
    candidates = oracle.brute_force(vertices, triangles, first[:, :3], first[:, 3:])
    nearest_t = candidates.t[candidates.ray == 0].min()
    assert abs(float(answer["t_hit"][0]) - nearest_t) < 1e-4 and answer["geometry_ids"][0] == 1
    assert (candidates.ray == 1).sum() == 0 and np.isinf(answer["t_hit"][1])
    assert answer["geometry_ids"][1] == meshcast.RaycastingScene.INVALID_ID
    # The camera's 640 x 480 rays: every 37th pixel against the oracle,
    # and the three images drawn are the answer's.
    rays = np.asarray(ns["rays"])
    assert rays.shape == (480, 640, 6)
    sample = rays.reshape(-1, 6)[::37]
    sampled = {key: np.asarray(ns["ans"][key]).reshape(-1)[::37] for key in ("t_hit", "geometry_ids")}
    assert check_hits(sampled, sample, vertices, triangles, owner, "the camera") > 500
    assert len(images) == 3
    assert np.array_equal(images[0], np.asarray(ns["ans"]["t_hit"]))
    assert np.array_equal(images[2], np.asarray(ns["ans"]["geometry_ids"]))
    # The virtual point cloud lies on the meshes.
    points = np.asarray(ns["pcd"].point.positions, np.float64)
    assert len(points) == np.isfinite(np.asarray(ns["ans"]["t_hit"])).sum()
    distance = nearest(points[::97], vertices, triangles)[0]
    assert (distance < 1e-4).all()


def test_distance_queries_tutorial(monkeypatch, capsys):
    if not meshcast.features.get("reader"):
        pytest.skip("meshcast built without the mesh reader")
    monkeypatch.setenv("MESHCAST_DATA", shapes.DATA)
    ns, images, printed = run_tutorial(DISTANCE_QUERIES, monkeypatch, capsys)
    o3d = ns["o3d"]
    v, t = meshcast.read_mesh(shapes.DATA + "/armadillo.off")
    v, t = v.astype(np.float64), t.astype(np.int64)
    diagonal = oracle.mesh_diagonal(v)
    bound = 4e-6 * diagonal  # the recommended layout's corners, within this of the input's
    # The far point (10, 10, 10): distance, sign and occupancy.
    far = np.array([[10.0, 10, 10]])
    want = nearest(far, v, t)[0]
    assert abs(float(ns["unsigned_distance"].numpy()[0]) - want[0]) <= bound + 1e-6 * want[0]
    inside = abs(winding_number(far, v, t)[0]) > 0.5  # (10, 10, 10) lies in this armadillo's body
    assert ("occupancy [1.]" if inside else "occupancy [0.]") in printed
    # The 32^3 grid: a sample of its signed distances, and the slices drawn.
    grid = np.asarray(ns["query_points"], np.float64).reshape(-1, 3)
    signed = np.asarray(ns["signed_distance"]).reshape(-1)
    pick = np.arange(0, len(grid), 331)
    distance = nearest(grid[pick], v, t)[0]
    inside = np.abs(winding_number(grid[pick], v, t)) > 0.5
    assert (np.abs(np.abs(signed[pick]) - distance) <= bound + 1e-6 * distance).all()
    clear = distance > 1e-3 * diagonal
    assert np.array_equal((signed[pick] < 0)[clear], inside[clear])
    assert len(images) == 2
    assert np.array_equal(images[0], np.asarray(ns["signed_distance"])[:, :, 15])
    assert np.array_equal(images[1], (np.asarray(ns["signed_distance"]) < 0)[:, :, 15].astype(np.float32))
    # The cube and sphere scene: the closest point to the origin.
    cv, ct, owner = legacy_meshes(o3d, ns["cube"], ns["sphere"])
    d, tri, point = nearest(np.zeros((1, 3)), cv, ct)
    answer = ns["ans"]
    assert np.allclose(np.asarray(answer["points"])[0], point[0], atol=1e-5)
    assert ns["mesh_ids"][answer["geometry_ids"][0].item()] == ["cube", "sphere"][owner[tri[0]]]
    assert f"belongs to triangle {tri[0] - (0 if owner[tri[0]] == 0 else len(ns['cube'].triangle.indices))}" in printed
