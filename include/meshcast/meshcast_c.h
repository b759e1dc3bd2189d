/* meshcast's C API: one header, for C11 and C++, and one library
 * (libmeshcast_c.so, or libmeshcast_c.a) exporting these functions alone,
 * every name beginning with meshcast_. docs/c-api.md states its rules.
 *
 * - Handles (meshcast_blob, meshcast_scene, meshcast_caster) are opaque;
 *   each is made by one call and released by its _release call. A handle
 *   released, or never made here, is refused with MESHCAST_ERROR_USAGE,
 *   never read. A call already running on another thread when the handle
 *   is released keeps it until that call returns: the release frees it
 *   then, and later calls are refused.
 * - Every call that can fail returns a meshcast_status. On failure,
 *   meshcast_last_error() (this thread's) names the input and the limit it
 *   broke, and the error callback, where one is set, gets the same words.
 *   Nothing throws through the API.
 * - Structs that may grow begin with struct_size: set it to sizeof the
 *   struct as your header declares it (the _init calls do). A library newer
 *   than your header reads only that many bytes and takes the defaults for
 *   the rest; a size below the first version's is refused.
 * - The caller's arrays are read or written during the call alone, except
 *   where a call says it keeps them (meshcast_blob_from_memory with
 *   MESHCAST_MEMORY_BORROW).
 *
 *   meshcast_mesh mesh;
 *   meshcast_mesh_init(&mesh);
 *   mesh.vertices = positions, mesh.vertex_count = n, mesh.indices = indices;
 *   mesh.triangle_count = t, mesh.index_bits = 32;
 *   meshcast_blob* blob;
 *   if (meshcast_blob_build(&mesh, NULL, &blob) != MESHCAST_OK) puts(meshcast_last_error());
 *   meshcast_blob_cast(blob, rays, count, NULL, hits, count, NULL);
 *   meshcast_blob_release(blob);
 */
#ifndef MESHCAST_C_H
#define MESHCAST_C_H

#include <stddef.h>
#include <stdint.h>

#if defined(MESHCAST_C_BUILDING) && defined(__GNUC__)
#define MESHCAST_C_API __attribute__((visibility("default")))
#else
#define MESHCAST_C_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* The API's version: a program built against major M runs on a library
 * of major M and any minor at or above its header's. */
#define MESHCAST_C_API_VERSION_MAJOR 2
#define MESHCAST_C_API_VERSION_MINOR 0
#define MESHCAST_C_API_VERSION ((MESHCAST_C_API_VERSION_MAJOR << 16) | MESHCAST_C_API_VERSION_MINOR)

/* The library's MESHCAST_C_API_VERSION, as it was built. */
MESHCAST_C_API uint32_t meshcast_api_version(void);

typedef enum meshcast_status {
  MESHCAST_OK = 0,
  /* A mesh, blob, file, ray or option the library refuses. */
  MESHCAST_ERROR_INPUT = 1,
  /* A call the API does not allow: a null or released handle, a struct_size
   * too small, a buffer too short, another caster's ticket. */
  MESHCAST_ERROR_USAGE = 2,
  /* A file that could not be written whole (nothing is left under its name). */
  MESHCAST_ERROR_OUTPUT = 3,
  /* Vulkan: no device, or a call that failed. */
  MESHCAST_ERROR_GPU = 4,
  MESHCAST_ERROR_OUT_OF_MEMORY = 5,
  MESHCAST_ERROR_INTERNAL = 6
} meshcast_status;

/* This thread's message for its last failed call ("" when none failed);
 * valid until this thread's next call. */
MESHCAST_C_API const char* meshcast_last_error(void);
/* "MESHCAST_ERROR_INPUT" for MESHCAST_ERROR_INPUT, and so on. */
MESHCAST_C_API const char* meshcast_status_name(meshcast_status status);
/* Called on the failing thread with every failure's status and message
 * (the process's one callback; NULL: none). The message is valid until the
 * callback returns, whatever it calls meanwhile (a failing call included:
 * its own failure calls the callback again, on the same thread); copy it
 * to keep it. After the failed call returns, meshcast_last_error() gives
 * that call's message again. */
