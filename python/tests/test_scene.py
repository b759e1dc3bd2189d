"""Scenes of instances: transforms, masks, enabling, removal, facing, commits.

A unit cube [-1, 1]^3 (outward faces, exact corners, AABBTree/Float3) placed
by instances; rays straight down the z axis from z = 5 over x, y points inside
the instance's footprint, so every answer is known exactly: the entry at the
top face and the exit at the bottom face."""

import numpy as np
import pytest

import meshcast
import shapes
from cases import FLOAT3_LAYOUT, NO_HIT


@pytest.fixture(scope="module")
def cube_blob():
    v, f = shapes.cube()
    return meshcast.build(v, f, layout=FLOAT3_LAYOUT)


def down_rays(points, z=5.0, speed=1.0):
    o = np.array([[x, y, z] for x, y in points], dtype=np.float64)
    d = np.tile(np.array([0, 0, -speed], dtype=np.float32), (len(points), 1))
    return o, d


def footprint(cx, cy, hx, hy):
    """Nine x, y points inside an instance's footprint (centre cx, cy, half-widths
    hx, hy). Their local x and y differ in size on every instance used here
    (x and y swapped or mirrored included), so no ray meets the cube's faces'
    diagonals (x = y): each crossing is one triangle."""
    return [(cx + fx * hx, cy + fy * hy) for fx in (-0.75, -0.25, 0.5) for fy in (-0.375, 0.125, 0.625)]


def test_translation(cube_blob):
    s = meshcast.Scene()
    m = s.add_mesh(cube_blob)
    assert m == 0 and s.add_mesh(cube_blob) == 1
    assert s.add_instance(m, translation=(10.0, -4.0, 1.0)) == 0
    assert s.add_instance(m, translation=(-6.0, 3.0, -2.0)) == 1
    assert s.instance_count == 2
    s.commit()
    o, d = down_rays(footprint(10, -4, 1, 1) + footprint(-6, 3, 1, 1) + [(0.0, 0.0)])
    r = s.cast(o, d)
    np.testing.assert_array_equal(r["instance"], [0] * 9 + [1] * 9 + [NO_HIT])
    np.testing.assert_array_equal(r["t"], [5 - 2] * 9 + [5 - (-2 + 1)] * 9 + [np.inf])
    a = s.cast(o, d, query="all", uv=True)
    assert a["uv"].shape == (36, 2)
    np.testing.assert_array_equal(a["found"], [2] * 18 + [0])
    np.testing.assert_array_equal(a["t"], [3, 5] * 9 + [6, 8] * 9)
    np.testing.assert_array_equal(a["instance"], [0] * 18 + [1] * 18)
    # max_hits 1: every hit counted, the nearest kept.
    one = s.cast(o, d, query="all", max_hits=1)
    np.testing.assert_array_equal(one["found"], [2] * 18 + [0])
    np.testing.assert_array_equal(one["offsets"], list(range(19)) + [18])
    np.testing.assert_array_equal(one["t"], [3] * 9 + [6] * 9)


def test_rotation_scale_mirror_nonuniform(cube_blob):
    """world = rotation_scale @ local + translation. A non-uniform scale
    diag(2, 0.5, 3) makes the cube 4 x 1 x 6; a mirror diag(-1, 1, 1) keeps its
    shape; a quarter turn about z swaps x and y."""
    s = meshcast.Scene()
    m = s.add_mesh(cube_blob)
    s.add_instance(m, rotation_scale=np.diag([2.0, 0.5, 3.0]), translation=(0.0, 0.0, 0.0))
    s.add_instance(m, rotation_scale=np.diag([-1.0, 1.0, 1.0]), translation=(20.0, 0.0, 0.0))
    # world x = -2 local y, world y = local x: a quarter turn, local y stretched by 2.
    quarter = np.array([[0, -2, 0], [1, 0, 0], [0, 0, 1]], dtype=np.float64)
    s.add_instance(m, rotation_scale=quarter, translation=(-20.0, 0.0, 0.0))
    s.commit()
    o, d = down_rays(footprint(0, 0, 2, 0.5) + footprint(20, 0, 1, 1) + footprint(-20, 0, 2, 1)
                     + [(0.0, 0.75), (2.25, 0.0), (-20.0, 1.25), (-17.75, 0.0)])  # just outside the stretched ones
    r = s.cast(o, d, query="all")
    np.testing.assert_array_equal(r["found"], [2] * 27 + [0] * 4)
    # The ray goes to the mesh's frame through the inverse of rotation_scale:
    # t within a rounding of the exact value.
    np.testing.assert_allclose(r["t"], [2, 8] * 9 + [4, 6] * 9 + [4, 6] * 9, rtol=1e-6)
    np.testing.assert_array_equal(r["instance"], [0] * 18 + [1] * 18 + [2] * 18)


