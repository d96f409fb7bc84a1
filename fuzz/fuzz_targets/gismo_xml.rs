//! Text to [`winslow::io::parse_gismo_xml`] (four curves or one patch), then
//! validation, certification and the writers' round trips.
#![no_main]

use libfuzzer_sys::fuzz_target;
use winslow::testutil::exercise::Reader;

fuzz_target!(|data: &[u8]| winslow_fuzz::fuzz_text(Reader::Gismo, data));