typedef void (*meshcast_error_callback)(void* user, meshcast_status status, const char* message);
MESHCAST_C_API void meshcast_set_error_callback(meshcast_error_callback callback, void* user);

#define MESHCAST_NO_HIT 0xFFFFFFFFu

/* A ray: o + t d for t in [tmin, tmax], both ends included. 32 bytes. */
typedef struct meshcast_ray {
  float org[3];
  float dir[3];
  float tmax;
  float tmin;
} meshcast_ray;

/* A hit: t (INFINITY on a miss) and the caller's triangle (MESHCAST_NO_HIT
 * on a miss); u, v and point only when asked for (MESHCAST_HIT_UV,
 * MESHCAST_HIT_POINT), else 0. 28 bytes. */
typedef struct meshcast_hit {
  float t;
  uint32_t triangle;
  float u, v;
  float point[3];
} meshcast_hit;

/* A scene's ray: a double-precision origin. 48 bytes. */
typedef struct meshcast_ray_d {
  double org[3];
  float dir[3];
  float tmax;
  float tmin;
  uint32_t reserved; /* 0 */
} meshcast_ray_d;

/* A scene's hit: the instance and its mesh's triangle. 20 bytes. */
typedef struct meshcast_scene_hit {
  float t;
  uint32_t instance;
  uint32_t triangle;
  float u, v;
} meshcast_scene_hit;

/* The nearest point of a mesh to a query point (distance INFINITY and
 * triangle MESHCAST_NO_HIT when none lies within the limit); u, v its
 * barycentrics on the triangle. 28 bytes. */
typedef struct meshcast_closest_point {
  float point[3];
  float distance;
  uint32_t triangle;
  float u, v;
} meshcast_closest_point;

/* A scene's nearest point, in double. 48 bytes. */
typedef struct meshcast_scene_closest_point {
  double point[3];
  double distance;
  uint32_t instance;
  uint32_t triangle;
  float u, v;
} meshcast_scene_closest_point;

/* The caller's mesh, read where it lies: vertex_count positions of three
 * floats every vertex_stride bytes (0: 12, packed), triangle_count
 * triangles of three index_bits-bit indices (16 or 32) every
 * triangle_stride bytes (0: packed). */
typedef struct meshcast_mesh {
  uint32_t struct_size;
  uint32_t index_bits;
  const float* vertices;
  uint64_t vertex_count;
  uint64_t vertex_stride;
  const void* indices;
  uint64_t triangle_count;
  uint64_t triangle_stride;
} meshcast_mesh;
MESHCAST_C_API void meshcast_mesh_init(meshcast_mesh* mesh);

/* How a blob is built. layout: "TREE/TRIANGLES" (meshcast layouts lists
 * them), "auto" (chosen for the mesh under the limits below), or NULL for
 * the recommended layout. */
typedef struct meshcast_build_options {
  uint32_t struct_size;
  uint32_t threads;             /* build threads (0: every core) */
  const char* layout;
  const char* name;             /* the mesh in messages (NULL: "mesh") */
  double max_bytes_per_triangle; /* auto: at most this (0: no limit) */
  double max_error;             /* auto: stated error at most this fraction of the diagonal (0: no limit) */
  uint32_t goal_memory;         /* auto: 1 the fewest bytes, 0 the fastest */
  uint32_t triangle_ids;        /* 1 (the default): hits name the caller's triangles; 0: their slots */
} meshcast_build_options;
MESHCAST_C_API void meshcast_build_options_init(meshcast_build_options* options);

typedef struct meshcast_blob meshcast_blob;

/* options NULL: the defaults. */
MESHCAST_C_API meshcast_status meshcast_blob_build(const meshcast_mesh* mesh, const meshcast_build_options* options,
                                                   meshcast_blob** out);
/* flags: MESHCAST_LOAD_MAP maps the file read-only (the pages shared, the
 * file not to be rewritten in place while mapped), else it is read whole.
 * Validated either way. */
