// The API a game calls: ray batches submitted during one frame
// and collected in a later one, from the CPU or the GPU, with the latency of
// each batch measured, and answers right away for the few rays that cannot
// wait.
//
//   Caster caster(blob, "level", {});           // automatic backend
//   Ticket t = caster.submit(rays);             // returns at once
//   ... a frame later ...
//   caster.wait(t, hits);                       // or poll(t) first
//   caster.trace_now(one_ray, one_hit);         // synchronous, this thread
//   Ticket s = caster.submit(rays, {Query::Any});     // per batch: any hit,
//   Ticket a = caster.submit(rays, {Query::All, Cull::Back, 8});  // every hit
//   caster.wait(a, lists);                      // HitLists for Query::All
//
// Scenes (meshcast/scene.h): a batch of world rays against the scene as it
// was committed when the batch was submitted (the batch holds that
// snapshot), while the game moves, hides and adds instances and commits the
// next frames. The CPU's workers walk it, or with Backend::Vulkan the GPU
// (closest or any hit of meshes in the recommended layout,
// OctTreeCompressed/ClusterBitPackSOA8, or the exact
// OctTreeCompressed/ClusterFloat3SOA8: gpu/scene.h), one scene batch on
// the device at a time, begun in submission order by the caster's GPU
// thread; Query::All, other layouts, a refused batch and a lost device
// are the CPU's (BatchRecord::ran_on says which answered). The Automatic
// backend sends scene batches to the CPU (its crossover is the blob's).
// The snapshot a batch holds holds the scene's meshes: a MappedBlob the
// scene shares stays mapped until the batch is collected, even when the
// scene is gone, and with Backend::Vulkan until the caster's GPU has taken
// another scene's meshes or the caster is destroyed (the device keeps the
// meshes it last uploaded); bytes the scene only references
// (Scene::add_mesh of a BlobView) must outlive the batch.
//
//   Caster scenes({});                          // no blob: scene batches alone
//   Ticket f = scenes.submit(scene, world_rays, {Query::Closest, Cull::None, 0xFF});
//   scene.set_transform(a, moved); scene.commit();  // the batch still sees the last frame
//   scenes.wait(f, scene_hits);                 // or a SceneHitLists for Query::All
//
// A caster owns a ring of `frames` slots; each submitted (or open()) batch
// holds one until it is collected with wait(). Slot buffers (rays, hits, the GPU's
// mapped buffers, the recorded command buffers) are reused, so after the
// first batches of a size nothing is allocated per frame. Every method may
// be called from several threads at once; the blob is only ever read.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "meshcast/jobs.h"
#include "meshcast/ray.h"
#include "meshcast/scene.h"

