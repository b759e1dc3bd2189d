//! The safe crate against the C++ library (the meshcast program's own
//! casts of a public mesh, read from its hits file, where
//! MESHCAST_PROGRAM and MESHCAST_MESH name them), against answers known
//! from a mesh's construction, and its failures as `Err`s.
use meshcast::{Backend, Blob, Caster, Hit, Query, Ray, RayD, Scene, SceneHit};
use std::path::PathBuf;
use std::process::Command;

// Two unit squares, A at z = 0 (triangles 0, 1) and B at z = 1 (2, 3),
// split along x = y (triangles 0 and 2 hold x >= y).
const SQUARES: [f32; 24] = [0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0., 0., 0., 1., 1., 0., 1., 1., 1., 1., 0., 1., 1.];
const CORNERS: [u32; 12] = [0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7];

/// The meshcast program and the mesh the comparisons use.
fn program_and_mesh() -> (String, String) {
    match (std::env::var("MESHCAST_PROGRAM"), std::env::var("MESHCAST_MESH")) {
        (Ok(p), Ok(m)) => (p, m),
        _ => panic!("set MESHCAST_PROGRAM (the meshcast program) and MESHCAST_MESH (a mesh file) to run this test"),
    }
}

fn run_program(program: &str, args: &[&str]) {
    let status = Command::new(program).args(args).output().expect("the meshcast program runs").status;
    assert!(status.success(), "{} {:?}: {}", program, args, status);
}