#define MESHCAST_LOAD_MAP 1u
MESHCAST_C_API meshcast_status meshcast_blob_load(const char* path, uint32_t flags, meshcast_blob** out);
/* A blob's bytes in memory, validated: copied (MESHCAST_MEMORY_COPY), or
 * with MESHCAST_MEMORY_BORROW read where they lie, and then they must stay
 * unchanged and outlive the blob and every scene it joins. */
#define MESHCAST_MEMORY_COPY 0u
#define MESHCAST_MEMORY_BORROW 1u
MESHCAST_C_API meshcast_status meshcast_blob_from_memory(const void* bytes, uint64_t size, uint32_t flags,
                                                         const char* name, meshcast_blob** out);
/* Written beside path, then renamed over it (an empty path is refused). */
MESHCAST_C_API meshcast_status meshcast_blob_save(const meshcast_blob* blob, const char* path);
/* The blob's bytes, valid while the blob lives. */
MESHCAST_C_API meshcast_status meshcast_blob_bytes(const meshcast_blob* blob, const void** bytes, uint64_t* size);

typedef struct meshcast_blob_info {
  uint32_t struct_size;
  uint32_t triangle_count;
  uint64_t bytes;
  const char* layout;  /* "TREE/TRIANGLES", valid while the blob lives */
  double error_bound;  /* the stated error, a fraction of the diagonal (0: exact) */
} meshcast_blob_info;
MESHCAST_C_API meshcast_status meshcast_blob_info_get(const meshcast_blob* blob, meshcast_blob_info* info);
/* NULL is MESHCAST_OK; a scene the blob joined keeps its bytes, and a cast
 * through it already running on another thread keeps it until it returns. */
MESHCAST_C_API meshcast_status meshcast_blob_release(meshcast_blob* blob);

#define MESHCAST_CLOSEST 0u
#define MESHCAST_ANY 1u
#define MESHCAST_CULL_NONE 0u
#define MESHCAST_CULL_BACK 1u
#define MESHCAST_CULL_FRONT 2u
#define MESHCAST_HIT_UV 1u
#define MESHCAST_HIT_POINT 2u

/* The question a cast asks. threads: 1 the calling thread alone, 0 every
 * core, n that many (the library's pool). */
typedef struct meshcast_query {
  uint32_t struct_size;
  uint32_t kind;    /* MESHCAST_CLOSEST or MESHCAST_ANY */
  uint32_t cull;    /* MESHCAST_CULL_* (a front face: counter-clockwise seen from the origin) */
  uint32_t outputs; /* MESHCAST_HIT_UV | MESHCAST_HIT_POINT (scenes: UV alone) */
  uint32_t mask;    /* scenes: instances whose mask shares a bit with it (0xFF: every one) */
  uint32_t threads;
} meshcast_query;
MESHCAST_C_API void meshcast_query_init(meshcast_query* query);

/* The hit of each ray into hits[0..ray_count) (hit_capacity at least
 * ray_count). not_walkable (NULL: not asked): rays with a NaN or infinite
 * component, a zero direction or a bad tmin/tmax, answered as misses.
 * query NULL: the closest hit on the calling thread. */
MESHCAST_C_API meshcast_status meshcast_blob_cast(const meshcast_blob* blob, const meshcast_ray* rays,
                                                  uint64_t ray_count, const meshcast_query* query, meshcast_hit* hits,
                                                  uint64_t hit_capacity, uint64_t* not_walkable);
/* Every hit of each ray: found[i] the count along the ray, its nearest
 * min(found[i], max_hits) at hits[i * max_hits ...], nearest first
 * (hit_capacity at least ray_count * max_hits; max_hits 1..4096). */
MESHCAST_C_API meshcast_status meshcast_blob_cast_all(const meshcast_blob* blob, const meshcast_ray* rays,
                                                      uint64_t ray_count, const meshcast_query* query,
                                                      uint32_t max_hits, uint32_t* found, meshcast_hit* hits,
                                                      uint64_t hit_capacity, uint64_t* not_walkable);
/* The nearest point of the mesh to each of point_count points (x, y, z
 * floats), within max_distance (INFINITY: any). OctTreeCompressed blobs
 * alone (the recommended layout and its exact form). threads as a query's. */