namespace meshcast::host {

enum class Backend { Cpu, Vulkan, Automatic };
const char* backend_name(Backend b);

// A batch's receipt. `caster` names the caster that issued it, a number no
// other caster of the process ever has (not its address, which a later
// caster may be given): every caster numbers its batches from 1, and
// another caster's ticket is refused with UsageError, never taken for one
// of its own.
struct Ticket {
  uint64_t id = 0;
  uint32_t slot = 0;
  uint64_t caster = 0;
};

// A batch open() gave: its ticket, and where its rays go. The span holds
// whatever the slot held before (an earlier batch's rays) until the caller
// writes it. To send fewer rays than were opened, narrow it to the ones
// written (`batch.rays = batch.rays.first(k)`): submit(batch) starts the
// span's rays alone.
struct OpenBatch {
  Ticket ticket;
  std::span<Ray> rays;
};

// The question a batch asks (ray.h): the query, the faces culled, and for
// Query::All the hits a ray's row keeps (1..kMaxHitsLimit). The CPU walks
// any of them; the GPU makes a method for each combination on its first
// batch (the blob's device copy shared), an extra moment on that batch. A
// Query::All batch with HitOutputs::Uv is the CPU's (the GPU's rows carry
// no u, v).
struct BatchQuery {
  Query query = Query::Closest;
  Cull cull = Cull::None;
  uint32_t max_hits = 16;
  // The CPU's packets for rays of one origin (ray.h; the same answers); the
  // GPU walks every ray alone.
  Packets packets = Packets::Auto;
};

// A scene batch's question: BatchQuery's, and the rays' mask (an instance
// is walked when its mask shares a bit with it).
struct SceneBatchQuery {
  Query query = Query::Closest;
  Cull cull = Cull::None;
  uint8_t mask = 0xFF;
  uint32_t max_hits = 16;
};

// What one batch cost. latency: submit() to the moment the hits were ready
// (for the GPU, the fence; for the CPU, the last job's end). device: the
// GPU's own time between its timestamps. cpu: the CPU time the batch took,
// the workers' summed time for a CPU batch, the submission for a GPU batch
// (the rays are read by the device as written: no packing).
struct BatchRecord {
  Backend ran_on = Backend::Cpu;
  uint32_t rays = 0;
  double latency_ms = 0, device_ms = 0, cpu_ms = 0;
};

struct Percentiles {
  size_t batches = 0;
  double p50_ms = 0, p99_ms = 0, rays_per_second = 0;
};

// An engine's own Vulkan objects, for a Vulkan backend that makes no instance
// or device of its own: the handles as the engine holds them (VkInstance,
// VkPhysicalDevice, VkDevice, VkQueue, PFN_vkGetInstanceProcAddr), cast to
// void* so this header needs no Vulkan. What meshcast needs of them:
//   - an instance created with VkApplicationInfo::apiVersion 1.2 or later,
//     stated in instance_api_version (Vulkan cannot be asked for it), and a
//     physical device whose VkPhysicalDeviceProperties::apiVersion is 1.2 or
//     later: the shaders are SPIR-V for Vulkan 1.2;
//   - a device created with shaderInt64 and shaderFloat64 (every method),
//     and shaderBufferInt64Atomics (VkPhysicalDeviceVulkan12Features or
//     VkPhysicalDeviceShaderAtomicInt64Features) for the bruteforce and
//     aabblist methods alone, stated in enabled_features: the
//     VkPhysicalDeviceFeatures2 the engine chained to VkDeviceCreateInfo
//     (read while the caster is made; Vulkan cannot be asked which features
//     a device enabled);
//   - no instance or device extension, and no layer;
//   - `queue` of `queue_family`, a family that offers compute (timestamps,
//     where it has them, give BatchRecord::device_ms), on which the engine
//     submits nothing at all while the caster lives (the caster submits
//     from threads of its own too: the Automatic backend's measurement, and
//     scene batches); and host-visible coherent memory for storage buffers.
// The caster checks them as it is made, and throws UsageError naming the
// version or feature that is missing or not stated, rather than leaving
// the GPU: an engine that hands its device over wants it used. A device
// without shaderBufferInt64Atomics is taken, and a blob whose layout only
// the bruteforce or aabblist method reads leaves the CPU answering, with
// gpu_error() naming the feature and the method. Everything must outlive
// the caster, which destroys none of it. get_instance_proc_addr: null for
// the loader's.
struct VulkanObjects {
  void* instance = nullptr;
  void* physical_device = nullptr;
  void* device = nullptr;
  void* queue = nullptr;
  uint32_t queue_family = 0;
  void* get_instance_proc_addr = nullptr;
  uint32_t instance_api_version = 0;      // VkApplicationInfo::apiVersion of `instance` (VK_API_VERSION_1_2 or later)
  const void* enabled_features = nullptr;  // const VkPhysicalDeviceFeatures2*: the device's, as created
};

// The Vulkan instances meshcast has made in this process so far, and how
// many of them still exist (an engine's own are never counted). A caster
// that will not use the GPU makes none: Backend::Cpu, and a caster of scene
// batches alone on Automatic. The Automatic backend takes no CPU-type
// (software) device by itself: where that is all there is, it makes an
// instance to look, destroys it at once, and measures nothing; the CPU
// answers and gpu_error() says why. Naming such a device
// (CasterOptions::device, $MESHCAST_VK_DEVICE), or Backend::Vulkan, takes it.
struct VulkanInstances {
  uint64_t created = 0, alive = 0;
};
VulkanInstances vulkan_instances();

// The most frames and worker threads a caster takes: each frame holds
// buffers, and on the GPU a fence and a command buffer, for as long as the
// caster lives; more than these is a mistake, not a need.
constexpr uint32_t kMaxCasterFrames = 1024;
constexpr uint32_t kMaxCasterThreads = 1024;

// The caster refuses an option out of range (UsageError naming it and its
// range) rather than bending it: a backend outside the enum, frames outside
// 1..kMaxCasterFrames, threads beyond kMaxCasterThreads, hit_outputs with
// bits other than HitOutputs::Uv and HitOutputs::Point, a job system whose
// threads() is 0, `validation` or `device` together with an engine's device
// (the engine made its instance and chose its device: its own layers
// validate meshcast's calls on it).
struct CasterOptions {
  Backend backend = Backend::Automatic;
  uint32_t frames = 4;          // batches in flight at most (1..kMaxCasterFrames)
  uint32_t threads = 0;         // CPU workers (0: every core), unless `jobs` is given
  JobSystem* jobs = nullptr;    // an engine's job system (not owned) instead of meshcast's pool
  // The Vulkan device: an index or a case-insensitive part of its name,
  // taken whatever its type; "" for $MESHCAST_VK_DEVICE, else the first
  // discrete GPU, else the first integrated one, else the first device;
  // on Automatic the first that is not CPU-type (software), or none.
  std::string device;
  VulkanObjects engine_vulkan;  // the engine's device instead (its `device` set); `device` and `validation` must be unset
  std::string gpu_method;       // "" : the one that reads the blob's layout
  bool validation = false;      // Vulkan validation layers on meshcast's own instance
  HitOutputs hit_outputs = HitOutputs::None;  // what each hit carries besides t and the triangle, either backend
  // A file with a saved crossover (the Automatic backend): read when it
  // holds one for this device and blob, else measured and written to it.
  // A file that is not a usable profile (not one, damaged, another
  // device's) is measured over, and why() says why; it is written over
  // only when it is a meshcast profile, so a path named by mistake is
  // left as it is. A profile that cannot be written leaves the crossover
  // measured and why() saying so.
  std::string profile;
  // Test hook: called before every GPU submission (on the submitting
  // thread: the caller's, or the caster's GPU thread for scene batches);
  // throwing GpuError there refuses the batch, or with `lost` set acts as
  // a lost device.
  std::function<void()> before_gpu_submit;
};

class Caster {
 public:
  // Validates the blob as BlobView does (InputError naming `name`; the
  // bytes 4-byte aligned); the caster reads the caller's bytes, which must
  // outlive it. UsageError for an option out of range (CasterOptions).
  // With Backend::Vulkan or Automatic, a device that is missing or fails
  // leaves the caster on the CPU, and gpu_error() says why; an engine's
  // device that lacks what VulkanObjects lists is UsageError naming it.
  Caster(std::span<const uint8_t> blob, const std::string& name, CasterOptions options = {});
  // A caster of scene batches alone: no blob; the CPU's workers, or with
  // Backend::Vulkan the GPU as above (a missing device leaves the CPU and
  // gpu_error() says why). Its blob calls throw UsageError.
  explicit Caster(CasterOptions options);
  // Waits for the batches still running (their jobs and fences), so none
  // outlives the caster. A thread blocked in wait() or wait_for_crossover()
  // when destruction begins gets UsageError (its batch is not collected),
  // unless its batch was ready before it woke (then it collects as usual);
  // the destructor waits for it to leave either way. No other call may overlap
  // the destructor (a submit() that does gets UsageError at best).
  ~Caster();
  Caster(const Caster&) = delete;
  Caster& operator=(const Caster&) = delete;

