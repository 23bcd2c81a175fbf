//! Texture files through the albedo decoder: the first byte picks the extension the file
//! claims (so a lying extension is tried too) and the import size limit (so the
//! downscale runs on small inputs); the rest is the file.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::sync::Once;
use unity::texture::{decode, Import};

/// The extensions the decoder accepts, and one it refuses.
const EXTENSIONS: [&str; 9] = ["png", "jpg", "tga", "tif", "exr", "psd", "hdr", "bmp", "dds"];

/// The `psd` crate panics on many malformed files; the decoder catches those panics and
/// reports a decode error, which is the behaviour under test. libfuzzer-sys's hook aborts
/// on every panic, caught or not, so it is replaced by a silent one: a panic the decoder
/// does not catch still reaches libfuzzer-sys's own `catch_unwind`, which aborts (a crash
/// with an artifact; reproduce it through `unity::texture::decode` to see the message).
static QUIET_PANICS: Once = Once::new();

fuzz_target!(|data: &[u8]| {
    QUIET_PANICS.call_once(|| std::panic::set_hook(Box::new(|_| {})));
    let Some((&select, bytes)) = data.split_first() else {
        return;
    };
    let ext = EXTENSIONS[select as usize % EXTENSIONS.len()];
    let import = Import {
        max_size: [2048, 64, 4, 1][(select as usize / EXTENSIONS.len()) % 4],
        ..Import::default()
    };
    if let Ok(t) = decode(bytes, ext, "Assets/fuzz", &import) {
        // Whatever the decoder accepts is a texture the soup reader accepts.
        assert!(t.validate().is_ok());
        assert!(t.width.max(t.height) <= import.max_size);
    }
});
