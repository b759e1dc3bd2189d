// libFuzzer target: any bytes as a blob, through validation and, when they
// pass, the CPU walker and the decoder. The header's checksum is written
// over the input first, so mutations reach the structural checks instead of
// all stopping at the checksum; what this proves is that validation alone
// keeps every walker in bounds and finite on whatever passes it, and that
// the packet walk answers as the single-ray walk does.
#include <cmath>
#include <cstdint>
#include <vector>

#include "check/agreement.h"
#include "meshcast/mesh.h"
#include "meshcast/blob.h"
#include "fuzz/rays.h"
#include "layout/blob_format.h"

using namespace meshcast;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<uint8_t> blob(data, data + size);
  if (size >= MC_BLOB_HEADER_BYTES) layout::seal(blob);
  try {
    BlobView view(blob, "fuzz input");
    const layout::BlobHeader& h = layout::header_of(blob.data());
    std::vector<Ray> rays = fuzz::rays_through_box(h.bounds_min, h.bounds_max);
    std::vector<Hit> hits(rays.size());
    view.trace(rays, hits);
    if (!fuzz::hits_on_segments(rays, hits)) __builtin_trap();
    // The same rays from one origin, the box's centre: a batch the packet
    // walk takes (Packets::Auto), whose answers must be the single-ray
    // walk's, triangle and t, bit for bit.
    std::vector<Ray> centred = rays;
    for (Ray& r : centred)
      for (int a = 0; a < 3; ++a) {
        const float centre = 0.5f * h.bounds_min[a] + 0.5f * h.bounds_max[a];
        r.org[a] = std::isfinite(centre) ? centre : 0.0f;
      }
    std::vector<Hit> packets(centred.size()), single(centred.size());
    view.trace(centred, packets, HitOutputs::None, Query::Closest, Cull::None, Packets::Auto);
    view.trace(centred, single, HitOutputs::None, Query::Closest, Cull::None, Packets::Off);
    for (size_t i = 0; i < centred.size(); ++i)
      if (packets[i].triangle != single[i].triangle || !(packets[i].t == single[i].t || packets[i].triangle == MC_NO_HIT))
        __builtin_trap();
    // A hit names a triangle of the mesh, or without a remap a slot number.
    const uint32_t names = layout::has_remap(h) ? h.triangle_count : h.remap_slots;
    for (const Hit& hit : hits)
      if (hit.triangle != MC_NO_HIT && hit.triangle >= names) __builtin_trap();
    Mesh stored = stored_mesh(blob);
    if (stored.triangles.size() != names) __builtin_trap();
  } catch (const InputError&) {
  }
  return 0;
}
