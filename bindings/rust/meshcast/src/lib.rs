//! meshcast from Rust: ray casts, every hit and nearest points against
//! static triangle meshes, from one small blob the CPU (and a GPU) read.
//! Safe handles over the C API (`meshcast-sys`): each frees itself on drop,
//! batches are slices of the library's own records (read and written in
//! place), and a failed call is an `Err` carrying the library's status and
//! message.
//!
//! ```no_run
//! let vertices = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0];
//! let floor = meshcast::Blob::build(&vertices, &[0, 1, 2, 0, 2, 3], None).unwrap();
//! let rays = [meshcast::ray([0.25, 0.75, 1.0], [0.0, 0.0, -1.0])];
//! let mut hits = [meshcast::Hit::default(); 1];
//! floor.cast(&rays, &mut hits, &meshcast::Query::default()).unwrap();
//! assert_eq!(hits[0].triangle, 1);
//! ```
use std::ffi::{CStr, CString};
use std::fmt;
use std::os::raw::c_char;
use std::ptr;

use meshcast_sys as sys;

pub use sys::meshcast_closest_point as ClosestPoint;
pub use sys::meshcast_hit as Hit;
pub use sys::meshcast_instance_id as InstanceId;
pub use sys::meshcast_mesh_id as MeshId;
pub use sys::meshcast_ray as Ray;
pub use sys::meshcast_ray_d as RayD;
pub use sys::meshcast_scene_closest_point as SceneClosestPoint;
pub use sys::meshcast_scene_hit as SceneHit;
pub use sys::meshcast_ticket as Ticket;
pub use sys::MESHCAST_NO_HIT as NO_HIT;

/// What a failed call returns: the library's status and its message, which
/// names the input and the limit it broke.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Error {
    pub status: u32,
    pub message: String,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Error {}

pub type Result<T> = std::result::Result<T, Error>;

fn text(p: *const c_char) -> String {
    if p.is_null() {
        return String::new();
    }
    unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
}

fn check(status: sys::meshcast_status) -> Result<()> {
    if status == sys::MESHCAST_OK {
        Ok(())
    } else {
        Err(Error { status, message: text(unsafe { sys::meshcast_last_error() }) })
    }
}

/// A usage error found before the call (a slice too short, a NUL in a string).
fn usage(message: String) -> Error {
    Error { status: sys::MESHCAST_ERROR_USAGE, message }
}

fn c_string(s: &str, what: &str) -> Result<CString> {
    CString::new(s).map_err(|_| usage(format!("{} holds a NUL byte", what)))
}

fn room(len: usize, needed: usize, what: &str) -> Result<()> {
    if len < needed {
        return Err(usage(format!("{} holds {} answers, fewer than the {} asked for", what, len, needed)));
    }
    Ok(())
}

/// The library's C API version (major << 16 | minor).
pub fn api_version() -> u32 {
    unsafe { sys::meshcast_api_version() }
}

/// A ray from `org` along `dir`, over [0, infinity).
pub fn ray(org: [f32; 3], dir: [f32; 3]) -> Ray {
    Ray { org, dir, tmax: f32::INFINITY, tmin: 0.0 }
}

/// A scene ray from a double-precision origin, over [0, infinity).
pub fn ray_d(org: [f64; 3], dir: [f32; 3]) -> RayD {
    RayD { org, dir, tmax: f32::INFINITY, tmin: 0.0, reserved: 0 }
}

/// Which hit, which faces, what each hit carries, which instances, how
/// many threads (1: this thread; 0: every core).
#[derive(Clone, Copy, Debug)]
pub struct Query {
    pub any: bool,
    pub cull: u32,
    pub outputs: u32,
    pub mask: u8,
    pub threads: u32,
}

impl Default for Query {
    fn default() -> Query {
        Query { any: false, cull: sys::MESHCAST_CULL_NONE, outputs: 0, mask: 0xFF, threads: 1 }
    }
}

