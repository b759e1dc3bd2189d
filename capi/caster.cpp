// The C API's casters: batches submitted (or written in place), polled
// and collected, on the CPU's workers or the GPU (meshcast/meshcast_c.h).
#include <memory>
#include <mutex>
#include <span>
#include <string>

#include "capi/casts.h"
#include "capi/handles.h"
#include "capi/status.h"

using namespace meshcast;
using namespace meshcast::capi;

namespace {

constexpr size_t kCasterOptionsV1 = sizeof(meshcast_caster_options);

meshcast_caster_options caster_defaults() {
  meshcast_caster_options o{};
  o.struct_size = sizeof o;
  o.backend = MESHCAST_BACKEND_AUTOMATIC;
  o.frames = 4;
  return o;
}

host::Ticket ticket_of(const meshcast_ticket* t) {
  required(t, "ticket");
  return {t->id, t->slot, t->caster};
}

meshcast_ticket c_ticket(const host::Ticket& t) { return {t.id, t.caster, t.slot, 0}; }

host::BatchQuery batch_query(const meshcast_query* query) {
  const CastQuery q = cast_query(query);
  host::BatchQuery b;
  b.query = q.query, b.cull = q.cull;
  return b;
}

void record_to(const host::BatchRecord& r, meshcast_batch_record* out) {
  if (!out) return;
  out->ran_on = r.ran_on == host::Backend::Vulkan ? MESHCAST_BACKEND_VULKAN : MESHCAST_BACKEND_CPU;
  out->rays = r.rays;
  out->latency_ms = r.latency_ms, out->device_ms = r.device_ms, out->cpu_ms = r.cpu_ms;
}

thread_local std::string why_text;

}  // namespace

