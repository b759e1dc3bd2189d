/* The C API (meshcast/meshcast_c.h) from C11: every call, with answers
 * known from the mesh's construction, and misuse of each kind (null and
 * released handles, a handle of another kind, a struct_size too small, a
 * buffer too short, another caster's ticket, bad meshes and files): a
 * status and a message, never a crash. Built with -Wall -Wextra -pedantic
 * -Werror, and run under AddressSanitizer too (scripts/test.sh).
 *
 * The mesh: two unit squares, A at z = 0 (triangles 0, 1) and B at z = 1
 * (triangles 2, 3), each split along its diagonal x = y; triangles 0 and
 * 2 hold the points with x >= y. Their corners run counter-clockwise seen
 * from above. */
#include <math.h>
#include <stdlib.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <threads.h>

#include "meshcast/meshcast_c.h"

static int failures = 0;

#define CHECK(cond)                                                                  \
  do {                                                                               \
    if (!(cond)) {                                                                   \
      fprintf(stderr, "%s:%d: CHECK(%s) failed (last error: %s)\n", __FILE__, __LINE__, #cond, \
              meshcast_last_error());                                                \
      ++failures;                                                                    \
    }                                                                                \
  } while (0)

/* The call returns `status` and its message holds `words`. */
#define EXPECT_FAILS(call, status, words)                                                          \
  do {                                                                                             \
    meshcast_status got_ = (call);                                                                 \
    if (got_ != (status) || strstr(meshcast_last_error(), (words)) == NULL) {                      \
      fprintf(stderr, "%s:%d: %s returned %s with \"%s\"; expected %s with \"%s\"\n", __FILE__, __LINE__, \
              #call, meshcast_status_name(got_), meshcast_last_error(), #status, (words));         \
      ++failures;                                                                                  \
    }                                                                                              \
  } while (0)

#define EXPECT_OK(call) CHECK((call) == MESHCAST_OK)

static const float kVertices[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
static const uint32_t kIndices[] = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};
static const uint16_t kIndices16[] = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};

static meshcast_mesh two_squares(void) {
  meshcast_mesh mesh;
  meshcast_mesh_init(&mesh);
  mesh.vertices = kVertices;
  mesh.vertex_count = 8;
  mesh.indices = kIndices;
  mesh.triangle_count = 4;
  return mesh;
}

static meshcast_ray down_at(float x, float y) {
  meshcast_ray r = {{x, y, 2}, {0, 0, -1}, INFINITY, 0};
  return r;
}

static int error_calls = 0;
static void count_errors(void* user, meshcast_status status, const char* message) {
  (void)message;
  *(int*)user += status != MESHCAST_OK;
}

static meshcast_blob* build(const char* layout) {
  meshcast_mesh mesh = two_squares();
  meshcast_build_options options;
  meshcast_build_options_init(&options);
  options.layout = layout;
  options.name = "two squares";
  meshcast_blob* blob = NULL;
  EXPECT_OK(meshcast_blob_build(&mesh, &options, &blob));
  CHECK(blob != NULL);
  return blob;
}

/* A committed scene of one instance of `blob` at the identity; its
   instance's id in *instance. */
static meshcast_scene* scene_of_one(meshcast_blob* blob, meshcast_instance_id* instance) {
  meshcast_scene* scene = NULL;
  meshcast_mesh_id mesh;
  EXPECT_OK(meshcast_scene_create(&scene));
  EXPECT_OK(meshcast_scene_add_mesh(scene, blob, &mesh));
  EXPECT_OK(meshcast_scene_add_instance(scene, mesh, NULL, 0xFF, 0, instance));
  EXPECT_OK(meshcast_scene_commit(scene));
  return scene;
}

static void test_version_and_errors(void) {
  CHECK(meshcast_api_version() >> 16 == MESHCAST_C_API_VERSION_MAJOR);
  CHECK(meshcast_api_version() >= (uint32_t)MESHCAST_C_API_VERSION); /* the same major, a minor at or above */
  CHECK(strcmp(meshcast_status_name(MESHCAST_ERROR_USAGE), "MESHCAST_ERROR_USAGE") == 0);
  meshcast_set_error_callback(count_errors, &error_calls);
  EXPECT_FAILS(meshcast_blob_release((meshcast_blob*)&error_calls), MESHCAST_ERROR_USAGE, "not a live meshcast_blob");
  CHECK(error_calls == 1);
  meshcast_set_error_callback(NULL, NULL);
  EXPECT_OK(meshcast_blob_release(NULL));
  CHECK(strcmp(meshcast_last_error(), "") == 0);
}

/* A callback that fails calls of its own: the message it was given stays
 * what it was, and readable, until it returns (its own calls' messages are
 * shorter and longer than it, so they would be written over it or move it). */
static int callback_depth = 0;
static int callback_kept_message = -1;
static void fail_inside_callback(void* user, meshcast_status status, const char* message) {
  (void)status;
  if (callback_depth) return;
  callback_depth = 1;
  char before[1024];
  snprintf(before, sizeof before, "%s", message);
  meshcast_hit hit;
  meshcast_blob_cast(NULL, NULL, 0, NULL, &hit, 0, NULL);     /* fails: a short message */
  meshcast_blob_release((meshcast_blob*)user);               /* fails: a long one */
  callback_kept_message = strcmp(before, message) == 0;
  callback_depth = 0;
}