  // Copies the rays and starts the batch; returns at once (a GPU batch's
  // rays are copied once, into the device's mapped memory). Throws
  // UsageError when all `frames` slots hold uncollected batches, for a
  // query out of range, or for a batch whose copy of the rays and room for
  // their hits the machine's memory cannot hold (naming the rays and the
  // bytes); what an engine's JobSystem::run() throws, as it threw it (the
  // slot stays free).
  Ticket submit(std::span<const Ray> rays, BatchQuery query = {});
  // Room for a batch of `rays` rays that the caller writes in place, then
  // starts with submit(batch): for a batch the GPU will answer, the
  // device's own mapped memory, read as written (no copy of the rays at
  // all: what a batch of millions wants); else the slot's array. The room
  // is not cleared: it holds an earlier batch's rays until written. The
  // batch holds a frame slot from now on; poll() and wait() refuse it
  // until it is submitted. Write Ray records only into the span, and
  // nothing after submit(). Throws as submit(rays).
  OpenBatch open(uint32_t rays, BatchQuery query = {});
  // Starts a batch open() gave, with the rays of batch.rays: the whole
  // room, or its first k rays when the caller narrowed the span to the
  // rays it wrote (the batch then has k rays, and wait() needs room for k
  // hits). UsageError for a batch not open (submitted already, or another
  // caster's), and for a span that no longer starts where open() put it or
  // is longer than the rays opened (the batch stays open then).
  Ticket submit(const OpenBatch& batch);
  // A scene batch (see above): the scene's last commit, taken now; call it
  // from the thread that edits and commits the scene. The rays are copied.
  // HitOutputs::Point is left out of scene hits (they carry none). Throws
  // as submit(rays).
  Ticket submit(const Scene& scene, std::span<const RayD> rays, SceneBatchQuery query = {});
  // Collects a scene batch (closest or any hit a ray, or Query::All's rows),
  // as wait(ticket, hits) does; its snapshot is let go.
  BatchRecord wait(const Ticket& t, std::span<SceneHit> hits);
  BatchRecord wait(const Ticket& t, SceneHitLists& lists);

