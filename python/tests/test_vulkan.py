"""backend="vulkan" answers what the CPU answers (here on Mesa's lavapipe)."""

import numpy as np
import pytest

import meshcast
import shapes
from cases import DEFAULT_LAYOUT, FLOAT3_LAYOUT

pytestmark = pytest.mark.skipif(not meshcast.features.get("vulkan"), reason="meshcast built without Vulkan")

_probe = {}


def vulkan_cast(b, *args, **kwargs):
    """b.cast on Vulkan; skips the test when the machine has no Vulkan device."""
    try:
        return b.cast(*args, backend="vulkan", **kwargs)
    except RuntimeError as e:
        if "device" in str(e).lower() or "vulkan" in str(e).lower():
            pytest.skip(f"no Vulkan device: {e}")
        raise


@pytest.fixture(scope="module")
def problem():
    v, f = shapes.sphere(rings=14, segments=22)
    pv, pf = shapes.soup(n=200, seed=6)
    v = np.concatenate([v, pv])
    f = np.concatenate([f, pf + len(v) - len(pv)]).astype(np.uint32)
    o, d = shapes.rays(v, 2000, seed=33)
    return v, f, o, d


@pytest.mark.parametrize("cull", ["none", "back", "front"])
@pytest.mark.parametrize("layout", [DEFAULT_LAYOUT, FLOAT3_LAYOUT])
@pytest.mark.parametrize("query", ["closest", "any", "all"])
def test_vulkan_equals_cpu(problem, layout, query, cull):
    v, f, o, d = problem
    b = meshcast.build(v, f, layout=layout)
    n = len(o)
    t_max = np.where(np.arange(n) % 3 == 0, 2.0, np.inf).astype(np.float32)
    t_min = np.where(np.arange(n) % 4 == 1, 0.25, 0.0).astype(np.float32)
    kw = dict(t_min=t_min, t_max=t_max, query=query, cull=cull)
    cpu = b.cast(o, d, **kw)
    gpu = vulkan_cast(b, o, d, **kw)
    assert set(gpu) == set(cpu)
    for key in cpu:
        assert gpu[key].dtype == cpu[key].dtype and gpu[key].shape == cpu[key].shape, key
    if query == "closest":
        np.testing.assert_array_equal(gpu["triangle"], cpu["triangle"])
        np.testing.assert_allclose(gpu["t"], cpu["t"], rtol=1e-6)
    elif query == "any":
        # Hit or miss agree; which triangle is the walk's (any one on the ray).
        np.testing.assert_array_equal(gpu["triangle"] == meshcast.NO_HIT, cpu["triangle"] == meshcast.NO_HIT)
    else:
        np.testing.assert_array_equal(gpu["found"], cpu["found"])
        np.testing.assert_array_equal(gpu["offsets"], cpu["offsets"])
        np.testing.assert_allclose(gpu["t"], cpu["t"], rtol=1e-6)
        ray = np.repeat(np.arange(n), np.diff(cpu["offsets"]))
        # The same triangles a ray (the order of equal t's is free).
        key_cpu = np.lexsort((cpu["triangle"], ray))
        key_gpu = np.lexsort((gpu["triangle"], ray))
        np.testing.assert_array_equal(gpu["triangle"][key_gpu], cpu["triangle"][key_cpu])


def test_vulkan_out_and_uv(problem):
    v, f, o, d = problem
    b = meshcast.build(v, f)
    n = len(o)
    out = {"t": np.empty(n, np.float32), "triangle": np.empty(n, np.uint32), "uv": np.empty((n, 2), np.float32)}
    r = vulkan_cast(b, o, d, uv=True, out=out)
    assert r["t"] is out["t"]
    cpu = b.cast(o, d, uv=True)
    np.testing.assert_array_equal(r["triangle"], cpu["triangle"])
    np.testing.assert_allclose(r["uv"], cpu["uv"], atol=1e-5)


def test_raycasting_scene_on_vulkan_equals_cpu(problem):
    """RaycastingScene's backend="vulkan": the scene's geometries on the GPU,
    the same answers as on the CPU (a padded ray a miss on both)."""
    v, f, o, d = problem
    scene = meshcast.RaycastingScene()
    scene.add_triangles(v, f)
    rays = np.concatenate([o, d], axis=1).astype(np.float32)
    rays[7, 4] = np.nan
    for geometries in (1, 2):
        if geometries == 2:
            scene.add_triangles(*shapes.grid(8, 8, z=0.5, scale=0.5))
        cpu = scene.cast_rays(rays)
        try:
            gpu = scene.cast_rays(rays, backend="vulkan")
        except RuntimeError as e:
            pytest.skip(f"no Vulkan device: {e}")
        assert sorted(gpu) == sorted(cpu)
        for key in cpu:
            assert np.array_equal(gpu[key].numpy(), cpu[key].numpy()), key
        assert np.isinf(gpu["t_hit"].numpy()[7])
        tfar = np.linspace(0.1, 5, len(rays)).astype(np.float32)
        assert np.array_equal(scene.test_occlusions(rays, tfar=tfar, backend="vulkan").numpy(),
                              scene.test_occlusions(rays, tfar=tfar).numpy())