static void test_callback_calls(void) {
  meshcast_set_error_callback(fail_inside_callback, &callback_depth);
  meshcast_query query;
  meshcast_query_init(&query);
  query.kind = 7;
  meshcast_blob* blob = build(NULL);
  meshcast_ray ray = down_at(0.5f, 0.5f);
  meshcast_hit hit;
  EXPECT_FAILS(meshcast_blob_cast(blob, &ray, 1, &query, &hit, 1, NULL), MESHCAST_ERROR_USAGE, "query->kind 7");
  CHECK(callback_kept_message == 1);
  meshcast_set_error_callback(NULL, NULL);
  EXPECT_OK(meshcast_blob_release(blob));
}

/* layout: NULL (the recommended one) or a name; point queries walk the
 * OctTreeCompressed layouts alone. */
static void test_blob_casts(const char* layout) {
  const int walks_points = layout == NULL || strncmp(layout, "OctTreeCompressed/", 18) == 0;
  meshcast_blob* blob = build(layout);
  meshcast_ray rays[4] = {down_at(0.75f, 0.25f), down_at(0.25f, 0.75f), down_at(3, 3), down_at(0.75f, 0.25f)};
  rays[3].tmin = 1.5f; /* past B: A's triangle 0 at t = 2 */
  rays[2].dir[2] = NAN; /* not walkable */
  meshcast_hit hits[4];
  meshcast_query query;
  meshcast_query_init(&query);
  query.outputs = MESHCAST_HIT_UV | MESHCAST_HIT_POINT;
  uint64_t not_walkable = 7;
  EXPECT_OK(meshcast_blob_cast(blob, rays, 4, &query, hits, 4, &not_walkable));
  CHECK(not_walkable == 1);
  CHECK(hits[0].triangle == 2 && hits[0].t == 1.0f && fabsf(hits[0].point[0] - 0.75f) < 1e-5f);
  CHECK(hits[1].triangle == 3 && hits[1].t == 1.0f);
  CHECK(hits[2].triangle == MESHCAST_NO_HIT && isinf(hits[2].t));
  CHECK(hits[3].triangle == 0 && hits[3].t == 2.0f);
  /* Culling: seen from above the corners run counter-clockwise (front). */
  query.cull = MESHCAST_CULL_FRONT;
  EXPECT_OK(meshcast_blob_cast(blob, rays, 2, &query, hits, 2, NULL));
  CHECK(hits[0].triangle == MESHCAST_NO_HIT && hits[1].triangle == MESHCAST_NO_HIT);
  query.cull = MESHCAST_CULL_BACK;
  query.kind = MESHCAST_ANY;
  query.threads = 0; /* every core */
  EXPECT_OK(meshcast_blob_cast(blob, rays, 2, &query, hits, 2, NULL));
  CHECK(hits[0].triangle == 0 || hits[0].triangle == 2);
  /* Every hit: B then A. */
  uint32_t found[2];
  meshcast_hit rows[2 * 3];
  query.kind = MESHCAST_CLOSEST, query.cull = MESHCAST_CULL_NONE;
  EXPECT_OK(meshcast_blob_cast_all(blob, rays, 2, &query, 3, found, rows, 6, NULL));
  CHECK(found[0] == 2 && rows[0].triangle == 2 && rows[1].triangle == 0 && rows[1].t == 2.0f);
  CHECK(found[1] == 2 && rows[3].triangle == 3 && rows[4].triangle == 1);
  /* Nearest points: 0.3 above A's diagonal (triangles 0 and 1: the lower). */
  const float points[6] = {0.5f, 0.5f, 0.3f, 0.25f, 0.75f, 5.0f};
  meshcast_closest_point near[2];
  if (walks_points) {
    EXPECT_OK(meshcast_blob_closest_points(blob, points, 2, INFINITY, 1, near, 2));
    CHECK(fabsf(near[0].distance - 0.3f) < 1e-6f && near[0].triangle == 0 && near[0].point[2] == 0.0f);
    CHECK(fabsf(near[1].distance - 4.0f) < 1e-6f && near[1].triangle == 3);
    EXPECT_OK(meshcast_blob_closest_points(blob, points, 2, 1.0f, 2, near, 2));
    CHECK(near[1].triangle == MESHCAST_NO_HIT && isinf(near[1].distance));
  } else {
    EXPECT_FAILS(meshcast_blob_closest_points(blob, points, 2, INFINITY, 1, near, 2), MESHCAST_ERROR_USAGE, layout);
  }

  /* Misuse: a status and the words that say what is wrong. */
  EXPECT_FAILS(meshcast_blob_cast(NULL, rays, 1, NULL, hits, 1, NULL), MESHCAST_ERROR_USAGE, "null meshcast_blob");
  EXPECT_FAILS(meshcast_blob_cast(blob, rays, 4, NULL, hits, 3, NULL), MESHCAST_ERROR_USAGE, "fewer than the 4");
  EXPECT_FAILS(meshcast_blob_cast(blob, NULL, 4, NULL, hits, 4, NULL), MESHCAST_ERROR_USAGE, "rays is null");
  query.struct_size = 4;
  EXPECT_FAILS(meshcast_blob_cast(blob, rays, 1, &query, hits, 1, NULL), MESHCAST_ERROR_USAGE, "struct_size 4");
  meshcast_query_init(&query);
  query.kind = 9;
  EXPECT_FAILS(meshcast_blob_cast(blob, rays, 1, &query, hits, 1, NULL), MESHCAST_ERROR_USAGE, "query->kind 9");
  EXPECT_FAILS(meshcast_blob_cast_all(blob, rays, 2, NULL, 0, found, rows, 6, NULL), MESHCAST_ERROR_USAGE, "max_hits 0");
  EXPECT_FAILS(meshcast_blob_cast_all(blob, rays, 2, NULL, 4, found, rows, 6, NULL), MESHCAST_ERROR_USAGE, "fewer than the 8");
  EXPECT_FAILS(meshcast_blob_closest_points(blob, points, 2, INFINITY, 5000, near, 2), MESHCAST_ERROR_USAGE, "threads 5000");
  EXPECT_OK(meshcast_blob_release(blob));
  EXPECT_FAILS(meshcast_blob_cast(blob, rays, 1, NULL, hits, 1, NULL), MESHCAST_ERROR_USAGE, "released already");
}