def test_mirror_keeps_facing(cube_blob):
    """Faces are decided in the mesh's own frame: a mirrored cube is not inside
    out. Rays from above meet its top face from outside (front) first, so
    cull="back" keeps the entry at t 4 and cull="front" the exit at t 6, as on
    the unmirrored cube."""
    for mirror in (np.diag([1.0, 1.0, 1.0]), np.diag([-1.0, 1.0, 1.0]), np.diag([1.0, -2.0, 1.0]),
                   np.diag([-1.0, -1.0, -1.0])):
        s = meshcast.Scene()
        s.add_instance(s.add_mesh(cube_blob), rotation_scale=mirror)
        s.commit()
        o, d = down_rays(footprint(0, 0, 1, 1))
        np.testing.assert_array_equal(s.cast(o, d, cull="back")["t"], 4.0, err_msg=f"{np.diag(mirror)}")
        np.testing.assert_array_equal(s.cast(o, d, cull="front")["t"], 6.0, err_msg=f"{np.diag(mirror)}")


def test_flip_facing(cube_blob):
    s = meshcast.Scene()
    i = s.add_instance(s.add_mesh(cube_blob), flip_facing=True)
    s.commit()
    o, d = down_rays(footprint(0, 0, 1, 1))
    np.testing.assert_array_equal(s.cast(o, d, cull="back")["t"], 6.0)
    np.testing.assert_array_equal(s.cast(o, d, cull="front")["t"], 4.0)
    np.testing.assert_array_equal(s.cast(o, d, query="any", cull="back")["t"], 6.0)
    s.set_flip_facing(i, False)
    s.commit()
    np.testing.assert_array_equal(s.cast(o, d, cull="back")["t"], 4.0)
    a = s.cast(o, d, cull="front", query="all")
    np.testing.assert_array_equal(a["found"], 1)
    np.testing.assert_array_equal(a["t"], 6.0)


def test_masks(cube_blob):
    s = meshcast.Scene()
    m = s.add_mesh(cube_blob)
    s.add_instance(m, translation=(0.0, 0.0, 0.0), mask=0x01)
    s.add_instance(m, translation=(0.0, 0.0, -4.0), mask=0x06)
    s.commit()
    o, d = down_rays(footprint(0, 0, 1, 1))
    for ray_mask, nearest, count in ((0xFF, 0, 4), (0x01, 0, 2), (0x02, 1, 2), (0x04, 1, 2), (0x08, None, 0),
                                     (0x05, 0, 4)):
        r = s.cast(o, d, mask=ray_mask)
        np.testing.assert_array_equal(r["instance"], NO_HIT if nearest is None else nearest, err_msg=hex(ray_mask))
        np.testing.assert_array_equal(s.cast(o, d, mask=ray_mask, query="all")["found"], count, err_msg=hex(ray_mask))
    s.set_mask(0, 0x08)
    s.commit()
    np.testing.assert_array_equal(s.cast(o, d, mask=0x08)["instance"], 0)
    np.testing.assert_array_equal(s.cast(o, d, mask=0x01)["instance"], NO_HIT)


def test_enable_remove_and_commit(cube_blob):
    s = meshcast.Scene()
    m = s.add_mesh(cube_blob)
    a = s.add_instance(m, translation=(0.0, 0.0, 0.0))
    b = s.add_instance(m, translation=(0.0, 0.0, -4.0))
    o, d = down_rays(footprint(0, 0, 1, 1))
    s.commit()
    np.testing.assert_array_equal(s.cast(o, d)["instance"], a)

    # Edits are seen after the next commit only.
    s.set_enabled(a, False)
    np.testing.assert_array_equal(s.cast(o, d)["instance"], a)
    s.commit()
    r = s.cast(o, d)
    np.testing.assert_array_equal(r["instance"], b)
    np.testing.assert_array_equal(r["t"], 8.0)
    s.set_enabled(a, True)
    s.commit()
    np.testing.assert_array_equal(s.cast(o, d)["instance"], a)

    s.set_transform(a, translation=(0.0, 0.0, -8.0))
    np.testing.assert_array_equal(s.cast(o, d)["t"], 4.0)
    s.commit()
    r = s.cast(o, d)
    np.testing.assert_array_equal(r["instance"], b)
    np.testing.assert_array_equal(s.cast(o, d, query="all")["found"], 4)
    s.set_transform(a, rotation_scale=np.diag([1.0, 1.0, 4.0]), translation=(0.0, 0.0, -8.0))  # z in [-12, -4]
    s.commit()
    np.testing.assert_array_equal(s.cast(o, d, query="all")["t"].reshape(-1, 4), np.tile([8, 9, 10, 17], (9, 1)))

    c = s.add_instance(m, translation=(0.0, 0.0, 2.5))  # not yet committed
    np.testing.assert_array_equal(s.cast(o, d)["instance"], b)
    s.commit()
    np.testing.assert_array_equal(s.cast(o, d)["instance"], c)
    assert s.instance_count == 3

    s.remove_instance(c)
    np.testing.assert_array_equal(s.cast(o, d)["instance"], c)  # still the last commit
    s.commit()
    r = s.cast(o, d)
    np.testing.assert_array_equal(r["instance"], b)  # the other ids unchanged
    np.testing.assert_array_equal(r["t"], 8.0)
    assert s.instance_count == 2


