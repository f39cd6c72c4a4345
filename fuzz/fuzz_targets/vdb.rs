//! Fuzz target: [`cloudscape_fuzz::vdb`] on every input.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = cloudscape_fuzz::vdb(data);
});