impl Query {
    fn raw(&self) -> sys::meshcast_query {
        let mut q = sys::meshcast_query::default();
        unsafe { sys::meshcast_query_init(&mut q) };
        q.kind = if self.any { sys::MESHCAST_ANY } else { sys::MESHCAST_CLOSEST };
        q.cull = self.cull;
        q.outputs = self.outputs;
        q.mask = self.mask as u32;
        q.threads = self.threads;
        q
    }
}

/// A mesh's blob.
pub struct Blob {
    raw: *mut sys::meshcast_blob,
}

// The library's blobs are read-only once made: any thread may cast through one.
unsafe impl Send for Blob {}
unsafe impl Sync for Blob {}

impl Blob {
    /// Built from x, y, z floats and three indices a triangle; `layout`
    /// "TREE/TRIANGLES", "auto", or None for the recommended one.
    pub fn build(vertices: &[f32], indices: &[u32], layout: Option<&str>) -> Result<Blob> {
        if vertices.len() % 3 != 0 || indices.len() % 3 != 0 {
            return Err(usage("vertices and indices come in threes".to_string()));
        }
        let mut mesh = sys::meshcast_mesh {
            struct_size: 0,
            index_bits: 0,
            vertices: ptr::null(),
            vertex_count: 0,
            vertex_stride: 0,
            indices: ptr::null(),
            triangle_count: 0,
            triangle_stride: 0,
        };
        unsafe { sys::meshcast_mesh_init(&mut mesh) };
        mesh.vertices = vertices.as_ptr();
        mesh.vertex_count = (vertices.len() / 3) as u64;
        mesh.indices = indices.as_ptr() as *const _;
        mesh.triangle_count = (indices.len() / 3) as u64;
        let mut options = sys::meshcast_build_options {
            struct_size: 0,
            threads: 0,
            layout: ptr::null(),
            name: ptr::null(),
            max_bytes_per_triangle: 0.0,
            max_error: 0.0,
            goal_memory: 0,
            triangle_ids: 0,
        };
        unsafe { sys::meshcast_build_options_init(&mut options) };
        let layout = match layout {
            Some(l) => Some(c_string(l, "layout")?),
            None => None,
        };
        options.layout = layout.as_ref().map_or(ptr::null(), |l| l.as_ptr());
        let mut raw = ptr::null_mut();
        check(unsafe { sys::meshcast_blob_build(&mesh, &options, &mut raw) })?;
        Ok(Blob { raw })
    }

    /// A blob file, read whole and validated: later changes to the file
    /// change nothing.
    ///
    /// A mapped load is [`Blob::map`], which is `unsafe`; this one takes no
    /// flag for it:
    ///
    /// ```compile_fail
    /// let blob = meshcast::Blob::load("terrain.blob", true);
    /// ```
    pub fn load(path: &str) -> Result<Blob> {
        Self::load_with(path, 0)
    }

    /// A blob file mapped read-only, validated once: its pages are shared
    /// with every other process mapping it, and never copied.
    ///
    /// # Safety
    ///
    /// The file must not be truncated or rewritten in place for as long as
    /// the blob, or any scene or caster it was given to, lives: the bytes
    /// are read where the file lies, so a truncated file ends the process
    /// with SIGBUS at the next read of a page past its new end (`bytes()`
    /// or a cast), and one rewritten in place is read unvalidated. Replacing
    /// the file by renaming a new one over its name (as [`Blob::save`]
    /// does) is safe: the mapping keeps the old file.
    ///
    /// Called outside an `unsafe` block it does not compile:
    ///
    /// ```compile_fail
    /// let blob = meshcast::Blob::map("terrain.blob");
    /// ```
    ///
    /// ```no_run
    /// // Nothing truncates or rewrites terrain.blob while `blob` lives.
    /// let blob = unsafe { meshcast::Blob::map("terrain.blob") }.unwrap();
    /// ```
    pub unsafe fn map(path: &str) -> Result<Blob> {
        Self::load_with(path, sys::MESHCAST_LOAD_MAP)
    }