def test_empty_scene_misses(cube_blob):
    s = meshcast.Scene()
    s.add_mesh(cube_blob)
    s.commit()
    o, d = down_rays(footprint(0, 0, 1, 1))
    r = s.cast(o, d)
    np.testing.assert_array_equal(r["triangle"], NO_HIT)
    assert np.all(np.isinf(r["t"]))


def test_scene_t_in_direction_units(cube_blob):
    """t is in units of the direction: twice as long, half the t."""
    s = meshcast.Scene()
    s.add_instance(s.add_mesh(cube_blob), rotation_scale=np.diag([1.0, 1.0, 2.0]))
    s.commit()
    o, d = down_rays(footprint(0, 0, 1, 1), speed=2.0)
    np.testing.assert_array_equal(s.cast(o, d)["t"], 1.5)
    np.testing.assert_array_equal(s.cast(o, d, t_min=1.75)["t"], 3.5)
    np.testing.assert_array_equal(s.cast(o, d, t_max=1.25)["triangle"], NO_HIT)


def test_scene_uv_and_triangle(cube_blob):
    """The triangle is the mesh's own number and uv names the hit point in it."""
    v, f = shapes.cube()
    s = meshcast.Scene()
    s.add_instance(s.add_mesh(cube_blob), rotation_scale=np.diag([-1.0, 1.0, 1.0]), translation=(3.0, 0.0, 0.0))
    s.commit()
    pts = footprint(3, 0, 1, 1)
    o, d = down_rays(pts)
    r = s.cast(o, d, uv=True)
    for k, (x, y) in enumerate(pts):
        tri = f[r["triangle"][k]].astype(np.int64)
        a, b, c = (v[tri].astype(np.float64) * [-1, 1, 1]) + [3, 0, 0]
        u, w = r["uv"][k].astype(np.float64)
        p = (1 - u - w) * a + u * b + w * c
        np.testing.assert_allclose(p, [x, y, 1.0], atol=1e-6)


def test_scene_keeps_its_blobs(tmp_path):
    """A scene keeps the blobs it was given: the Python objects dropped and a
    loaded blob's file removed, it still casts."""
    import gc
    import os
    v, f = shapes.cube()
    path = tmp_path / "cube.mcb"
    meshcast.build(v, f, layout=FLOAT3_LAYOUT).save(str(path))
    s = meshcast.Scene()
    s.add_instance(s.add_mesh(meshcast.load(str(path))), translation=(0.0, 0.0, 0.0))
    s.add_instance(s.add_mesh(meshcast.build(v, f, layout=FLOAT3_LAYOUT)), translation=(0.0, 0.0, -4.0))
    s.commit()
    gc.collect()
    os.remove(path)
    o, d = down_rays(footprint(0, 0, 1, 1))
    r = s.cast(o, d, query="all")
    np.testing.assert_array_equal(r["found"], 4)
    np.testing.assert_array_equal(r["t"].reshape(-1, 4), np.tile([4, 6, 8, 10], (9, 1)))


def test_ids_of_another_scene_are_refused(cube_blob):
    """An id is an int that remembers its scene: another scene refuses it by
    name though its index is one that scene gave too; a plain int (or numpy's,
    as casts answer) is an index of the scene it is given to."""
    s, other = meshcast.Scene(), meshcast.Scene()
    m, their_m = s.add_mesh(cube_blob), other.add_mesh(cube_blob)
    a = s.add_instance(m, translation=(0.0, 0.0, 0.0))
    theirs = other.add_instance(their_m)
    assert (a, m) == (theirs, their_m) == (0, 0)
    assert isinstance(a, meshcast.InstanceId) and isinstance(m, meshcast.MeshId)
    assert a.scene != theirs.scene
    for edit in (lambda: s.add_instance(their_m), lambda: s.set_transform(theirs, translation=(1.0, 0.0, 0.0)),
                 lambda: s.set_mask(theirs, 0), lambda: s.set_flip_facing(theirs, True),
                 lambda: s.set_enabled(theirs, False), lambda: s.remove_instance(theirs)):
        with pytest.raises(ValueError, match="was given by another scene"):
            edit()
    with pytest.raises(TypeError, match="an int"):
        s.set_mask(True, 1)
    with pytest.raises(ValueError, match="unknown"):
        s.set_mask(-1, 1)
    with pytest.raises(ValueError, match="unknown"):
        s.set_mask(2 ** 40, 1)
    s.commit()
    o, d = down_rays(footprint(0, 0, 1, 1))
    r = s.cast(o, d)
    np.testing.assert_array_equal(r["instance"], a)  # nothing refused changed the scene
    s.set_mask(r["instance"][0], 0x02)  # an index as casts answer it
    s.set_enabled(0, False)
    s.commit()
    np.testing.assert_array_equal(s.cast(o, d)["instance"], NO_HIT)
    assert repr(a).startswith("InstanceId(0, scene=")
