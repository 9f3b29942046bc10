//! Links Intel Embree 3 when, and only when, the `embree` feature is on, so that everything else
//! builds on machines without the library. `EMBREE_LIB_DIR` adds a search path for a library
//! installed outside the system's.

fn main() {
    println!("cargo::rerun-if-env-changed=EMBREE_LIB_DIR");
    if std::env::var_os("CARGO_FEATURE_EMBREE").is_some() {
        if let Some(dir) = std::env::var_os("EMBREE_LIB_DIR") {
            println!("cargo::rustc-link-search=native={}", dir.to_string_lossy());
        }
        println!("cargo::rustc-link-lib=dylib=embree3");
    }
}