  // Whether the batch is ready. UsageError for a ticket this caster did not
  // issue (another caster's, or made up) or that was already collected.
  bool poll(const Ticket& t);
  // Blocks until ready, copies the hits into `hits` (at least the batch's
  // size, else UsageError) and frees the slot; returns that batch's record.
  // UsageError for a Query::All batch (its rows: the overload below). A
  // batch the caster moved from the GPU to the CPU after submit() returned
  // (a refused scene batch, a lost device) whose JobSystem::run() threw is
  // collected by rethrowing what it threw.
  BatchRecord wait(const Ticket& t, std::span<Hit> hits);
  // A Query::All batch's rows into `lists`: compact rows (meshcast/ray.h),
  // cleared first, their capacity kept; the CPU's jobs' rows are copied
  // one after the other, the GPU's fixed device rows compacted as they are
  // read back. UsageError for a batch of another query.
  BatchRecord wait(const Ticket& t, HitLists& lists);
  // The calling thread walks the rays now (the CPU walker, no pool):
  // closest or any hit, or with `lists` every hit (compact rows keeping
  // lists.max_hits a ray, BlobView::trace_all_hits).
  void trace_now(std::span<const Ray> rays, std::span<Hit> hits, BatchQuery query = {}) const;
  void trace_now(std::span<const Ray> rays, HitLists& lists, Cull cull = Cull::None) const;

  // Where a batch of `rays` would go now, and why in a sentence.
  Backend choose(uint32_t rays) const;
  std::string why(uint32_t rays) const;
  // The Automatic backend: GPU from this batch size on (~0u: never, or not
  // known yet). Construction never waits for it: read from
  // CasterOptions::profile when that names this device and blob, else
  // measured in the background on a frame slot of its own, every batch
  // going to the CPU meanwhile. wait_for_crossover() blocks until it is
  // known (at once for the other backends).
  uint32_t crossover() const;
  bool crossover_known() const;
  void wait_for_crossover();
  // Whether batches may go to the GPU now: its device was made (the
  // Vulkan or Automatic backend; for a caster of scene batches alone,
  // Vulkan) and has not failed since. Blob batches then go where choose()
  // says, scene batches the GPU scene method reads to the device.
  bool gpu_available() const;
  // Why the GPU is not available although the caster asked for one: the
  // device, or the method for the blob's layout, could not be made, or the
  // device was lost (a failed submission, fence or read-back), after which
  // every batch is the CPU's. "" while it is available, and for
  // Backend::Cpu (and a caster of scene batches alone on Automatic).
  std::string gpu_error() const;
  std::string device_name() const;
  // Messages from the Vulkan validation layers so far (options.validation).
  uint32_t validation_messages() const;
  uint32_t cpu_threads() const;

  // Latency percentiles and throughput of the collected batches of one
  // backend (all sizes together), or of one batch size.
  Percentiles percentiles(Backend b, uint32_t rays = 0) const;
  std::vector<BatchRecord> records() const;
  void clear_records();

 private:
  // Its slots, threads and GPU methods (host/caster_impl.h): none of them
  // is part of the API, and their headers stay out of the user's.
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace meshcast::host
