//! Text to [`winslow::io::json::parse_json`], then validation, certification and the
//! writers' round trips ([`winslow::testutil::exercise`]); seeds: json_boundary documents.
#![no_main]

use libfuzzer_sys::fuzz_target;
use winslow::testutil::exercise::Reader;

fuzz_target!(|data: &[u8]| winslow_fuzz::fuzz_text(Reader::Json, data));
