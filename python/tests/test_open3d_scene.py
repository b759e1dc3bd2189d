"""The rest of Open3D's RaycastingScene: signed distance and occupancy
(the sign against the exact winding number), pinhole rays, the mesh
keyword, copies, and the answers' isfinite()."""

import copy
import types

import numpy as np
import pytest

import meshcast
import oracle
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


def test_pinhole_arguments_of_neither_form_are_a_type_error_naming_both():
    k, e = np.eye(3), np.eye(4)
    forms = (r"\(intrinsic_matrix, extrinsic_matrix, width_px, height_px\) or "
             r"\(fov_deg, center, eye, up, width_px, height_px\)")
    create = meshcast.RaycastingScene.create_rays_pinhole
    for args, kwargs, wrong in (((), dict(intrinsic=k, extrinsic_matrix=e, width_px=4, height_px=3),
                                 "an unknown keyword intrinsic=, no intrinsic_matrix"),
                                ((k, e, 4), {}, "no height_px"),
                                ((k, e, 4, 3), dict(width_px=4), "width_px= given twice"),
                                ((k, e, 4, 3, 1), {}, "5 positional arguments"),
                                ((), dict(fov_deg=60.0, center=[0, 0, 1], eye=[0, 0, 0], up=[0, 1, 0], width=4,
                                          height_px=3), "an unknown keyword width=, no width_px")):
        with pytest.raises(TypeError, match=f"create_rays_pinhole: {wrong}; it takes {forms}"):
            create(*args, **kwargs)


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


def padded_rays():
    """Rays at a sphere, with a camera's padding among them: a NaN origin, an
    infinite direction, a zero direction (rows 1, 3, 5)."""
    v, t = shapes.sphere()
    centre = v.mean(axis=0)
    rays = np.zeros((7, 6), np.float32)
    rays[:, :3] = centre + [0, 0, 10]
    rays[:, 3:] = [0, 0, -1]
    rays[:, 0] += np.linspace(-0.5, 0.5, 7)
    rays[1, 0] = np.nan
    rays[3, 4] = np.inf
    rays[5, 3:] = 0
    return v, t, rays


def test_rays_that_are_not_rays_miss_as_in_open3d():
    v, t, rays = padded_rays()
    scene = meshcast.RaycastingScene()
    scene.add_triangles(v, t)
    bad, good = [1, 3, 5], [0, 2, 4, 6]
    hit = scene.cast_rays(rays)
    assert np.isinf(hit["t_hit"].numpy()[bad]).all() and np.isfinite(hit["t_hit"].numpy()[good]).all()
    assert (hit["geometry_ids"].numpy()[bad] == scene.INVALID_ID).all()
    assert (hit["primitive_ids"].numpy()[bad] == scene.INVALID_ID).all()
    assert (hit["primitive_normals"].numpy()[bad] == 0).all()
    alone = scene.cast_rays(rays[good])
    for key in hit:
        assert np.array_equal(hit[key].numpy()[good], alone[key].numpy()), key
    assert scene.test_occlusions(rays).numpy().tolist() == [True, False, True, False, True, False, True]
    assert scene.count_intersections(rays).numpy().tolist() == [2, 0, 2, 0, 2, 0, 2]
    listed = scene.list_intersections(rays)
    assert np.diff(listed["ray_splits"].numpy()).tolist() == [2, 0, 2, 0, 2, 0, 2]
    # a second geometry: the scene's own walk, not one blob's
    scene.add_triangles(*shapes.cube())
    assert np.isinf(scene.cast_rays(rays)["t_hit"].numpy()[bad]).all()
    assert scene.count_intersections(rays).numpy()[bad].tolist() == [0, 0, 0]


