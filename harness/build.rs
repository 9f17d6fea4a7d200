fn main() {
    println!("cargo:rerun-if-changed=src/host/varargs.c");
    cc::Build::new()
        .file("src/host/varargs.c")
        .warnings(true)
        .compile("morphfx_varargs");
}