/// The little-endian word at `at`.
fn word(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

fn down_at(x: f32, y: f32) -> Ray {
    meshcast::ray([x, y, 2.0], [0.0, 0.0, -1.0])
}

#[test]
fn answers_as_the_cpp_library_on_a_public_mesh() {
    let (program, mesh) = program_and_mesh();
    let scratch = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let blob_path = scratch.join("rs_mesh.blob");
    let run = |args: &[&str]| run_program(&program, args);
    run(&["build", &mesh, "--out", blob_path.to_str().unwrap()]);
    // Nothing rewrites the file while the blob lives: the test wrote it, and
    // only reads it from here on.
    let blob = unsafe { Blob::map(blob_path.to_str().unwrap()) }.unwrap();
    for kind in ["long", "probe", "radial", "segment"] {
        let rays_path = scratch.join(format!("rs_{}.rays", kind));
        let hits_path = scratch.join(format!("rs_{}.hits", kind));
        run(&["rays", &mesh, "--kind", kind, "--count", "20000", "--seed", "4", "--out", rays_path.to_str().unwrap()]);
        run(&["trace", blob_path.to_str().unwrap(), "--rays", rays_path.to_str().unwrap(), "--out",
              hits_path.to_str().unwrap()]);
        let rays_file = std::fs::read(&rays_path).unwrap();
        assert_eq!(&rays_file[..4], b"RAYS");
        let n = word(&rays_file, 4) as usize;
        let rays: Vec<Ray> = (0..n)
            .map(|i| {
                let f = |k: usize| f32::from_bits(word(&rays_file, 8 + 28 * i + 4 * k));
                Ray { org: [f(0), f(1), f(2)], dir: [f(3), f(4), f(5)], tmax: f(6), tmin: 0.0 }
            })
            .collect();
        let mut hits = vec![Hit::default(); n];
        blob.cast(&rays, &mut hits, &Query { threads: 0, ..Query::default() }).unwrap();
        let hits_file = std::fs::read(&hits_path).unwrap();
        assert_eq!(&hits_file[..4], b"HITS");
        let differ = (0..n)
            .filter(|&i| word(&hits_file, 8 + 8 * i) != hits[i].t.to_bits() || word(&hits_file, 12 + 8 * i) != hits[i].triangle)
            .count();
        assert_eq!(differ, 0, "{} rays: {} of {} answers differ from the C++ library's", kind, differ, n);
    }
}

/// A scene of the mesh twice (as it is, and turned a quarter about z and
/// halved, inside the first), cast by the meshcast program from a scene
/// file and through the crate from the same instances: every t, instance
/// and triangle the same, both instances hit.
#[test]
fn a_scene_answers_as_the_cpp_library() {
    let (program, mesh) = program_and_mesh();
    let scratch = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let (blob_path, scene_path) = (scratch.join("rs_scene_mesh.blob"), scratch.join("rs_scene.json"));
    let (rays_path, hits_path) = (scratch.join("rs_scene.rays"), scratch.join("rs_scene.hiti"));
    let run = |args: &[&str]| run_program(&program, args);
    run(&["build", &mesh, "--out", blob_path.to_str().unwrap()]);
    std::fs::write(&scene_path, "{\"meshes\": {\"m\": \"rs_scene_mesh.blob\"}, \"instances\": [{\"mesh\": \"m\"}, \
         {\"mesh\": \"m\", \"rotation_scale\": [0, -0.5, 0, 0.5, 0, 0, 0, 0, 0.5]}]}").unwrap();
    run(&["rays", &mesh, "--kind", "long", "--count", "20000", "--seed", "6", "--out", rays_path.to_str().unwrap()]);
    run(&["trace", scene_path.to_str().unwrap(), "--rays", rays_path.to_str().unwrap(), "--out",
          hits_path.to_str().unwrap()]);
    let rays_file = std::fs::read(&rays_path).unwrap();
    let n = word(&rays_file, 4) as usize;
    let rays: Vec<RayD> = (0..n)
        .map(|i| {
            let f = |k: usize| f32::from_bits(word(&rays_file, 8 + 28 * i + 4 * k));
            RayD { org: [f(0) as f64, f(1) as f64, f(2) as f64], dir: [f(3), f(4), f(5)], tmax: f(6), tmin: 0.0, reserved: 0 }
        })
        .collect();
    let blob = Blob::load(blob_path.to_str().unwrap()).unwrap();
    let mut scene = Scene::new().unwrap();
    let m = scene.add_mesh(&blob).unwrap();
    scene.add_instance(m, &meshcast::translation(0.0, 0.0, 0.0), 0xFF, false).unwrap();
    let turned = meshcast::Transform { rotation_scale: [0.0, -0.5, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.5], translation: [0.0; 3] };
    scene.add_instance(m, &turned, 0xFF, false).unwrap();
    scene.commit().unwrap();
    let mut hits = vec![SceneHit::default(); n];
    scene.cast(&rays, &mut hits, &Query { threads: 0, ..Query::default() }).unwrap();
    let file = std::fs::read(&hits_path).unwrap();
    assert_eq!((&file[..4], word(&file, 4) as usize), (&b"HITI"[..], n));
    let differ = (0..n)
        .filter(|&i| {
            (word(&file, 8 + 12 * i), word(&file, 12 + 12 * i), word(&file, 16 + 12 * i))
                != (hits[i].t.to_bits(), hits[i].instance, hits[i].triangle)
        })
        .count();
    let second = hits.iter().filter(|h| h.instance == 1).count();
    let found = hits.iter().filter(|h| h.triangle != meshcast::NO_HIT).count();
    assert_eq!(differ, 0, "{} of {} answers differ from the C++ library's", differ, n);
    assert!(second > 0 && second < found, "{} of {} hits on the second instance", second, found);
}

#[test]
fn known_answers_scenes_and_casters() {
    let blob = Blob::build(&SQUARES, &CORNERS, None).unwrap();
    assert_eq!(blob.triangle_count(), 4);
    assert!(blob.layout().starts_with("OctTreeCompressed/"));
    assert!(blob.error_bound() > 0.0, "the recommended layout is compact, with a stated bound");
    let rays = [down_at(0.75, 0.25), down_at(0.25, 0.75), down_at(3.0, 3.0)];
    let mut hits = [Hit::default(); 3];
    blob.cast(&rays, &mut hits, &Query::default()).unwrap();
    assert_eq!((hits[0].triangle, hits[0].t, hits[1].triangle), (2, 1.0, 3));
    assert_eq!(hits[2].triangle, meshcast::NO_HIT);
    blob.cast(&rays, &mut hits, &Query { cull: meshcast_sys::MESHCAST_CULL_FRONT, ..Query::default() }).unwrap();
    assert_eq!((hits[0].triangle, hits[1].triangle), (meshcast::NO_HIT, meshcast::NO_HIT));
    let (mut found, mut rows) = ([0u32; 3], [Hit::default(); 6]);
    blob.cast_all(&rays, 2, &mut found, &mut rows, &Query::default()).unwrap();
    assert_eq!((found, rows[0].triangle, rows[1].triangle, rows[1].t), ([2, 2, 0], 2, 0, 2.0));
    let near = blob.closest_points(&[[0.5, 0.5, 0.3]], f32::INFINITY, 1).unwrap();
    assert!((near[0].distance - 0.3).abs() < 1e-6 && near[0].triangle == 0);
    let copy = Blob::from_bytes(blob.bytes()).unwrap();
    assert_eq!(copy.triangle_count(), 4);

    let mut scene = Scene::new().unwrap();
    let mesh = scene.add_mesh(&blob).unwrap();
    let copy_for_second = Blob::from_bytes(blob.bytes()).unwrap();
    drop(blob); // the scene keeps its bytes
    let far = scene.add_instance(mesh, &meshcast::translation(1e9, 0.0, 0.0), 0xFF, false).unwrap();
    let near0 = scene.add_instance(mesh, &meshcast::translation(0.0, 0.0, 0.0), 1, false).unwrap();
    scene.commit().unwrap();
    let scene_rays = [meshcast::ray_d([1e9 + 0.75, 0.25, 2.0], [0.0, 0.0, -1.0]), meshcast::ray_d([0.25, 0.75, 2.0], [0.0, 0.0, -1.0])];
    let mut scene_hits = [SceneHit::default(); 2];
    scene.cast(&scene_rays, &mut scene_hits, &Query::default()).unwrap();
    assert_eq!((scene_hits[0].instance, scene_hits[0].triangle, scene_hits[0].t), (far.index, 2, 1.0));
    assert_eq!((scene_hits[1].instance, scene_hits[1].triangle), (near0.index, 3));
    // Another scene's ids are refused, though their indices are this one's too.
    let mut second = Scene::new().unwrap();
    let their_mesh = second.add_mesh(&copy_for_second).unwrap();
    let theirs = second.add_instance(their_mesh, &meshcast::translation(0.0, 0.0, 0.0), 0xFF, false).unwrap();
    assert_eq!((theirs.index, their_mesh.index), (far.index, mesh.index));
    let refused = scene.set_enabled(theirs, false).unwrap_err();
    assert!(refused.status == meshcast_sys::MESHCAST_ERROR_USAGE && refused.message.contains("another scene"), "{}", refused);
    let refused = scene.add_instance(their_mesh, &meshcast::translation(0.0, 0.0, 0.0), 0xFF, false).unwrap_err();
    assert!(refused.message.contains("another scene"), "{}", refused);
    scene.set_enabled(near0, false).unwrap();
    scene.commit().unwrap();
    scene.cast(&scene_rays, &mut scene_hits, &Query::default()).unwrap();
    assert_eq!(scene_hits[1].triangle, meshcast::NO_HIT);
    let point = scene.closest_points(&[[1e9 + 0.5, 0.5, 0.25]], f64::INFINITY, 1).unwrap();
    assert!(point[0].instance == far.index && (point[0].distance - 0.25).abs() < 1e-6);

    let caster = Caster::new(Some(&copy), Backend::Cpu, 2).unwrap();
    let other = Caster::new(Some(&copy), Backend::Cpu, 1).unwrap();
    let ticket = caster.submit(&rays, &Query::default()).unwrap();
    caster.poll(&ticket).unwrap();
    let refused = other.wait(&ticket, &mut hits).unwrap_err();
    assert_eq!(refused.status, meshcast_sys::MESHCAST_ERROR_USAGE, "another caster's ticket: {}", refused);
    caster.wait(&ticket, &mut hits).unwrap();
    assert_eq!((hits[0].triangle, hits[1].triangle, hits[2].triangle), (2, 3, meshcast::NO_HIT));
    let (backend, why) = caster.backend_for(1000).unwrap();
    assert!(backend == Backend::Cpu && !why.is_empty());
    let scenes = Caster::new(None, Backend::Cpu, 1).unwrap();
    let ticket = scenes.submit_scene(&scene, &scene_rays, &Query::default()).unwrap();
    drop(scene); // the batch keeps what it walks
    scenes.wait_scene(&ticket, &mut scene_hits).unwrap();
    assert_eq!((scene_hits[0].instance, scene_hits[1].triangle), (far.index, meshcast::NO_HIT));
}

#[test]
fn failures_are_errors_naming_what_is_wrong() {
    let mut nan = SQUARES;
    nan[4] = f32::NAN;
    let e = Blob::build(&nan, &CORNERS, None).err().unwrap();
    assert!(e.status == meshcast_sys::MESHCAST_ERROR_INPUT && e.message.contains("vertex 1"), "{}", e);
    let e = Blob::build(&SQUARES, &CORNERS, Some("NoSuchTree/Float3")).err().unwrap();
    assert!(e.message.contains("NoSuchTree"), "{}", e);
    let e = Blob::load("/no/such/file.blob").err().unwrap();
    assert!(e.status == meshcast_sys::MESHCAST_ERROR_INPUT && e.message.contains("/no/such/file.blob"), "{}", e);
    let e = Blob::from_bytes(&[0u8; 100]).err().unwrap();
    assert_eq!(e.status, meshcast_sys::MESHCAST_ERROR_INPUT, "{}", e);
    let blob = Blob::build(&SQUARES, &CORNERS, None).unwrap();
    let e = blob.cast(&[down_at(0.5, 0.5); 4], &mut [Hit::default(); 2], &Query::default()).unwrap_err();
    assert!(e.message.contains("fewer than the 4"), "{}", e);
    let e = blob.cast(&[down_at(0.5, 0.5)], &mut [Hit::default()], &Query { threads: 5000, ..Query::default() }).unwrap_err();
    assert!(e.message.contains("threads 5000"), "{}", e);
    let e = blob.save("/no/such/folder/x.blob").unwrap_err();
    assert_eq!(e.status, meshcast_sys::MESHCAST_ERROR_OUTPUT, "{}", e);
}
