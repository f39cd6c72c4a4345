//! Fuzz target: [`cloudscape_fuzz::sprite_model`] on every input.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = cloudscape_fuzz::sprite_model(data);
});
