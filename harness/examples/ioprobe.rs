use std::time::Instant;
use morphfx_harness::io::{self, ExrPrecision, OutputFormat};
fn main() {
    let p = std::path::Path::new("/tmp/mb/plates/a.0001.exr");
    for _ in 0..3 {
        let t = Instant::now();
        let plate = io::read(p).unwrap();
        let r = t.elapsed();
        let t = Instant::now();
        io::write_as(std::path::Path::new("/tmp/mb/probe.exr"), &plate, OutputFormat::new(ExrPrecision::Half)).unwrap();
        let w = t.elapsed();
        let t = Instant::now();
        io::write_as(std::path::Path::new("/tmp/mb/probe.exr"), &plate, OutputFormat { compression: exr::prelude::Compression::Uncompressed, ..OutputFormat::new(ExrPrecision::Half)}).unwrap();
        println!("read {:?} write zip {:?} write none {:?}", r, w, t.elapsed());
    }
}