MESHCAST_C_API meshcast_status meshcast_blob_closest_points(const meshcast_blob* blob, const float* points,
                                                            uint64_t point_count, float max_distance, uint32_t threads,
                                                            meshcast_closest_point* out, uint64_t out_capacity);

typedef struct meshcast_scene meshcast_scene;

/* An instance's placement: x_world = rotation_scale (row-major 3x3) x_mesh
 * + translation. */
typedef struct meshcast_transform {
  float rotation_scale[9];
  double translation[3];
} meshcast_transform;
MESHCAST_C_API void meshcast_transform_identity(meshcast_transform* transform);

/* A mesh or an instance a scene gave. index counts from 0 in the order
 * they were added (a meshcast_scene_hit's instance is its instance's
 * index); scene is the number of the scene that gave it, never given to
 * another scene of the process, which refuses the id (MESHCAST_ERROR_USAGE)
 * as a caster refuses another caster's ticket. */
typedef struct meshcast_mesh_id {
  uint64_t scene;
  uint32_t index;
  uint32_t reserved;
} meshcast_mesh_id;
typedef struct meshcast_instance_id {
  uint64_t scene;
  uint32_t index;
  uint32_t reserved;
} meshcast_instance_id;

MESHCAST_C_API meshcast_status meshcast_scene_create(meshcast_scene** out);
/* The scene keeps the blob's bytes (the blob may be released after). */
MESHCAST_C_API meshcast_status meshcast_scene_add_mesh(meshcast_scene* scene, const meshcast_blob* blob,
                                                       meshcast_mesh_id* mesh);
/* transform NULL: the identity. mask: 8 bits. flip_facing: 1 turns its
 * faces (culling then drops the mesh's front faces). */
MESHCAST_C_API meshcast_status meshcast_scene_add_instance(meshcast_scene* scene, meshcast_mesh_id mesh,
                                                           const meshcast_transform* transform, uint32_t mask,
                                                           uint32_t flip_facing, meshcast_instance_id* instance);
MESHCAST_C_API meshcast_status meshcast_scene_set_transform(meshcast_scene* scene, meshcast_instance_id instance,
                                                            const meshcast_transform* transform);
MESHCAST_C_API meshcast_status meshcast_scene_set_mask(meshcast_scene* scene, meshcast_instance_id instance,
                                                       uint32_t mask);
MESHCAST_C_API meshcast_status meshcast_scene_set_flip_facing(meshcast_scene* scene, meshcast_instance_id instance,
                                                              uint32_t flip_facing);
MESHCAST_C_API meshcast_status meshcast_scene_set_enabled(meshcast_scene* scene, meshcast_instance_id instance,
                                                          uint32_t enabled);
MESHCAST_C_API meshcast_status meshcast_scene_remove_instance(meshcast_scene* scene, meshcast_instance_id instance);
/* The edits so far are seen by the casts from now on. A scene given a mesh
 * or an instance is cast (or submitted to a caster) only once committed:
 * before its first commit, MESHCAST_ERROR_USAGE. */
MESHCAST_C_API meshcast_status meshcast_scene_commit(meshcast_scene* scene);
MESHCAST_C_API meshcast_status meshcast_scene_cast(const meshcast_scene* scene, const meshcast_ray_d* rays,
                                                   uint64_t ray_count, const meshcast_query* query,
                                                   meshcast_scene_hit* hits, uint64_t hit_capacity,
                                                   uint64_t* not_walkable);
MESHCAST_C_API meshcast_status meshcast_scene_cast_all(const meshcast_scene* scene, const meshcast_ray_d* rays,
                                                       uint64_t ray_count, const meshcast_query* query,
                                                       uint32_t max_hits, uint32_t* found, meshcast_scene_hit* hits,
                                                       uint64_t hit_capacity, uint64_t* not_walkable);
/* points: x, y, z doubles; the distance is the world's under any scale. */
MESHCAST_C_API meshcast_status meshcast_scene_closest_points(const meshcast_scene* scene, const double* points,
                                                             uint64_t point_count, double max_distance, uint32_t mask,
                                                             uint32_t threads, meshcast_scene_closest_point* out,
                                                             uint64_t out_capacity);
MESHCAST_C_API meshcast_status meshcast_scene_release(meshcast_scene* scene);