    fn load_with(path: &str, flags: u32) -> Result<Blob> {
        let path = c_string(path, "path")?;
        let mut raw = ptr::null_mut();
        check(unsafe { sys::meshcast_blob_load(path.as_ptr(), flags, &mut raw) })?;
        Ok(Blob { raw })
    }

    /// A blob's bytes, copied and validated.
    pub fn from_bytes(bytes: &[u8]) -> Result<Blob> {
        let mut raw = ptr::null_mut();
        check(unsafe {
            sys::meshcast_blob_from_memory(bytes.as_ptr() as *const _, bytes.len() as u64, sys::MESHCAST_MEMORY_COPY,
                                           ptr::null(), &mut raw)
        })?;
        Ok(Blob { raw })
    }

    pub fn save(&self, path: &str) -> Result<()> {
        let path = c_string(path, "path")?;
        check(unsafe { sys::meshcast_blob_save(self.raw, path.as_ptr()) })
    }

    /// The blob's bytes, as long as it lives.
    pub fn bytes(&self) -> &[u8] {
        let (mut data, mut size) = (ptr::null(), 0u64);
        check(unsafe { sys::meshcast_blob_bytes(self.raw, &mut data, &mut size) }).expect("a live blob's bytes");
        unsafe { std::slice::from_raw_parts(data as *const u8, size as usize) }
    }

    fn info(&self) -> sys::meshcast_blob_info {
        let mut info = sys::meshcast_blob_info {
            struct_size: std::mem::size_of::<sys::meshcast_blob_info>() as u32,
            triangle_count: 0,
            bytes: 0,
            layout: ptr::null(),
            error_bound: 0.0,
        };
        check(unsafe { sys::meshcast_blob_info_get(self.raw, &mut info) }).expect("a live blob's info");
        info
    }
    pub fn triangle_count(&self) -> u32 {
        self.info().triangle_count
    }
    pub fn layout(&self) -> String {
        text(self.info().layout)
    }
    /// The stated error, a fraction of the mesh's diagonal (0: exact).
    pub fn error_bound(&self) -> f64 {
        self.info().error_bound
    }

    /// The hit of each ray into `hits` (at least as long); returns the rays
    /// not walkable (answered as misses).
    pub fn cast(&self, rays: &[Ray], hits: &mut [Hit], query: &Query) -> Result<u64> {
        room(hits.len(), rays.len(), "hits")?;
        let mut skipped = 0;
        check(unsafe {
            sys::meshcast_blob_cast(self.raw, rays.as_ptr(), rays.len() as u64, &query.raw(), hits.as_mut_ptr(),
                                    hits.len() as u64, &mut skipped)
        })?;
        Ok(skipped)
    }

    /// Every hit: `found[i]` along ray i, its nearest min(found[i],
    /// max_hits) at `hits[i * max_hits..]`.
    pub fn cast_all(&self, rays: &[Ray], max_hits: u32, found: &mut [u32], hits: &mut [Hit], query: &Query)
                    -> Result<u64> {
        room(found.len(), rays.len(), "found")?;
        room(hits.len(), rays.len() * max_hits as usize, "hits")?;
        let mut skipped = 0;
        check(unsafe {
            sys::meshcast_blob_cast_all(self.raw, rays.as_ptr(), rays.len() as u64, &query.raw(), max_hits,
                                        found.as_mut_ptr(), hits.as_mut_ptr(), hits.len() as u64, &mut skipped)
        })?;
        Ok(skipped)
    }

    /// The nearest point of the mesh to each point within `max_distance`.
    pub fn closest_points(&self, points: &[[f32; 3]], max_distance: f32, threads: u32) -> Result<Vec<ClosestPoint>> {
        let mut out = vec![ClosestPoint::default(); points.len()];
        check(unsafe {
            sys::meshcast_blob_closest_points(self.raw, points.as_ptr() as *const f32, points.len() as u64, max_distance,
                                              threads, out.as_mut_ptr(), out.len() as u64)
        })?;
        Ok(out)
    }
}

