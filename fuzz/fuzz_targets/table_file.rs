//! Fuzz target: [`cloudscape_fuzz::table_file`] on every input.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = cloudscape_fuzz::table_file(data);
});
