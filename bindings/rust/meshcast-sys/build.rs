// Links libmeshcast_c: from MESHCAST_LIB_DIR where it is set (a build
// folder, or an install prefix's lib), else from the system's paths.
fn main() {
    println!("cargo:rerun-if-env-changed=MESHCAST_LIB_DIR");
    if let Ok(dir) = std::env::var("MESHCAST_LIB_DIR") {
        println!("cargo:rustc-link-search=native={}", dir);
    }
    println!("cargo:rustc-link-lib=dylib=meshcast_c");
}
