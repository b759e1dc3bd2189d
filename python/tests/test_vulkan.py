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


@pytest.mark.parametrize("layout", [DEFAULT_LAYOUT, FLOAT3_LAYOUT])
@pytest.mark.parametrize("query", ["closest", "any"])
def test_vulkan_equals_cpu(problem, layout, query):
    v, f, o, d = problem
    b = meshcast.build(v, f, layout=layout)
    t_max = np.where(np.arange(len(o)) % 3 == 0, 2.0, np.inf).astype(np.float32)
    cpu = b.cast(o, d, t_max=t_max, query=query)
    gpu = vulkan_cast(b, o, d, t_max=t_max, query=query)
    assert gpu["t"].dtype == np.float32 and gpu["triangle"].dtype == np.uint32
    if query == "closest":
        np.testing.assert_array_equal(gpu["triangle"], cpu["triangle"])
        np.testing.assert_allclose(gpu["t"], cpu["t"], rtol=1e-6)
    else:
        # Any hit: hit or miss agree (which triangle is the walk's).
        np.testing.assert_array_equal(gpu["triangle"] == meshcast.NO_HIT, cpu["triangle"] == meshcast.NO_HIT)


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