static void test_build_load_save(void) {
  meshcast_mesh mesh = two_squares();
  meshcast_blob* blob = NULL;
  /* 16-bit indices, a strided vertex buffer: the same answers. */
  float strided[8 * 4];
  for (int v = 0; v < 8; ++v) {
    for (int k = 0; k < 3; ++k) strided[4 * v + k] = kVertices[3 * v + k];
    strided[4 * v + 3] = -1;
  }
  mesh.vertices = strided, mesh.vertex_stride = 16, mesh.indices = kIndices16, mesh.index_bits = 16;
  EXPECT_OK(meshcast_blob_build(&mesh, NULL, &blob));
  meshcast_blob_info info;
  info.struct_size = sizeof info;
  EXPECT_OK(meshcast_blob_info_get(blob, &info));
  CHECK(info.triangle_count == 4 && strstr(info.layout, "OctTreeCompressed/") == info.layout && info.bytes > 0);
  /* Saved, loaded (read and mapped), from memory (copied and borrowed). */
  const char* path = "c_api_test.blob";
  EXPECT_OK(meshcast_blob_save(blob, path));
  const void* bytes = NULL;
  uint64_t size = 0;
  EXPECT_OK(meshcast_blob_bytes(blob, &bytes, &size));
  CHECK(size == info.bytes);
  meshcast_blob* loaded[4] = {NULL, NULL, NULL, NULL};
  EXPECT_OK(meshcast_blob_load(path, 0, &loaded[0]));
  EXPECT_OK(meshcast_blob_load(path, MESHCAST_LOAD_MAP, &loaded[1]));
  EXPECT_OK(meshcast_blob_from_memory(bytes, size, MESHCAST_MEMORY_COPY, "copy", &loaded[2]));
  EXPECT_OK(meshcast_blob_from_memory(bytes, size, MESHCAST_MEMORY_BORROW, "borrowed", &loaded[3]));
  meshcast_ray ray = down_at(0.25f, 0.75f);
  for (int i = 0; i < 4; ++i) {
    meshcast_hit hit;
    EXPECT_OK(meshcast_blob_cast(loaded[i], &ray, 1, NULL, &hit, 1, NULL));
    CHECK(hit.triangle == 3 && hit.t == 1.0f);
    EXPECT_OK(meshcast_blob_release(loaded[i]));
  }
  /* The automatic layout under an error limit of 0 (none) and a bytes limit. */
  meshcast_build_options options;
  meshcast_build_options_init(&options);
  options.layout = "auto";
  options.max_bytes_per_triangle = 1000;
  meshcast_blob* chosen = NULL;
  EXPECT_OK(meshcast_blob_build(&mesh, &options, &chosen));
  EXPECT_OK(meshcast_blob_release(chosen));

  /* Bad input: named, nothing handed out. */
  meshcast_blob* none = (meshcast_blob*)&failures;
  float bad[8 * 3];
  memcpy(bad, kVertices, sizeof bad);
  bad[7] = NAN;
  meshcast_mesh nan_mesh = two_squares();
  nan_mesh.vertices = bad;
  EXPECT_FAILS(meshcast_blob_build(&nan_mesh, NULL, &none), MESHCAST_ERROR_INPUT, "vertex 2");
  CHECK(none == NULL);
  uint32_t far_index[12];
  memcpy(far_index, kIndices, sizeof far_index);
  far_index[5] = 99;
  meshcast_mesh out_of_range = two_squares();
  out_of_range.indices = far_index;
  EXPECT_FAILS(meshcast_blob_build(&out_of_range, NULL, &none), MESHCAST_ERROR_INPUT, "99");
  mesh.index_bits = 8;
  EXPECT_FAILS(meshcast_blob_build(&mesh, NULL, &none), MESHCAST_ERROR_USAGE, "index_bits 8");
  mesh.struct_size = 3;
  EXPECT_FAILS(meshcast_blob_build(&mesh, NULL, &none), MESHCAST_ERROR_USAGE, "struct_size 3");
  meshcast_build_options_init(&options);
  options.layout = "NoSuchTree/Float3";
  mesh = two_squares();
  EXPECT_FAILS(meshcast_blob_build(&mesh, &options, &none), MESHCAST_ERROR_INPUT, "NoSuchTree");
  options.layout = NULL;
  options.max_error = 1e-3;
  EXPECT_FAILS(meshcast_blob_build(&mesh, &options, &none), MESHCAST_ERROR_USAGE, "layout \"auto\"");
  EXPECT_FAILS(meshcast_blob_load("no/such/file.blob", 0, &none), MESHCAST_ERROR_INPUT, "no/such/file.blob");
  unsigned char corrupted[4096];
  CHECK(size <= sizeof corrupted);
  memcpy(corrupted, bytes, size);
  corrupted[size / 2] ^= 0xFF;
  EXPECT_FAILS(meshcast_blob_from_memory(corrupted, size, MESHCAST_MEMORY_COPY, "corrupted", &none), MESHCAST_ERROR_INPUT,
               "corrupted");
  EXPECT_FAILS(meshcast_blob_from_memory(bytes, size / 2, MESHCAST_MEMORY_COPY, "truncated", &none), MESHCAST_ERROR_INPUT,
               "truncated");
  EXPECT_FAILS(meshcast_blob_save(blob, "no/such/folder/x.blob"), MESHCAST_ERROR_OUTPUT, "no/such/folder/x.blob");
  info.struct_size = 2;
  EXPECT_FAILS(meshcast_blob_info_get(blob, &info), MESHCAST_ERROR_USAGE, "struct_size 2");
  EXPECT_OK(meshcast_blob_release(blob));
  remove(path);
}

