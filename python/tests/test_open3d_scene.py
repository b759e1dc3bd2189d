"""The rest of Open3D's RaycastingScene: signed distance and occupancy
(the sign against the exact winding number), pinhole rays, the mesh
keyword, copies, and the answers' isfinite()."""

import copy
import types

import numpy as np
import pytest

import meshcast
import shapes
from point_oracle import nearest, winding_number


def closed_meshes():
    sv, st = shapes.sphere()
    cv, ct = shapes.cube()
    ov, ot = shapes.octahedron()
    return {"sphere": (sv, st), "cube": (cv, ct), "octahedron": (ov, ot)}


def windings(t, rng):
    """The mesh wound outward, inward, and half of its triangles each way."""
    flipped = t[:, ::-1].copy()
    mixed = np.where(rng.uniform(size=(len(t), 1)) < 0.5, t, flipped)
    return {"outward": t, "inward": flipped, "mixed": mixed}


@pytest.mark.parametrize("name", sorted(closed_meshes()))
def test_sign_and_occupancy_equal_the_winding_number(name):
    v, t = closed_meshes()[name]
    rng = np.random.default_rng(4)
    lo, hi = v.min(0).astype(np.float64), v.max(0).astype(np.float64)
    diagonal = np.linalg.norm(hi - lo)
    p = lo - 0.3 * (hi - lo) + rng.uniform(0, 1.6, (400, 3)) * (hi - lo)
    # and points on grid planes through corners and edges, where a ray may
    # meet shared edges and vertices
    p = np.concatenate([p, np.round(p * 4) / 4])
    inside = np.abs(winding_number(p, v, t)) > 0.5
    distance = nearest(p, v, t)[0]
    keep = distance > 1e-6 * diagonal  # the sign of a point on the surface is either
    for winding, tris in windings(t, rng).items():
        scene = meshcast.RaycastingScene()
        scene.add_triangles(v, tris)
        for nsamples in (1, 3):
            sd = scene.compute_signed_distance(p, nsamples=nsamples).numpy()
            occupancy = scene.compute_occupancy(p, nsamples=nsamples).numpy()
            assert sd.dtype == np.float32 and occupancy.dtype == np.float32
            what = f"{name} wound {winding}, nsamples {nsamples}"
            assert np.array_equal((sd < 0)[keep], inside[keep]), what
            assert np.array_equal(occupancy[keep], inside[keep].astype(np.float32)), what
            assert np.array_equal(np.abs(sd), scene.compute_distance(p).numpy()), what


def test_nsamples_must_be_odd_and_points_three_wide():
    v, t = shapes.cube()
    scene = meshcast.RaycastingScene()
    scene.add_triangles(v, t)
    for bad in (0, 2, -1, 1.5):
        with pytest.raises(ValueError, match="nsamples"):
            scene.compute_occupancy(np.zeros((1, 3)), nsamples=bad)
    with pytest.raises(ValueError, match=r"\(\.\.\., 3\)"):
        scene.compute_signed_distance(np.zeros((2, 4)))
    with pytest.raises(ValueError, match=r"query_points\[1\]"):
        scene.compute_occupancy(np.array([[0, 0, 0], [np.nan, 0, 0]]))


def test_pinhole_rays_from_matrices_reproject_to_their_pixels():
    k = np.array([[500.0, 0, 320], [0, 480, 240], [0, 0, 1]])
    angle = 0.3
    r = np.array([[np.cos(angle), 0, np.sin(angle)], [0, 1, 0], [-np.sin(angle), 0, np.cos(angle)]])
    t = np.array([0.5, -1.0, 4.0])
    e = np.eye(4)
    e[:3, :3], e[:3, 3] = r, t
    rays = meshcast.RaycastingScene.create_rays_pinhole(k, e, 64, 48).numpy()
    assert rays.shape == (48, 64, 6) and rays.dtype == np.float32
    # every ray starts at the camera's centre: the world point the extrinsic sends to 0
    centre = rays[..., :3].reshape(-1, 3).astype(np.float64)
    assert np.allclose(r @ centre.T + t[:, None], 0, atol=1e-5)
    # a point along each ray lands on its pixel's centre
    along = centre + 2.0 * rays[..., 3:].reshape(-1, 3)
    cam = r @ along.T + t[:, None]
    pix = k @ cam
    pix = pix[:2] / pix[2]
    y, x = np.mgrid[0:48, 0:64]
    assert np.allclose(pix[0], x.ravel() + 0.5, atol=1e-3) and np.allclose(pix[1], y.ravel() + 0.5, atol=1e-3)
    # keywords, and Open3D's names
    again = meshcast.RaycastingScene.create_rays_pinhole(intrinsic_matrix=k, extrinsic_matrix=e, width_px=64, height_px=48)
    assert np.array_equal(again.numpy(), rays)


