//! [`winslow::boundary::validate`] (and `inspect`, reorientation) on four sides built
//! directly: point clouds, spline curves whose fields are set by hand (so the
//! validator's own consistency checks are reached), uniform B-splines and analytic
//! polylines.
#![no_main]

use libfuzzer_sys::fuzz_target;
use winslow::testutil::exercise::exercise_sides;
use winslow_fuzz::{check, SideIn};

fuzz_target!(|sides: [SideIn; 4]| {
    let [a, b, c, d] = &sides;
    let (Some(a), Some(b), Some(c), Some(d)) = (a.side(), b.side(), c.side(), d.side()) else {
        return;
    };
    check(&exercise_sides([a, b, c, d]));
});