static void test_scene(void) {
  meshcast_blob* blob = build(NULL);
  meshcast_scene* scene = NULL;
  EXPECT_OK(meshcast_scene_create(&scene));
  meshcast_mesh_id mesh;
  meshcast_instance_id far, near;
  EXPECT_OK(meshcast_scene_add_mesh(scene, blob, &mesh));
  EXPECT_OK(meshcast_blob_release(blob)); /* the scene keeps its bytes */
  meshcast_transform t;
  meshcast_transform_identity(&t);
  t.translation[0] = 1e9; /* far out: double origins keep the hit exact */
  EXPECT_OK(meshcast_scene_add_instance(scene, mesh, &t, 0xFF, 0, &far));
  EXPECT_OK(meshcast_scene_add_instance(scene, mesh, NULL, 0x01, 0, &near));
  EXPECT_OK(meshcast_scene_commit(scene));
  meshcast_ray_d rays[2] = {{{1e9 + 0.75, 0.25, 2}, {0, 0, -1}, INFINITY, 0, 0}, {{0.25, 0.75, 2}, {0, 0, -1}, INFINITY, 0, 0}};
  meshcast_scene_hit hits[2];
  EXPECT_OK(meshcast_scene_cast(scene, rays, 2, NULL, hits, 2, NULL));
  CHECK(far.index == 0 && near.index == 1 && far.scene == mesh.scene && near.scene == mesh.scene);
  CHECK(hits[0].instance == far.index && hits[0].triangle == 2 && hits[0].t == 1.0f);
  CHECK(hits[1].instance == near.index && hits[1].triangle == 3);
  meshcast_query query;
  meshcast_query_init(&query);
  query.mask = 0x02; /* the near instance's mask is 0x01 */
  EXPECT_OK(meshcast_scene_cast(scene, rays, 2, &query, hits, 2, NULL));
  CHECK(hits[0].instance == far.index && hits[1].instance == MESHCAST_NO_HIT);
  EXPECT_OK(meshcast_scene_set_mask(scene, near, 0x03));
  EXPECT_OK(meshcast_scene_set_flip_facing(scene, near, 1));
  EXPECT_OK(meshcast_scene_commit(scene));
  query.cull = MESHCAST_CULL_BACK; /* flipped: the mesh's front faces are its back */
  EXPECT_OK(meshcast_scene_cast(scene, rays, 2, &query, hits, 2, NULL));
  CHECK(hits[0].instance == far.index && hits[1].instance == MESHCAST_NO_HIT);
  uint32_t found[2];
  meshcast_scene_hit rows[4];
  EXPECT_OK(meshcast_scene_cast_all(scene, rays, 2, NULL, 2, found, rows, 4, NULL));
  CHECK(found[0] == 2 && rows[0].t == 1.0f && rows[1].t == 2.0f && found[1] == 2);
  t.translation[2] = 10;
  EXPECT_OK(meshcast_scene_set_transform(scene, far, &t));
  EXPECT_OK(meshcast_scene_set_enabled(scene, near, 0));
  EXPECT_OK(meshcast_scene_commit(scene));
  EXPECT_OK(meshcast_scene_cast(scene, rays, 2, NULL, hits, 2, NULL));
  CHECK(hits[0].triangle == MESHCAST_NO_HIT && hits[1].triangle == MESHCAST_NO_HIT);
  const double points[3] = {1e9 + 0.5, 0.5, 10.25};
  meshcast_scene_closest_point nearest;
  EXPECT_OK(meshcast_scene_closest_points(scene, points, 1, INFINITY, 0xFF, 1, &nearest, 1));
  CHECK(nearest.instance == far.index && fabs(nearest.distance - 0.25) < 1e-6 && fabs(nearest.point[0] - (1e9 + 0.5)) < 1e-6);
  EXPECT_OK(meshcast_scene_remove_instance(scene, near));
  EXPECT_FAILS(meshcast_scene_remove_instance(scene, near), MESHCAST_ERROR_USAGE, "");
  meshcast_mesh_id unknown = mesh;
  unknown.index = 42;
  EXPECT_FAILS(meshcast_scene_add_instance(scene, unknown, NULL, 0xFF, 0, &near), MESHCAST_ERROR_USAGE, "42");
  EXPECT_FAILS(meshcast_scene_add_instance(scene, mesh, NULL, 0x100, 0, &near), MESHCAST_ERROR_USAGE, "mask 256");
  EXPECT_FAILS(meshcast_scene_cast(scene, rays, 2, NULL, hits, 1, NULL), MESHCAST_ERROR_USAGE, "fewer than the 2");
  /* A scene where a blob belongs. */
  EXPECT_FAILS(meshcast_blob_save((const meshcast_blob*)scene, "x.blob"), MESHCAST_ERROR_USAGE, "is a meshcast_scene");
  EXPECT_OK(meshcast_scene_release(scene));
  EXPECT_FAILS(meshcast_scene_commit(scene), MESHCAST_ERROR_USAGE, "released already");
}