extern "C" {

void meshcast_caster_options_init(meshcast_caster_options* options) {
  if (options) *options = caster_defaults();
}

meshcast_status meshcast_caster_create(const meshcast_blob* blob, const meshcast_caster_options* options,
                                       meshcast_caster** out) {
  return guarded("meshcast_caster_create", [&] {
    *required(out, "out") = nullptr;
    const meshcast_caster_options o = sized(options, caster_defaults(), kCasterOptionsV1, "options");
    host::CasterOptions c;
    if (o.backend > MESHCAST_BACKEND_AUTOMATIC)
      throw UsageError("options->backend " + std::to_string(o.backend) + ": MESHCAST_BACKEND_CPU, _VULKAN or _AUTOMATIC (0, 1, 2)");
    c.backend = o.backend == MESHCAST_BACKEND_CPU      ? host::Backend::Cpu
                : o.backend == MESHCAST_BACKEND_VULKAN ? host::Backend::Vulkan
                                                       : host::Backend::Automatic;
    c.frames = o.frames, c.threads = o.threads;
    if (o.outputs & ~(MESHCAST_HIT_UV | MESHCAST_HIT_POINT))
      throw UsageError("options->outputs " + std::to_string(o.outputs) + ": MESHCAST_HIT_UV and MESHCAST_HIT_POINT alone");
    c.hit_outputs = HitOutputs(o.outputs);
    auto made = std::make_unique<meshcast_caster>();
    if (blob) {
      const auto b = live(blob, "blob");
      made->blob_owner = b->owner;
      made->caster = std::make_unique<host::Caster>(b->view.bytes(), b->name, c);
    } else {
      made->caster = std::make_unique<host::Caster>(c);
    }
    hand_out(std::move(made), out);
  });
}

meshcast_status meshcast_caster_submit(meshcast_caster* caster, const meshcast_ray* rays, uint64_t ray_count,
                                       const meshcast_query* query, meshcast_ticket* ticket) {
  return guarded("meshcast_caster_submit", [&] {
    const auto c = live(caster, "caster");
    meshcast_ticket* out = required(ticket, "ticket");
    *out = c_ticket(c->caster->submit(rays_of(array(rays, ray_count, "rays"), ray_count), batch_query(query)));
  });
}

meshcast_status meshcast_caster_open(meshcast_caster* caster, uint32_t ray_count, const meshcast_query* query,
                                     meshcast_open_batch* batch) {
  return guarded("meshcast_caster_open", [&] {
    const auto c = live(caster, "caster");
    meshcast_open_batch* out = required(batch, "batch");
    const host::OpenBatch open = c->caster->open(ray_count, batch_query(query));
    out->ticket = c_ticket(open.ticket);
    out->rays = reinterpret_cast<meshcast_ray*>(open.rays.data());
    out->ray_count = open.rays.size();
  });
}

meshcast_status meshcast_caster_submit_open(meshcast_caster* caster, const meshcast_open_batch* batch, uint64_t written,
                                            meshcast_ticket* ticket) {
  return guarded("meshcast_caster_submit_open", [&] {
    const auto c = live(caster, "caster");
    const meshcast_open_batch& b = *required(batch, "batch");
    meshcast_ticket* out = required(ticket, "ticket");
    if (written > b.ray_count)
      throw UsageError("written " + std::to_string(written) + " is more than the " + std::to_string(b.ray_count) +
                       " rays the batch was opened for");
    host::OpenBatch open{ticket_of(&b.ticket), {reinterpret_cast<Ray*>(b.rays), size_t(written)}};
    *out = c_ticket(c->caster->submit(open));
  });
}

meshcast_status meshcast_caster_submit_scene(meshcast_caster* caster, const meshcast_scene* scene,
                                             const meshcast_ray_d* rays, uint64_t ray_count, const meshcast_query* query,
                                             meshcast_ticket* ticket) {
  return guarded("meshcast_caster_submit_scene", [&] {
    const auto c = live(caster, "caster");
    const auto s = live(scene, "scene");
    meshcast_ticket* out = required(ticket, "ticket");
    const CastQuery q = cast_query(query);
    host::SceneBatchQuery b;
    b.query = q.query, b.cull = q.cull, b.mask = q.mask;
    const host::Ticket t = c->caster->submit(s->scene, rays_of(array(rays, ray_count, "rays"), ray_count), b);
    // The batch walks the scene's commit until it is collected: the bytes
    // the scene references stay alive that long, released scene or not.
    std::lock_guard<std::mutex> lock(c->held_lock);
    c->held[t.id] = s->owners;
    *out = c_ticket(t);
  });
}

meshcast_status meshcast_caster_poll(meshcast_caster* caster, const meshcast_ticket* ticket, uint32_t* ready) {
  return guarded("meshcast_caster_poll", [&] {
    const auto c = live(caster, "caster");
    uint32_t* out = required(ready, "ready");
    *out = c->caster->poll(ticket_of(ticket)) ? 1 : 0;
  });
}

meshcast_status meshcast_caster_wait(meshcast_caster* caster, const meshcast_ticket* ticket, meshcast_hit* hits,
                                     uint64_t hit_capacity, meshcast_batch_record* record) {
  return guarded("meshcast_caster_wait", [&] {
    const auto c = live(caster, "caster");
    const host::Ticket t = ticket_of(ticket);
    record_to(c->caster->wait(t, hits_of(array(hits, hit_capacity, "hits"), hit_capacity)), record);
  });
}

meshcast_status meshcast_caster_wait_scene(meshcast_caster* caster, const meshcast_ticket* ticket,
                                           meshcast_scene_hit* hits, uint64_t hit_capacity,
                                           meshcast_batch_record* record) {
  return guarded("meshcast_caster_wait_scene", [&] {
    const auto c = live(caster, "caster");
    const host::Ticket t = ticket_of(ticket);
    record_to(c->caster->wait(t, hits_of(array(hits, hit_capacity, "hits"), hit_capacity)), record);
    std::lock_guard<std::mutex> lock(c->held_lock);
    c->held.erase(t.id);
  });
}

meshcast_status meshcast_caster_backend(meshcast_caster* caster, uint32_t ray_count, uint32_t* backend, const char** why) {
  return guarded("meshcast_caster_backend", [&] {
    const auto c = live(caster, "caster");
    const host::Backend b = c->caster->choose(ray_count);
    if (backend) *backend = b == host::Backend::Vulkan ? MESHCAST_BACKEND_VULKAN : MESHCAST_BACKEND_CPU;
    if (why) {
      why_text = c_api_words(c->caster->why(ray_count));
      *why = why_text.c_str();
    }
  });
}

meshcast_status meshcast_caster_release(meshcast_caster* caster) {
  return guarded("meshcast_caster_release", [&] { release(caster, "caster"); });
}

}  // extern "C"