def test_cast_rays_leaves_out_uvs_and_normals_and_writes_into_out():
    v, t, rays = padded_rays()
    scene = meshcast.RaycastingScene()
    scene.add_triangles(v, t)
    whole = scene.cast_rays(rays)
    bare = scene.cast_rays(rays, uvs=False, normals=False)
    assert sorted(bare) == ["geometry_ids", "primitive_ids", "t_hit"]
    for key in bare:
        assert np.array_equal(bare[key].numpy(), whole[key].numpy()), key
    assert sorted(scene.cast_rays(rays, normals=False)) == ["geometry_ids", "primitive_ids", "primitive_uvs", "t_hit"]
    out = {"t_hit": np.full(7, -1, np.float32), "primitive_normals": np.zeros((7, 3), np.float32)}
    written = scene.cast_rays(rays, out=out)
    assert np.shares_memory(written["t_hit"], out["t_hit"])
    assert np.array_equal(out["t_hit"], whole["t_hit"].numpy())
    assert np.array_equal(out["primitive_normals"], whole["primitive_normals"].numpy())
    occluded = np.zeros(7, bool)
    scene.test_occlusions(rays, out=occluded)
    assert occluded.tolist() == scene.test_occlusions(rays).numpy().tolist()
    with pytest.raises(ValueError, match=r"out\[\"t\"\]: the answer has no such array"):
        scene.cast_rays(rays, out={"t": np.zeros(7, np.float32)})
    with pytest.raises(ValueError, match=r"out\[\"t_hit\"\]: dtype float64"):
        scene.cast_rays(rays, out={"t_hit": np.zeros(7)})
    with pytest.raises(ValueError, match=r"out\[\"out\"\]: shape \(6,\)"):
        scene.test_occlusions(rays, out=np.zeros(6, bool))
    with pytest.raises(ValueError, match=r"backend \"cuda\": cpu or vulkan"):
        scene.cast_rays(rays, backend="cuda")


def holed_sphere(directions, half_angle_deg=20):
    """A sphere with a round hole wherever one of `directions` leaves it from
    its centre: the triangles whose centroids lie within half_angle of it."""
    v, t = shapes.sphere(rings=24, segments=40)
    centre = v.astype(np.float64).mean(axis=0)
    centroid = v[t].astype(np.float64).mean(axis=1) - centre
    centroid /= np.linalg.norm(centroid, axis=1, keepdims=True)
    near = (centroid @ np.asarray(directions, np.float64).T > np.cos(np.radians(half_angle_deg))).any(axis=1)
    return v, t[~near], centre


def test_winding_sign_is_right_where_parity_and_votes_fail():
    """A sphere with holes where the sign rays leave it: from points about
    its centre every ray escapes, so parity and a vote of three rays answer
    outside, while the winding number (about 0.9 there) answers inside, as
    the exact winding number does."""
    v, t, centre = holed_sphere(meshcast._SIGN_DIRECTIONS[:3])
    rng = np.random.default_rng(12)
    p = centre + rng.uniform(-0.05, 0.05, (50, 3))
    exact = winding_number(p, v, t)
    assert (exact > 0.8).all() and (exact < 0.95).all()
    scene = meshcast.RaycastingScene()
    scene.add_triangles(v, t)
    assert (scene.compute_occupancy(p).numpy() == 0).all()               # parity: wrong
    assert (scene.compute_occupancy(p, nsamples=3).numpy() == 0).all()   # three votes: wrong
    assert (scene.compute_occupancy(p, sign="winding").numpy() == 1).all()
    sd = scene.compute_signed_distance(p, sign="winding").numpy()
    assert (sd < 0).all() and np.array_equal(-sd, scene.compute_distance(p).numpy())
    with pytest.raises(ValueError, match=r"sign: 'votes' is neither"):
        scene.compute_occupancy(p, sign="votes")


