//! The C API of meshcast (`include/meshcast/meshcast_c.h`), declared by
//! hand: every struct, constant and function of the header, in its order,
//! with the C types spelled as Rust's. `tests/header.rs` reads the header
//! and checks each declaration here against it (names, fields, parameter
//! types, sizes). docs/c-api.md states the rules (ownership, threads,
//! errors, versions); the `meshcast` crate wraps them safely.
#![allow(non_camel_case_types)]

use std::os::raw::{c_char, c_void};

pub const MESHCAST_C_API_VERSION_MAJOR: u32 = 2;
pub const MESHCAST_C_API_VERSION_MINOR: u32 = 0;
pub const MESHCAST_C_API_VERSION: u32 = (MESHCAST_C_API_VERSION_MAJOR << 16) | MESHCAST_C_API_VERSION_MINOR;

pub type meshcast_status = u32;
pub const MESHCAST_OK: meshcast_status = 0;
pub const MESHCAST_ERROR_INPUT: meshcast_status = 1;
pub const MESHCAST_ERROR_USAGE: meshcast_status = 2;
pub const MESHCAST_ERROR_OUTPUT: meshcast_status = 3;
pub const MESHCAST_ERROR_GPU: meshcast_status = 4;
pub const MESHCAST_ERROR_OUT_OF_MEMORY: meshcast_status = 5;
pub const MESHCAST_ERROR_INTERNAL: meshcast_status = 6;

pub type meshcast_error_callback = Option<unsafe extern "C" fn(user: *mut c_void, status: meshcast_status, message: *const c_char)>;