typedef struct meshcast_caster meshcast_caster;

#define MESHCAST_BACKEND_CPU 0u
#define MESHCAST_BACKEND_VULKAN 1u
#define MESHCAST_BACKEND_AUTOMATIC 2u

typedef struct meshcast_caster_options {
  uint32_t struct_size;
  uint32_t backend; /* MESHCAST_BACKEND_* (Automatic: the GPU from the batch size it measures on) */
  uint32_t frames;  /* batches in flight at most (1..1024) */
  uint32_t threads; /* CPU workers (0: every core) */
  uint32_t outputs; /* MESHCAST_HIT_UV | MESHCAST_HIT_POINT, for every batch */
} meshcast_caster_options;
MESHCAST_C_API void meshcast_caster_options_init(meshcast_caster_options* options);

/* A batch's receipt, good for the caster that issued it alone. */
typedef struct meshcast_ticket {
  uint64_t id;
  uint64_t caster;
  uint32_t slot;
  uint32_t reserved;
} meshcast_ticket;

/* Room for rays written in place (open), then submitted. */
typedef struct meshcast_open_batch {
  meshcast_ticket ticket;
  meshcast_ray* rays;
  uint64_t ray_count;
} meshcast_open_batch;

/* What a batch cost, and where it ran (MESHCAST_BACKEND_CPU or _VULKAN). */
typedef struct meshcast_batch_record {
  uint32_t ran_on;
  uint32_t rays;
  double latency_ms, device_ms, cpu_ms;
} meshcast_batch_record;

/* blob NULL: a caster of scene batches alone. The caster reads the blob's
 * bytes, which it keeps. */
MESHCAST_C_API meshcast_status meshcast_caster_create(const meshcast_blob* blob, const meshcast_caster_options* options,
                                                      meshcast_caster** out);
/* The rays are copied; query: kind and cull (threads and mask unused). */
MESHCAST_C_API meshcast_status meshcast_caster_submit(meshcast_caster* caster, const meshcast_ray* rays,
                                                      uint64_t ray_count, const meshcast_query* query,
                                                      meshcast_ticket* ticket);
MESHCAST_C_API meshcast_status meshcast_caster_open(meshcast_caster* caster, uint32_t ray_count,
                                                    const meshcast_query* query, meshcast_open_batch* batch);
/* Starts an open batch with its first `written` rays. */
MESHCAST_C_API meshcast_status meshcast_caster_submit_open(meshcast_caster* caster, const meshcast_open_batch* batch,
                                                           uint64_t written, meshcast_ticket* ticket);
MESHCAST_C_API meshcast_status meshcast_caster_submit_scene(meshcast_caster* caster, const meshcast_scene* scene,
                                                            const meshcast_ray_d* rays, uint64_t ray_count,
                                                            const meshcast_query* query, meshcast_ticket* ticket);
MESHCAST_C_API meshcast_status meshcast_caster_poll(meshcast_caster* caster, const meshcast_ticket* ticket,
                                                    uint32_t* ready);
/* Blocks until ready, writes the hits (hit_capacity at least the batch's
 * rays), frees the slot; record may be NULL. */
MESHCAST_C_API meshcast_status meshcast_caster_wait(meshcast_caster* caster, const meshcast_ticket* ticket,
                                                    meshcast_hit* hits, uint64_t hit_capacity,
                                                    meshcast_batch_record* record);
MESHCAST_C_API meshcast_status meshcast_caster_wait_scene(meshcast_caster* caster, const meshcast_ticket* ticket,
                                                          meshcast_scene_hit* hits, uint64_t hit_capacity,
                                                          meshcast_batch_record* record);
/* Where a batch of ray_count rays would go now, and why in a sentence
 * (valid until the caster's next call from this thread). */
MESHCAST_C_API meshcast_status meshcast_caster_backend(meshcast_caster* caster, uint32_t ray_count, uint32_t* backend,
                                                       const char** why);
MESHCAST_C_API meshcast_status meshcast_caster_release(meshcast_caster* caster);

#ifdef __cplusplus
}
#endif

#endif /* MESHCAST_C_H */
