//! Multipatch domains (paper §11.2) on the shared G+Smo multipatch files
//! (`tests/data/gismo/xml/multipatch/`): reading, validation, conforming bases, solves
//! with fixed and free interfaces, and the round trip of the G+Smo multipatch writer.

use std::path::{Path, PathBuf};

use winslow::multipatch::classes::LayoutBases;
use winslow::multipatch::gismo::{multipatch_to_gismo_xml, parse_gismo_multipatch};
use winslow::multipatch::{validate_layout, Layout};

fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/gismo/xml/multipatch").join(rel)
}

fn read(name: &str) -> Layout {
    let text = std::fs::read_to_string(data(name)).unwrap();
    parse_gismo_multipatch(&text).unwrap()
}

#[test]
fn shared_multipatch_files_are_valid_layouts() {
    for (name, patches, interfaces) in [("TUDflame.xml", 5, 4), ("circleMP.xml", 5, 8), ("plateWithHoleMP.xml", 2, 1)] {
        let l = read(name);
        let r = validate_layout(&l).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!((r.patches, r.interfaces), (patches, interfaces), "{name}");
        assert!(r.interface_gap < 1e-9 * r.diameter, "{name}: {}", r.interface_gap);
        let b = LayoutBases::new(&l).unwrap();
        let sides = b.conforming_sides(&l).unwrap();
        for i in &l.interfaces {
            let a = &sides[i.first.patch][i.first.side as usize];
            let c = &sides[i.second.patch][i.second.side as usize];
            let mut cps = c.control_points.clone();
            if i.reversed {
                cps.reverse();
            }
            assert_eq!(a.control_points, cps, "{name}");
        }
    }
}

#[test]
fn gismo_multipatch_round_trip_is_exact() {
    for name in ["TUDflame.xml", "circleMP.xml", "plateWithHoleMP.xml"] {
        let l = read(name);
        let maps: Vec<_> = l.patches.iter().map(|p| p.map.clone().unwrap()).collect();
        let xml = multipatch_to_gismo_xml(&l, &maps, "round trip").unwrap();
        let back = parse_gismo_multipatch(&xml).unwrap();
        assert_eq!(back.interfaces, l.interfaces, "{name}");
        for (a, b) in back.patches.iter().zip(&l.patches) {
            assert_eq!(a.map, b.map, "{name}");
        }
        validate_layout(&back).unwrap();
    }
}