/* A scene cast before its first commit: refused, saying to commit (its
 * edits are not yet what casts see); the same scene answers once committed.
 * A scene nothing was added to casts as the empty world it is. */
static void test_scene_before_commit(void) {
  meshcast_blob* blob = build(NULL);
  meshcast_scene* scene = NULL;
  meshcast_scene* empty = NULL;
  EXPECT_OK(meshcast_scene_create(&scene));
  EXPECT_OK(meshcast_scene_create(&empty));
  meshcast_mesh_id mesh;
  meshcast_instance_id instance;
  EXPECT_OK(meshcast_scene_add_mesh(scene, blob, &mesh));
  EXPECT_OK(meshcast_scene_add_instance(scene, mesh, NULL, 0xFF, 0, &instance));
  meshcast_ray_d ray = {{0.25, 0.75, 2}, {0, 0, -1}, INFINITY, 0, 0};
  meshcast_scene_hit hit;
  uint32_t found;
  const double point[3] = {0.5, 0.5, 3};
  meshcast_scene_closest_point nearest;
  EXPECT_FAILS(meshcast_scene_cast(scene, &ray, 1, NULL, &hit, 1, NULL), MESHCAST_ERROR_USAGE, "commit it first");
  EXPECT_FAILS(meshcast_scene_cast_all(scene, &ray, 1, NULL, 1, &found, &hit, 1, NULL), MESHCAST_ERROR_USAGE,
               "never committed");
  EXPECT_FAILS(meshcast_scene_closest_points(scene, point, 1, INFINITY, 0xFF, 1, &nearest, 1), MESHCAST_ERROR_USAGE,
               "never committed");
  meshcast_caster_options options;
  meshcast_caster_options_init(&options);
  options.backend = MESHCAST_BACKEND_CPU;
  meshcast_caster* caster = NULL;
  EXPECT_OK(meshcast_caster_create(NULL, &options, &caster));
  meshcast_ticket ticket;
  EXPECT_FAILS(meshcast_caster_submit_scene(caster, scene, &ray, 1, NULL, &ticket), MESHCAST_ERROR_USAGE,
               "never committed");
  EXPECT_OK(meshcast_scene_cast(empty, &ray, 1, NULL, &hit, 1, NULL));
  CHECK(hit.instance == MESHCAST_NO_HIT);
  EXPECT_OK(meshcast_scene_commit(scene));
  EXPECT_OK(meshcast_scene_cast(scene, &ray, 1, NULL, &hit, 1, NULL));
  CHECK(hit.instance == instance.index && hit.triangle == 3 && hit.t == 1.0f);
  EXPECT_OK(meshcast_caster_release(caster));
  EXPECT_OK(meshcast_scene_release(empty));
  EXPECT_OK(meshcast_scene_release(scene));
  EXPECT_OK(meshcast_blob_release(blob));
}

/* Ids are good with the scene that gave them alone: another scene's mesh
 * or instance is refused by name, even where its index is one this scene
 * also gave, as is a default-made (zeroed) id and a reserved field set. */
static void test_ids_of_another_scene(void) {
  meshcast_blob* blob = build(NULL);
  meshcast_instance_id mine, theirs;
  meshcast_scene* scene = scene_of_one(blob, &mine);
  meshcast_scene* other = scene_of_one(blob, &theirs);
  CHECK(mine.index == theirs.index && mine.scene != theirs.scene);
  meshcast_mesh_id their_mesh;
  EXPECT_OK(meshcast_scene_add_mesh(other, blob, &their_mesh));
  meshcast_instance_id added;
  EXPECT_FAILS(meshcast_scene_add_instance(scene, their_mesh, NULL, 0xFF, 0, &added), MESHCAST_ERROR_USAGE,
               "was given by another scene");
  meshcast_transform t;
  meshcast_transform_identity(&t);
  EXPECT_FAILS(meshcast_scene_set_transform(scene, theirs, &t), MESHCAST_ERROR_USAGE, "another scene");
  EXPECT_FAILS(meshcast_scene_set_mask(scene, theirs, 1), MESHCAST_ERROR_USAGE, "another scene");
  EXPECT_FAILS(meshcast_scene_set_flip_facing(scene, theirs, 1), MESHCAST_ERROR_USAGE, "another scene");
  EXPECT_FAILS(meshcast_scene_set_enabled(scene, theirs, 0), MESHCAST_ERROR_USAGE, "another scene");
  EXPECT_FAILS(meshcast_scene_remove_instance(scene, theirs), MESHCAST_ERROR_USAGE, "another scene");
  CHECK(strstr(meshcast_last_error(), "meshcast_scene_remove_instance: instance 0 was given by") != NULL);
  meshcast_instance_id zeroed = {0, 0, 0};
  EXPECT_FAILS(meshcast_scene_set_mask(scene, zeroed, 1), MESHCAST_ERROR_USAGE, "no scene");
  meshcast_instance_id reserved = mine;
  reserved.reserved = 1;
  EXPECT_FAILS(meshcast_scene_set_mask(scene, reserved, 1), MESHCAST_ERROR_USAGE, "instance.reserved 1");
  /* Nothing refused changed either scene: both still answer their one instance. */
  EXPECT_OK(meshcast_scene_commit(scene));
  meshcast_ray_d ray = {{0.25, 0.75, 2}, {0, 0, -1}, INFINITY, 0, 0};
  meshcast_scene_hit hit;
  EXPECT_OK(meshcast_scene_cast(scene, &ray, 1, NULL, &hit, 1, NULL));
  CHECK(hit.instance == mine.index && hit.triangle == 3);
  EXPECT_OK(meshcast_scene_remove_instance(other, theirs));
  EXPECT_OK(meshcast_scene_remove_instance(scene, mine));
  EXPECT_OK(meshcast_scene_release(other));
  EXPECT_OK(meshcast_scene_release(scene));
  EXPECT_OK(meshcast_blob_release(blob));
}

