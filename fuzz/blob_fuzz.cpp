// libFuzzer target: any bytes as a blob, through validation and, when they
// pass, the CPU walker and the decoder. The header's checksum is written
// over the input first, so mutations reach the structural checks instead of
// all stopping at the checksum; what this proves is that validation alone
// keeps every walker in bounds and finite on whatever passes it.
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
