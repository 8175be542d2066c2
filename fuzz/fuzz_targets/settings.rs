//! Settings files: `settings_from_str` on any UTF-8 text must not panic, and an error must
//! name the origin.

#![no_main]

use libfuzzer_sys::fuzz_target;
use penumbra::scene::settings_from_str;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    if let Err(err) = settings_from_str(text, "fuzz.ron") {
        let message = err.to_string();
        assert!(message.starts_with("fuzz.ron:"), "{message}");
    }
});