/* Messages in the C API's own words: its names (options->frames, not a C++
 * type's), a blob longer than its header says with both sizes, a mesh too
 * large for the address space said so, an empty path refused as one. */
static void test_messages(void) {
  meshcast_blob* blob = build(NULL);
  meshcast_blob* none = NULL;
  meshcast_caster_options options;
  meshcast_caster_options_init(&options);
  options.backend = MESHCAST_BACKEND_CPU;
  options.frames = 0;
  meshcast_caster* caster = NULL;
  EXPECT_FAILS(meshcast_caster_create(NULL, &options, &caster), MESHCAST_ERROR_USAGE, "options->frames 0");
  CHECK(strstr(meshcast_last_error(), "::") == NULL);
  options.frames = 4;
  options.threads = 5000;
  EXPECT_FAILS(meshcast_caster_create(NULL, &options, &caster), MESHCAST_ERROR_USAGE, "options->threads 5000");
  CHECK(strstr(meshcast_last_error(), "::") == NULL);
  meshcast_scene* scene = NULL;
  EXPECT_OK(meshcast_scene_create(&scene));
  meshcast_instance_id instance;
  meshcast_mesh_id mesh;
  EXPECT_OK(meshcast_scene_add_mesh(scene, blob, &mesh));
  meshcast_mesh_id unknown = mesh;
  unknown.index = 42;
  EXPECT_FAILS(meshcast_scene_add_instance(scene, unknown, NULL, 0xFF, 0, &instance), MESHCAST_ERROR_USAGE,
               "mesh 42");
  CHECK(strstr(meshcast_last_error(), "::") == NULL);
  meshcast_transform flat;
  meshcast_transform_identity(&flat);
  flat.rotation_scale[8] = 0;
  EXPECT_FAILS(meshcast_scene_add_instance(scene, mesh, &flat, 0xFF, 0, &instance), MESHCAST_ERROR_USAGE,
               "not invertible");
  CHECK(strstr(meshcast_last_error(), "::") == NULL);
  EXPECT_OK(meshcast_scene_release(scene));

  /* Longer than its header says: both sizes. */
  const void* bytes = NULL;
  uint64_t size = 0;
  EXPECT_OK(meshcast_blob_bytes(blob, &bytes, &size));
  unsigned char longer[4096 + 8];
  CHECK(size + 8 <= sizeof longer);
  memcpy(longer, bytes, size);
  memset(longer + size, 0, 8);
  char words[128];
  snprintf(words, sizeof words, "is %llu bytes, longer than the %llu bytes its header says",
           (unsigned long long)(size + 8), (unsigned long long)size);
  EXPECT_FAILS(meshcast_blob_from_memory(longer, size + 8, MESHCAST_MEMORY_COPY, "longer", &none), MESHCAST_ERROR_INPUT,
               words);
  CHECK(strstr(meshcast_last_error(), "truncated") == NULL);

  /* A stride times a count past the address space, vertices and triangles. */
  meshcast_mesh mesh_of = two_squares();
  mesh_of.vertex_stride = UINT64_MAX / 4;
  EXPECT_FAILS(meshcast_blob_build(&mesh_of, NULL, &none), MESHCAST_ERROR_INPUT,
               "8 vertices of vertex stride 4611686018427387903 bytes do not fit in this process's address space");
  mesh_of = two_squares();
  mesh_of.triangle_stride = UINT64_MAX / 2;
  EXPECT_FAILS(meshcast_blob_build(&mesh_of, NULL, &none), MESHCAST_ERROR_INPUT,
               "4 triangles of triangle stride 9223372036854775807 bytes do not fit in this process's address space");

  /* An empty path: refused as one, nothing about how files are written. */
  EXPECT_FAILS(meshcast_blob_save(blob, ""), MESHCAST_ERROR_OUTPUT, "the path is empty");
  CHECK(strstr(meshcast_last_error(), "rename") == NULL);
  EXPECT_OK(meshcast_blob_release(blob));
}