def test_pinhole_rays_from_a_look_at_camera():
    eye, center, up = np.array([2.0, 3.0, 0.0]), np.array([0.0, 0.0, 2.0]), np.array([0.0, 1.0, 0.0])
    width, height, fov = 80, 60, 90.0
    rays = meshcast.RaycastingScene.create_rays_pinhole(fov_deg=fov, center=center, eye=eye, up=up,
                                                        width_px=width, height_px=height).numpy()
    assert rays.shape == (height, width, 6)
    assert np.allclose(rays[..., :3], eye, atol=1e-6)
    d = rays[..., 3:].astype(np.float64)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    front = (center - eye) / np.linalg.norm(center - eye)
    # the image's centre (between the four middle pixels) looks at `center`
    middle = d[height // 2 - 1:height // 2 + 1, width // 2 - 1:width // 2 + 1].mean(axis=(0, 1))
    assert np.allclose(middle / np.linalg.norm(middle), front, atol=1e-6)
    # the horizontal field of view: the outer pixels' edges, fov apart
    row = rays[height // 2, :, 3:].astype(np.float64)
    half_pixel = np.degrees(np.arctan(np.tan(np.radians(fov / 2)) / width))
    left, right = row[0] / np.linalg.norm(row[0]), row[-1] / np.linalg.norm(row[-1])
    spread = np.degrees(np.arccos(np.clip(left @ right, -1, 1)))
    assert abs(spread - fov) < 4 * half_pixel
    # Open3D's orientation: the first column looks towards up x front, the
    # first row away from up (its images come out turned half a turn)
    right = np.cross(up, front)
    upward = up - (up @ front) * front  # the camera's up, across its view
    assert rays[height // 2, 0, 3:] @ right < 0 < rays[height // 2, -1, 3:] @ right
    assert rays[0, width // 2, 3:] @ upward < 0 < rays[-1, width // 2, 3:] @ upward
    # the image's columns run along the camera's horizontal, rows along up
    assert abs((row[-1] - row[0]) @ up) < 1e-6
    assert abs((rays[-1, width // 2, 3:] - rays[0, width // 2, 3:]).astype(np.float64) @ np.cross(up, front)) < 1e-6
    # a scene cast with them: the positional form gives the same rays
    again = meshcast.RaycastingScene.create_rays_pinhole(fov, center, eye, up, width, height)
    assert np.array_equal(again.numpy(), rays)


def test_mesh_keyword_copies_and_isfinite():
    v, t = shapes.cube()
    mesh = types.SimpleNamespace(vertex=types.SimpleNamespace(positions=v), triangle=types.SimpleNamespace(indices=t))
    scene = meshcast.RaycastingScene()
    assert scene.add_triangles(mesh=mesh) == 0
    twin, deep = copy.copy(scene), copy.deepcopy(scene)
    sv, st = shapes.sphere()
    assert scene.add_triangles(sv, st) == 1
    rays = np.array([[0, 0, -10, 0, 0, 1], [0.25, -0.5, 10, 0, 0, -1], [5, 5, 5, 1, 0, 0]], np.float32)
    t_scene = scene.cast_rays(rays)["t_hit"]
    for other in (twin, deep):
        answer = other.cast_rays(rays)
        assert answer["geometry_ids"].numpy().tolist() == [0, 0, meshcast.RaycastingScene.INVALID_ID]
        assert other.add_triangles(sv, st) == 1  # its own next id, not the original's
    assert scene.cast_rays(rays)["geometry_ids"].numpy().tolist() == [0, 1, meshcast.RaycastingScene.INVALID_ID]
    finite = t_scene.isfinite()
    assert finite.numpy().tolist() == [True, True, False] and finite.dtype == bool
    hit = finite.numpy()
    points = rays[hit][:, :3] + rays[hit][:, 3:] * t_scene[hit].reshape((-1, 1))
    assert np.allclose(points[0], [0, 0, -1])
    with pytest.raises(TypeError):
        scene.add_triangles(v, t, mesh=mesh)
