//! Point-cloud inputs without a parser in front: a contour (points and four corner
//! indices) split by [`winslow::io::json::split_contour`], or four point-cloud sides;
//! then [`winslow::boundary::validate`] and reorientation.
#![no_main]

use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use winslow::boundary::SideCurve;
use winslow::io::json::split_contour;
use winslow::testutil::exercise::exercise_sides;
use winslow_fuzz::{check, points, P};

#[derive(Debug, Arbitrary)]
enum Input {
    Contour { points: Vec<P>, corners: [u16; 4] },
    Sides([Vec<P>; 4]),
}

fuzz_target!(|input: Input| {
    let sides = match input {
        Input::Contour { points: p, corners } => match split_contour(&points(&p), corners.map(usize::from)) {
            Ok(sides) => sides,
            Err(e) => {
                assert!(winslow::testutil::exercise::informative(&e), "{e:?}");
                return;
            }
        },
        Input::Sides(s) => s.map(|p| points(&p)),
    };
    check(&exercise_sides(sides.map(SideCurve::Points)));
});