def test_winding_sign_of_overlapping_and_open_meshes():
    """Two overlapping closed spheres (their common part has winding number
    2: two crossings there, parity says outside) and the holed sphere,
    wound both ways: sign="winding" is the exact winding number's on every
    point whose exact |w| is not within 1e-3 of 1/2."""
    sv, st = shapes.sphere()
    moved = sv + np.float32([0.8, 0, 0])
    both = (np.concatenate([sv, moved]), np.concatenate([st, st + len(sv)]))
    hv, ht, _ = holed_sphere(meshcast._SIGN_DIRECTIONS[:3])
    rng = np.random.default_rng(13)
    for name, (v, t) in {"overlapping": both, "holed": (hv, ht), "holed, inward": (hv, ht[:, ::-1].copy())}.items():
        lo, hi = v.min(0).astype(np.float64), v.max(0).astype(np.float64)
        p = lo - 0.2 * (hi - lo) + rng.uniform(0, 1.4, (600, 3)) * (hi - lo)
        exact = winding_number(p, v, t)
        clear = np.abs(np.abs(exact) - 0.5) > 1e-3
        scene = meshcast.RaycastingScene()
        scene.add_triangles(v, t)
        got = scene.compute_occupancy(p, sign="winding").numpy()
        assert np.array_equal(got[clear] == 1, (np.abs(exact) > 0.5)[clear]), name
        if name == "overlapping":
            common = np.abs(exact - 2) < 0.1
            assert common.sum() > 10 and (scene.compute_occupancy(p[common]).numpy() == 0).all()


def test_winding_number_within_its_bound():
    """compute_winding_number against the exact sum over the stored
    triangles (the exact layout stores the input's): within the bound it
    answers, and the bound small where the mesh is far."""
    v, t = shapes.sphere(rings=30, segments=50)
    v2, t2 = shapes.cube(lo=-0.4, hi=0.6)
    scene = meshcast.RaycastingScene()
    scene.add_triangles(v, t)
    scene.add_triangles(v2, t2)
    rng = np.random.default_rng(14)
    p = rng.uniform(-3, 5, (300, 3))
    got = scene.compute_winding_number(p)
    w, bound = got["winding_number"].numpy(), got["bound"].numpy()
    assert w.dtype == np.float64 and w.shape == (300,)
    exact = winding_number(p, v, t) + winding_number(p, v2, t2)
    # The scene stores the recommended layout: its corners within 2^-18 of
    # the mesh's extent of the input's, which moves w by little away from
    # the surface.
    far = (nearest(p, v, t)[0] > 0.05) & (nearest(p, v2, t2)[0] > 0.05)
    assert far.sum() > 200
    assert (np.abs(w - exact)[far] <= bound[far] + 1e-4).all()
    assert np.median(bound) < 0.05 and (bound >= 0).all()
    loose = scene.compute_winding_number(p, tolerance=0.3)
    assert (np.abs(loose["winding_number"].numpy() - exact)[far] <= loose["bound"].numpy()[far] + 1e-4).all()
    assert np.median(loose["bound"].numpy()) > np.median(bound)
    for bad in (0, 1, float("nan")):
        with pytest.raises(ValueError, match="tolerance"):
            scene.compute_winding_number(p, tolerance=bad)


def test_help_states_arguments_and_keys():
    """help() of the casts and of every RaycastingScene member names their
    arguments and what they answer; help(meshcast) stays a page a reader
    reads (the answers' Tensor, an ndarray, is left out of it)."""
    import inspect
    import pydoc
    text = pydoc.render_doc(meshcast, renderer=pydoc.plaintext)
    assert len(text.splitlines()) < 1200 and "class Tensor" not in text
    blob_doc = meshcast.Blob.cast.__doc__
    for word in ("origins", "t_min", "query", "cull", "max_hits", "out", "backend", "invalid", "\"t\"", "\"found\""):
        assert word in blob_doc, word
    for word in ("mask", "\"instance\"", "invalid"):
        assert word in meshcast.Scene.cast.__doc__, word
    for name, member in inspect.getmembers(meshcast.RaycastingScene, inspect.isfunction):
        if name.startswith("_"):
            continue
        doc = member.__doc__ or ""
        for parameter in inspect.signature(member).parameters:
            if parameter not in ("self", "args", "kwargs", "memo"):
                assert parameter in doc, f"{name}: {parameter}"
        assert "Tensor" in doc or "Returns" in doc or "rays" in doc, name