pub const MESHCAST_NO_HIT: u32 = 0xFFFF_FFFF;

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct meshcast_ray {
    pub org: [f32; 3],
    pub dir: [f32; 3],
    pub tmax: f32,
    pub tmin: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct meshcast_hit {
    pub t: f32,
    pub triangle: u32,
    pub u: f32,
    pub v: f32,
    pub point: [f32; 3],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct meshcast_ray_d {
    pub org: [f64; 3],
    pub dir: [f32; 3],
    pub tmax: f32,
    pub tmin: f32,
    pub reserved: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct meshcast_scene_hit {
    pub t: f32,
    pub instance: u32,
    pub triangle: u32,
    pub u: f32,
    pub v: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct meshcast_closest_point {
    pub point: [f32; 3],
    pub distance: f32,
    pub triangle: u32,
    pub u: f32,
    pub v: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct meshcast_scene_closest_point {
    pub point: [f64; 3],
    pub distance: f64,
    pub instance: u32,
    pub triangle: u32,
    pub u: f32,
    pub v: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct meshcast_mesh {
    pub struct_size: u32,
    pub index_bits: u32,
    pub vertices: *const f32,
    pub vertex_count: u64,
    pub vertex_stride: u64,
    pub indices: *const c_void,
    pub triangle_count: u64,
    pub triangle_stride: u64,
}

#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct meshcast_build_options {
    pub struct_size: u32,
    pub threads: u32,
    pub layout: *const c_char,
    pub name: *const c_char,
    pub max_bytes_per_triangle: f64,
    pub max_error: f64,
    pub goal_memory: u32,
    pub triangle_ids: u32,
}

#[repr(C)]
pub struct meshcast_blob {
    _opaque: [u8; 0],
}

pub const MESHCAST_LOAD_MAP: u32 = 1;
pub const MESHCAST_MEMORY_COPY: u32 = 0;
pub const MESHCAST_MEMORY_BORROW: u32 = 1;

#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct meshcast_blob_info {
    pub struct_size: u32,
    pub triangle_count: u32,
    pub bytes: u64,
    pub layout: *const c_char,
    pub error_bound: f64,
}

pub const MESHCAST_CLOSEST: u32 = 0;
pub const MESHCAST_ANY: u32 = 1;
pub const MESHCAST_CULL_NONE: u32 = 0;
pub const MESHCAST_CULL_BACK: u32 = 1;
pub const MESHCAST_CULL_FRONT: u32 = 2;
pub const MESHCAST_HIT_UV: u32 = 1;
pub const MESHCAST_HIT_POINT: u32 = 2;

#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct meshcast_query {
    pub struct_size: u32,
    pub kind: u32,
    pub cull: u32,
    pub outputs: u32,
    pub mask: u32,
    pub threads: u32,
}

#[repr(C)]
pub struct meshcast_scene {
    _opaque: [u8; 0],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct meshcast_transform {
    pub rotation_scale: [f32; 9],
    pub translation: [f64; 3],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct meshcast_mesh_id {
    pub scene: u64,
    pub index: u32,
    pub reserved: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct meshcast_instance_id {
    pub scene: u64,
    pub index: u32,
    pub reserved: u32,
}

#[repr(C)]
pub struct meshcast_caster {
    _opaque: [u8; 0],
}

pub const MESHCAST_BACKEND_CPU: u32 = 0;
pub const MESHCAST_BACKEND_VULKAN: u32 = 1;
pub const MESHCAST_BACKEND_AUTOMATIC: u32 = 2;

#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct meshcast_caster_options {
    pub struct_size: u32,
    pub backend: u32,
    pub frames: u32,
    pub threads: u32,
    pub outputs: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct meshcast_ticket {
    pub id: u64,
    pub caster: u64,
    pub slot: u32,
    pub reserved: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct meshcast_open_batch {
    pub ticket: meshcast_ticket,
    pub rays: *mut meshcast_ray,
    pub ray_count: u64,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct meshcast_batch_record {
    pub ran_on: u32,
    pub rays: u32,
    pub latency_ms: f64,
    pub device_ms: f64,
    pub cpu_ms: f64,
}

extern "C" {
    pub fn meshcast_api_version() -> u32;
    pub fn meshcast_last_error() -> *const c_char;
    pub fn meshcast_status_name(status: meshcast_status) -> *const c_char;
    pub fn meshcast_set_error_callback(callback: meshcast_error_callback, user: *mut c_void);
    pub fn meshcast_mesh_init(mesh: *mut meshcast_mesh);
    pub fn meshcast_build_options_init(options: *mut meshcast_build_options);
    pub fn meshcast_blob_build(mesh: *const meshcast_mesh, options: *const meshcast_build_options,
                               out: *mut *mut meshcast_blob) -> meshcast_status;
    pub fn meshcast_blob_load(path: *const c_char, flags: u32, out: *mut *mut meshcast_blob) -> meshcast_status;
    pub fn meshcast_blob_from_memory(bytes: *const c_void, size: u64, flags: u32, name: *const c_char,
                                     out: *mut *mut meshcast_blob) -> meshcast_status;
    pub fn meshcast_blob_save(blob: *const meshcast_blob, path: *const c_char) -> meshcast_status;
    pub fn meshcast_blob_bytes(blob: *const meshcast_blob, bytes: *mut *const c_void, size: *mut u64) -> meshcast_status;
    pub fn meshcast_blob_info_get(blob: *const meshcast_blob, info: *mut meshcast_blob_info) -> meshcast_status;
    pub fn meshcast_blob_release(blob: *mut meshcast_blob) -> meshcast_status;
    pub fn meshcast_query_init(query: *mut meshcast_query);
    pub fn meshcast_blob_cast(blob: *const meshcast_blob, rays: *const meshcast_ray, ray_count: u64,
                              query: *const meshcast_query, hits: *mut meshcast_hit, hit_capacity: u64,
                              not_walkable: *mut u64) -> meshcast_status;
    pub fn meshcast_blob_cast_all(blob: *const meshcast_blob, rays: *const meshcast_ray, ray_count: u64,
                                  query: *const meshcast_query, max_hits: u32, found: *mut u32, hits: *mut meshcast_hit,
                                  hit_capacity: u64, not_walkable: *mut u64) -> meshcast_status;
    pub fn meshcast_blob_closest_points(blob: *const meshcast_blob, points: *const f32, point_count: u64,
                                        max_distance: f32, threads: u32, out: *mut meshcast_closest_point,
                                        out_capacity: u64) -> meshcast_status;
    pub fn meshcast_transform_identity(transform: *mut meshcast_transform);
    pub fn meshcast_scene_create(out: *mut *mut meshcast_scene) -> meshcast_status;
    pub fn meshcast_scene_add_mesh(scene: *mut meshcast_scene, blob: *const meshcast_blob,
                                   mesh: *mut meshcast_mesh_id) -> meshcast_status;
    pub fn meshcast_scene_add_instance(scene: *mut meshcast_scene, mesh: meshcast_mesh_id,
                                       transform: *const meshcast_transform, mask: u32, flip_facing: u32,
                                       instance: *mut meshcast_instance_id) -> meshcast_status;
    pub fn meshcast_scene_set_transform(scene: *mut meshcast_scene, instance: meshcast_instance_id,
                                        transform: *const meshcast_transform) -> meshcast_status;
    pub fn meshcast_scene_set_mask(scene: *mut meshcast_scene, instance: meshcast_instance_id, mask: u32)
                                   -> meshcast_status;
    pub fn meshcast_scene_set_flip_facing(scene: *mut meshcast_scene, instance: meshcast_instance_id,
                                          flip_facing: u32) -> meshcast_status;
    pub fn meshcast_scene_set_enabled(scene: *mut meshcast_scene, instance: meshcast_instance_id, enabled: u32)
                                      -> meshcast_status;
    pub fn meshcast_scene_remove_instance(scene: *mut meshcast_scene, instance: meshcast_instance_id)
                                          -> meshcast_status;
    pub fn meshcast_scene_commit(scene: *mut meshcast_scene) -> meshcast_status;
    pub fn meshcast_scene_cast(scene: *const meshcast_scene, rays: *const meshcast_ray_d, ray_count: u64,
                               query: *const meshcast_query, hits: *mut meshcast_scene_hit, hit_capacity: u64,
                               not_walkable: *mut u64) -> meshcast_status;
    pub fn meshcast_scene_cast_all(scene: *const meshcast_scene, rays: *const meshcast_ray_d, ray_count: u64,
                                   query: *const meshcast_query, max_hits: u32, found: *mut u32,
                                   hits: *mut meshcast_scene_hit, hit_capacity: u64, not_walkable: *mut u64)
                                   -> meshcast_status;
    pub fn meshcast_scene_closest_points(scene: *const meshcast_scene, points: *const f64, point_count: u64,
                                         max_distance: f64, mask: u32, threads: u32,
                                         out: *mut meshcast_scene_closest_point, out_capacity: u64) -> meshcast_status;
    pub fn meshcast_scene_release(scene: *mut meshcast_scene) -> meshcast_status;
    pub fn meshcast_caster_options_init(options: *mut meshcast_caster_options);
    pub fn meshcast_caster_create(blob: *const meshcast_blob, options: *const meshcast_caster_options,
                                  out: *mut *mut meshcast_caster) -> meshcast_status;
    pub fn meshcast_caster_submit(caster: *mut meshcast_caster, rays: *const meshcast_ray, ray_count: u64,
                                  query: *const meshcast_query, ticket: *mut meshcast_ticket) -> meshcast_status;
    pub fn meshcast_caster_open(caster: *mut meshcast_caster, ray_count: u32, query: *const meshcast_query,
                                batch: *mut meshcast_open_batch) -> meshcast_status;
    pub fn meshcast_caster_submit_open(caster: *mut meshcast_caster, batch: *const meshcast_open_batch, written: u64,
                                       ticket: *mut meshcast_ticket) -> meshcast_status;
    pub fn meshcast_caster_submit_scene(caster: *mut meshcast_caster, scene: *const meshcast_scene,
                                        rays: *const meshcast_ray_d, ray_count: u64, query: *const meshcast_query,
                                        ticket: *mut meshcast_ticket) -> meshcast_status;
    pub fn meshcast_caster_poll(caster: *mut meshcast_caster, ticket: *const meshcast_ticket, ready: *mut u32)
                                -> meshcast_status;
    pub fn meshcast_caster_wait(caster: *mut meshcast_caster, ticket: *const meshcast_ticket, hits: *mut meshcast_hit,
                                hit_capacity: u64, record: *mut meshcast_batch_record) -> meshcast_status;
    pub fn meshcast_caster_wait_scene(caster: *mut meshcast_caster, ticket: *const meshcast_ticket,
                                      hits: *mut meshcast_scene_hit, hit_capacity: u64,
                                      record: *mut meshcast_batch_record) -> meshcast_status;
    pub fn meshcast_caster_backend(caster: *mut meshcast_caster, ray_count: u32, backend: *mut u32,
                                   why: *mut *const c_char) -> meshcast_status;
    pub fn meshcast_caster_release(caster: *mut meshcast_caster) -> meshcast_status;
}