static void test_casters(void) {
  meshcast_blob* blob = build(NULL);
  meshcast_caster_options options;
  meshcast_caster_options_init(&options);
  options.backend = MESHCAST_BACKEND_CPU;
  options.threads = 2;
  meshcast_caster* caster = NULL;
  meshcast_caster* other = NULL;
  EXPECT_OK(meshcast_caster_create(blob, &options, &caster));
  EXPECT_OK(meshcast_caster_create(blob, &options, &other));
  EXPECT_OK(meshcast_blob_release(blob)); /* the casters keep its bytes */
  meshcast_ray rays[2] = {down_at(0.75f, 0.25f), down_at(0.25f, 0.75f)};
  meshcast_ticket ticket;
  EXPECT_OK(meshcast_caster_submit(caster, rays, 2, NULL, &ticket));
  uint32_t ready = 2;
  EXPECT_OK(meshcast_caster_poll(caster, &ticket, &ready));
  CHECK(ready == 0 || ready == 1);
  EXPECT_FAILS(meshcast_caster_wait(other, &ticket, NULL, 0, NULL), MESHCAST_ERROR_USAGE, "");
  meshcast_hit hits[2];
  meshcast_batch_record record;
  EXPECT_OK(meshcast_caster_wait(caster, &ticket, hits, 2, &record));
  CHECK(hits[0].triangle == 2 && hits[1].triangle == 3 && record.rays == 2 && record.ran_on == MESHCAST_BACKEND_CPU);
  EXPECT_FAILS(meshcast_caster_wait(caster, &ticket, hits, 2, NULL), MESHCAST_ERROR_USAGE, "");
  /* Written in place. */
  meshcast_open_batch batch;
  EXPECT_OK(meshcast_caster_open(caster, 4, NULL, &batch));
  CHECK(batch.ray_count == 4 && batch.rays != NULL);
  batch.rays[0] = down_at(0.25f, 0.75f);
  EXPECT_FAILS(meshcast_caster_submit_open(caster, &batch, 5, &ticket), MESHCAST_ERROR_USAGE, "written 5");
  EXPECT_OK(meshcast_caster_submit_open(caster, &batch, 1, &ticket));
  EXPECT_OK(meshcast_caster_wait(caster, &ticket, hits, 1, NULL));
  CHECK(hits[0].triangle == 3);
  uint32_t backend = 9;
  const char* why = NULL;
  EXPECT_OK(meshcast_caster_backend(caster, 1000, &backend, &why));
  CHECK(backend == MESHCAST_BACKEND_CPU && why != NULL && strlen(why) > 0);
  /* Scene batches. */
  meshcast_blob* again = build(NULL);
  meshcast_instance_id instance;
  meshcast_scene* scene = scene_of_one(again, &instance);
  meshcast_caster* scenes = NULL;
  EXPECT_OK(meshcast_caster_create(NULL, &options, &scenes));
  meshcast_ray_d ray = {{0.25, 0.75, 2}, {0, 0, -1}, INFINITY, 0, 0};
  EXPECT_OK(meshcast_caster_submit_scene(scenes, scene, &ray, 1, NULL, &ticket));
  EXPECT_OK(meshcast_scene_release(scene)); /* the batch keeps what it walks */
  EXPECT_OK(meshcast_blob_release(again));
  meshcast_scene_hit hit;
  EXPECT_OK(meshcast_caster_wait_scene(scenes, &ticket, &hit, 1, NULL));
  CHECK(hit.instance == instance.index && hit.triangle == 3 && hit.t == 1.0f);
  EXPECT_FAILS(meshcast_caster_submit(scenes, rays, 1, NULL, &ticket), MESHCAST_ERROR_USAGE, "");
  EXPECT_OK(meshcast_caster_release(other));
  options.frames = 0;
  EXPECT_FAILS(meshcast_caster_create(NULL, &options, &other), MESHCAST_ERROR_USAGE, "frames");
  CHECK(other == NULL);
  options.struct_size = 1;
  EXPECT_FAILS(meshcast_caster_create(NULL, &options, &other), MESHCAST_ERROR_USAGE, "struct_size 1");
  EXPECT_OK(meshcast_caster_release(scenes));
  EXPECT_OK(meshcast_caster_release(caster));
  EXPECT_FAILS(meshcast_caster_release(caster), MESHCAST_ERROR_USAGE, "released already");
}

/* A handle released while another thread casts through it: the cast in
 * flight keeps what it reads until it returns (a mapped blob's pages
 * included), and the thread's next call is refused. Large batches, so the
 * release lands inside a cast; three rounds of each kind. */
enum { kGrid = 256, kRaceRays = 1 << 15 };
typedef struct racer {
  int kind; /* 0 a blob's cast, 1 a scene's, 2 a caster's batch */
  void* handle;
  const meshcast_ray* rays;
  const meshcast_ray_d* scene_rays;
  meshcast_hit* hits;
  meshcast_scene_hit* scene_hits;
  atomic_int casts;
  atomic_int ended;
  meshcast_status refused;
  char message[512];
} racer;

static int cast_until_refused(void* arg) {
  racer* r = arg;
  for (;;) {
    meshcast_status status;
    if (r->kind == 0) {
      status = meshcast_blob_cast(r->handle, r->rays, kRaceRays, NULL, r->hits, kRaceRays, NULL);
    } else if (r->kind == 1) {
      status = meshcast_scene_cast(r->handle, r->scene_rays, kRaceRays, NULL, r->scene_hits, kRaceRays, NULL);
    } else {
      meshcast_ticket ticket;
      status = meshcast_caster_submit(r->handle, r->rays, kRaceRays, NULL, &ticket);
      if (status == MESHCAST_OK) status = meshcast_caster_wait(r->handle, &ticket, r->hits, kRaceRays, NULL);
    }
    if (status != MESHCAST_OK) {
      r->refused = status;
      snprintf(r->message, sizeof r->message, "%s", meshcast_last_error());
      atomic_store(&r->ended, 1);
      return 0;
    }
    atomic_fetch_add(&r->casts, 1);
  }
}