impl Drop for Blob {
    fn drop(&mut self) {
        unsafe { sys::meshcast_blob_release(self.raw) };
    }
}

/// An instance's placement: world = rotation_scale (row-major 3x3) mesh + translation.
pub type Transform = sys::meshcast_transform;

/// A translation alone.
pub fn translation(x: f64, y: f64, z: f64) -> Transform {
    Transform { rotation_scale: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0], translation: [x, y, z] }
}

/// Instances of blobs, with double-precision translations.
pub struct Scene {
    raw: *mut sys::meshcast_scene,
}

unsafe impl Send for Scene {}
unsafe impl Sync for Scene {}

impl Scene {
    pub fn new() -> Result<Scene> {
        let mut raw = ptr::null_mut();
        check(unsafe { sys::meshcast_scene_create(&mut raw) })?;
        Ok(Scene { raw })
    }
    /// The scene keeps the blob's bytes: the blob may be dropped after.
    /// The id is good with this scene alone: another scene refuses it
    /// (`MESHCAST_ERROR_USAGE`); its `index` counts meshes from 0.
    pub fn add_mesh(&mut self, blob: &Blob) -> Result<MeshId> {
        let mut id = MeshId::default();
        check(unsafe { sys::meshcast_scene_add_mesh(self.raw, blob.raw, &mut id) })?;
        Ok(id)
    }
    /// The id is good with this scene alone, as add_mesh's; its `index` is
    /// what hits report (`SceneHit::instance`).
    pub fn add_instance(&mut self, mesh: MeshId, transform: &Transform, mask: u8, flip_facing: bool)
                        -> Result<InstanceId> {
        let mut id = InstanceId::default();
        check(unsafe {
            sys::meshcast_scene_add_instance(self.raw, mesh, transform, mask as u32, flip_facing as u32, &mut id)
        })?;
        Ok(id)
    }
    pub fn set_transform(&mut self, instance: InstanceId, transform: &Transform) -> Result<()> {
        check(unsafe { sys::meshcast_scene_set_transform(self.raw, instance, transform) })
    }
    pub fn set_mask(&mut self, instance: InstanceId, mask: u8) -> Result<()> {
        check(unsafe { sys::meshcast_scene_set_mask(self.raw, instance, mask as u32) })
    }
    pub fn set_flip_facing(&mut self, instance: InstanceId, flip: bool) -> Result<()> {
        check(unsafe { sys::meshcast_scene_set_flip_facing(self.raw, instance, flip as u32) })
    }
    pub fn set_enabled(&mut self, instance: InstanceId, enabled: bool) -> Result<()> {
        check(unsafe { sys::meshcast_scene_set_enabled(self.raw, instance, enabled as u32) })
    }
    pub fn remove_instance(&mut self, instance: InstanceId) -> Result<()> {
        check(unsafe { sys::meshcast_scene_remove_instance(self.raw, instance) })
    }
    /// The edits so far, seen by the casts from now on.
    pub fn commit(&mut self) -> Result<()> {
        check(unsafe { sys::meshcast_scene_commit(self.raw) })
    }
    pub fn cast(&self, rays: &[RayD], hits: &mut [SceneHit], query: &Query) -> Result<u64> {
        room(hits.len(), rays.len(), "hits")?;
        let mut skipped = 0;
        check(unsafe {
            sys::meshcast_scene_cast(self.raw, rays.as_ptr(), rays.len() as u64, &query.raw(), hits.as_mut_ptr(),
                                     hits.len() as u64, &mut skipped)
        })?;
        Ok(skipped)
    }
    /// The nearest point to each point (in double), the world's distance.
    pub fn closest_points(&self, points: &[[f64; 3]], max_distance: f64, threads: u32)
                          -> Result<Vec<SceneClosestPoint>> {
        let mut out = vec![SceneClosestPoint::default(); points.len()];
        check(unsafe {
            sys::meshcast_scene_closest_points(self.raw, points.as_ptr() as *const f64, points.len() as u64,
                                               max_distance, 0xFF, threads, out.as_mut_ptr(), out.len() as u64)
        })?;
        Ok(out)
    }
}