def hits_against_float64(answer, rays, v, t, delta):
    """The clean rays' t_hit against the oracle's within its tolerance for
    corners moved by `delta`, and each hit's uv against the float64 point
    on the triangle it names. Returns the largest t error in float32 ulps
    of t, and the largest uv error."""
    rays = np.asarray(rays, np.float64)
    got_t = answer["t_hit"].numpy().astype(np.float64)
    got_tri = answer["primitive_ids"].numpy().astype(np.int64)
    got_uv = answer["primitive_uvs"].numpy().astype(np.float64)
    truth = oracle.classify(oracle.brute_force(v, t, rays[:, :3], rays[:, 3:], delta=delta))
    want_t, _, tol, unique = truth.nearest()
    clean = truth.clean & unique & np.isfinite(want_t)
    assert clean.sum() > 0.5 * len(rays)
    error = np.abs(got_t[clean] - want_t[clean])
    assert np.all(error <= tol[clean]), f"{(error > tol[clean]).sum()} hits beyond the oracle's tolerance"
    ulps = (error / np.spacing(want_t[clean].astype(np.float32))).max()
    hit = got_tri != meshcast.RaycastingScene.INVALID_ID
    a, b, c = (v[t[got_tri[hit], k]].astype(np.float64) for k in range(3))
    p = rays[hit, :3] + got_t[hit, None] * rays[hit, 3:]
    # the point's barycentrics on its triangle's plane, in float64
    e1, e2, w = b - a, c - a, p - a
    d11, d12, d22 = (e1 * e1).sum(1), (e1 * e2).sum(1), (e2 * e2).sum(1)
    w1, w2 = (w * e1).sum(1), (w * e2).sum(1)
    det = d11 * d22 - d12 * d12
    uv = np.stack([(d22 * w1 - d12 * w2) / det, (d11 * w2 - d12 * w1) / det], axis=1)
    return ulps, np.abs(uv - got_uv[hit]).max()


def test_exact_by_default_and_compact_when_allowed():
    v, t = shapes.sphere(40, 60)
    origins, directions = shapes.rays(v, 3000, seed=11, inside_fraction=0.5)
    rays = np.concatenate([origins, directions], axis=1)
    diagonal = oracle.mesh_diagonal(v)

    # Exact: t within a few float32 ulps of the float64 hit (about 10
    # measured), where the compact cluster's moved corners take it tens of
    # thousands of ulps off at grazing angles.
    exact = meshcast.RaycastingScene()
    exact.add_triangles(v, t)
    ulps, uv_error = hits_against_float64(exact.cast_rays(rays), rays, v, t, 0.0)
    print("exact: t within", ulps, "ulps, uv within", uv_error)
    assert ulps <= 64 and uv_error < 1e-4

    # max_error lets the compact cluster in: its bound (below 4e-6 of the
    # diagonal) holds, and the answers leave float rounding.
    compact = meshcast.RaycastingScene(max_error=1e-5)
    compact.add_triangles(v, t)
    ulps, uv_error = hits_against_float64(compact.cast_rays(rays), rays, v, t, 4e-6 * diagonal)
    print("compact: t within", ulps, "ulps, uv within", uv_error)
    assert ulps > 1000
    d_exact = exact.compute_distance(v[:200]).numpy()
    assert np.all(d_exact <= 1e-6 * diagonal)  # the vertices themselves: on the mesh
    assert compact.compute_distance(v[:200]).numpy().max() > 0  # moved to the grid

    # A limit below the compact cluster's bound keeps every geometry exact.
    tight = meshcast.RaycastingScene(max_error=1e-7)
    tight.add_triangles(v, t)
    assert np.array_equal(tight.cast_rays(rays)["t_hit"].numpy(), exact.cast_rays(rays)["t_hit"].numpy())

    # A layout by name, and the refusals.
    named = meshcast.RaycastingScene(layout="OctTreeCompressed/ClusterBitPackSOA8")
    named.add_triangles(v, t)
    assert np.array_equal(named.cast_rays(rays)["t_hit"].numpy(), compact.cast_rays(rays)["t_hit"].numpy())
    with pytest.raises(ValueError, match="OctTreeCompressed/ClusterBitPackSOA8"):
        meshcast.RaycastingScene(layout="OctTreeCompressed/ClusterBitPack")
    for bad in (-1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="max_error"):
            meshcast.RaycastingScene(max_error=bad)
    over = meshcast.RaycastingScene(layout="OctTreeCompressed/ClusterBitPackSOA8", max_error=1e-7)
    with pytest.raises(ValueError, match="max_error"):
        over.add_triangles(v, t)