static void race_release(racer* r) {
  atomic_store(&r->casts, 0);
  atomic_store(&r->ended, 0);
  r->refused = MESHCAST_OK;
  r->message[0] = 0;
  thrd_t thread;
  CHECK(thrd_create(&thread, cast_until_refused, r) == thrd_success);
  /* Released during its second cast (unless the first failed: reported below). */
  while (atomic_load(&r->casts) < 1 && !atomic_load(&r->ended)) thrd_yield();
  if (r->kind == 0) EXPECT_OK(meshcast_blob_release(r->handle));
  else if (r->kind == 1) EXPECT_OK(meshcast_scene_release(r->handle));
  else EXPECT_OK(meshcast_caster_release(r->handle));
  CHECK(thrd_join(thread, NULL) == thrd_success);
  if (r->refused != MESHCAST_ERROR_USAGE || !strstr(r->message, "released already")) {
    fprintf(stderr, "%s:%d: the casting thread ended with %s: \"%s\"\n", __FILE__, __LINE__,
            meshcast_status_name(r->refused), r->message);
    ++failures;
  }
  CHECK(r->kind == 1 ? r->scene_hits[0].t == 1.0f : r->hits[0].t == 1.0f); /* its last whole cast */
}

static void test_release_while_casting(void) {
  /* A grid of kGrid x kGrid squares at z = 0 over [0, 1]^2, mapped from a file. */
  const int side = kGrid + 1;
  float* vertices = malloc(sizeof(float) * 3 * side * side);
  uint32_t* indices = malloc(sizeof(uint32_t) * 6 * kGrid * kGrid);
  meshcast_ray* rays = malloc(sizeof(meshcast_ray) * kRaceRays);
  meshcast_ray_d* scene_rays = malloc(sizeof(meshcast_ray_d) * kRaceRays);
  meshcast_hit* hits = malloc(sizeof(meshcast_hit) * kRaceRays);
  meshcast_scene_hit* scene_hits = malloc(sizeof(meshcast_scene_hit) * kRaceRays);
  CHECK(vertices && indices && rays && scene_rays && hits && scene_hits);
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      float* v = vertices + 3 * (y * side + x);
      v[0] = (float)x / kGrid, v[1] = (float)y / kGrid, v[2] = 0;
    }
  for (int y = 0; y < kGrid; ++y)
    for (int x = 0; x < kGrid; ++x) {
      uint32_t* t = indices + 6 * (y * kGrid + x);
      const uint32_t a = (uint32_t)(y * side + x);
      t[0] = a, t[1] = a + 1, t[2] = a + side + 1, t[3] = a, t[4] = a + side + 1, t[5] = a + side;
    }
  for (int i = 0; i < kRaceRays; ++i) {
    const unsigned k = (unsigned)i;
    const float x = (float)((k * 7919u) % 1000u + 0.5) / 1000, y = (float)((k * 104729u) % 997u + 0.5) / 997;
    meshcast_ray r = {{x, y, 1}, {0, 0, -1}, INFINITY, 0};
    meshcast_ray_d d = {{x, y, 1}, {0, 0, -1}, INFINITY, 0, 0};
    rays[i] = r, scene_rays[i] = d;
  }
  meshcast_mesh mesh;
  meshcast_mesh_init(&mesh);
  mesh.vertices = vertices, mesh.vertex_count = (uint64_t)side * side;
  mesh.indices = indices, mesh.triangle_count = 2ull * kGrid * kGrid;
  meshcast_blob* built = NULL;
  EXPECT_OK(meshcast_blob_build(&mesh, NULL, &built));
  const char* path = "c_api_race.blob";
  EXPECT_OK(meshcast_blob_save(built, path));
  EXPECT_OK(meshcast_blob_release(built));
  meshcast_caster_options options;
  meshcast_caster_options_init(&options);
  options.backend = MESHCAST_BACKEND_CPU;
  options.threads = 1;
  for (int round = 0; round < 3; ++round)
    for (int kind = 0; kind < 3; ++kind) {
      racer r = {.kind = kind, .rays = rays, .scene_rays = scene_rays, .hits = hits, .scene_hits = scene_hits};
      meshcast_blob* blob = NULL;
      EXPECT_OK(meshcast_blob_load(path, MESHCAST_LOAD_MAP, &blob));
      if (kind == 0) {
        r.handle = blob;
      } else if (kind == 1) {
        meshcast_instance_id instance;
        meshcast_scene* scene = scene_of_one(blob, &instance);
        EXPECT_OK(meshcast_blob_release(blob));
        r.handle = scene;
      } else {
        meshcast_caster* caster = NULL;
        EXPECT_OK(meshcast_caster_create(blob, &options, &caster));
        EXPECT_OK(meshcast_blob_release(blob));
        r.handle = caster;
      }
      race_release(&r);
    }
  remove(path);
  free(vertices), free(indices), free(rays), free(scene_rays), free(hits), free(scene_hits);
}

int main(void) {
  test_version_and_errors();
  test_callback_calls();
  test_blob_casts(NULL);
  test_blob_casts("OctTreeCompressed/ClusterFloat3SOA8");
  test_blob_casts("AABBTree/Float3");
  test_build_load_save();
  test_scene();
  test_scene_before_commit();
  test_ids_of_another_scene();
  test_messages();
  test_casters();
  test_release_while_casting();
  if (failures) {
    fprintf(stderr, "%d checks failed\n", failures);
    return 1;
  }
  printf("every check of the C API passed\n");
  return 0;
}