impl Drop for Scene {
    fn drop(&mut self) {
        unsafe { sys::meshcast_scene_release(self.raw) };
    }
}

/// Where a caster's batches run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backend {
    Cpu,
    Vulkan,
    Automatic,
}

/// Batches cast a frame ahead on the CPU's workers or the GPU.
pub struct Caster {
    raw: *mut sys::meshcast_caster,
}

unsafe impl Send for Caster {}
unsafe impl Sync for Caster {}

impl Caster {
    /// `blob` None: a caster of scene batches alone.
    pub fn new(blob: Option<&Blob>, backend: Backend, threads: u32) -> Result<Caster> {
        let mut options = sys::meshcast_caster_options::default();
        unsafe { sys::meshcast_caster_options_init(&mut options) };
        options.backend = match backend {
            Backend::Cpu => sys::MESHCAST_BACKEND_CPU,
            Backend::Vulkan => sys::MESHCAST_BACKEND_VULKAN,
            Backend::Automatic => sys::MESHCAST_BACKEND_AUTOMATIC,
        };
        options.threads = threads;
        let mut raw = ptr::null_mut();
        check(unsafe { sys::meshcast_caster_create(blob.map_or(ptr::null(), |b| b.raw), &options, &mut raw) })?;
        Ok(Caster { raw })
    }
    pub fn submit(&self, rays: &[Ray], query: &Query) -> Result<Ticket> {
        let mut ticket = Ticket::default();
        check(unsafe { sys::meshcast_caster_submit(self.raw, rays.as_ptr(), rays.len() as u64, &query.raw(), &mut ticket) })?;
        Ok(ticket)
    }
    pub fn submit_scene(&self, scene: &Scene, rays: &[RayD], query: &Query) -> Result<Ticket> {
        let mut ticket = Ticket::default();
        check(unsafe {
            sys::meshcast_caster_submit_scene(self.raw, scene.raw, rays.as_ptr(), rays.len() as u64, &query.raw(),
                                              &mut ticket)
        })?;
        Ok(ticket)
    }
    pub fn poll(&self, ticket: &Ticket) -> Result<bool> {
        let mut ready = 0;
        check(unsafe { sys::meshcast_caster_poll(self.raw, ticket, &mut ready) })?;
        Ok(ready != 0)
    }
    /// Blocks until ready and writes the batch's hits.
    pub fn wait(&self, ticket: &Ticket, hits: &mut [Hit]) -> Result<()> {
        let mut record = sys::meshcast_batch_record::default();
        check(unsafe { sys::meshcast_caster_wait(self.raw, ticket, hits.as_mut_ptr(), hits.len() as u64, &mut record) })
    }
    pub fn wait_scene(&self, ticket: &Ticket, hits: &mut [SceneHit]) -> Result<()> {
        let mut record = sys::meshcast_batch_record::default();
        check(unsafe {
            sys::meshcast_caster_wait_scene(self.raw, ticket, hits.as_mut_ptr(), hits.len() as u64, &mut record)
        })
    }
    /// Where a batch of `rays` rays would go now, and why.
    pub fn backend_for(&self, rays: u32) -> Result<(Backend, String)> {
        let (mut backend, mut why) = (0u32, ptr::null());
        check(unsafe { sys::meshcast_caster_backend(self.raw, rays, &mut backend, &mut why) })?;
        let b = if backend == sys::MESHCAST_BACKEND_VULKAN { Backend::Vulkan } else { Backend::Cpu };
        Ok((b, text(why)))
    }
}

impl Drop for Caster {
    fn drop(&mut self) {
        unsafe { sys::meshcast_caster_release(self.raw) };
    }
}
