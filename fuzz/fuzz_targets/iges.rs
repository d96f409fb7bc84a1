//! Text to the IGES reader ([`Reader::Iges`]: the core's `io::iges::parse_iges`) and, by content, to
//! [`winslow::io::parse_document`]; then certification, the writers' round trips and
//! validation of the map's boundary.
#![no_main]

use libfuzzer_sys::fuzz_target;
use winslow::testutil::exercise::Reader;

fuzz_target!(|data: &[u8]| {
    winslow_fuzz::fuzz_text(Reader::Iges, data);
    winslow_fuzz::fuzz_text(Reader::Document, data);
});
