// Compiles the FMI logger callback (c/logger.c): it is variadic, which stable Rust cannot define.
fn main() {
    println!("cargo:rerun-if-changed=c/logger.c");
    cc::Build::new()
        .file("c/logger.c")
        .warnings(true)
        .extra_warnings(true)
        .compile("contour_cosim_logger");
}
