#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| terramesh_fuzz::objects(data));
