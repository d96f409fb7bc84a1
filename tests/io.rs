//! Input/output and validation of the shared geometries (copied to `tests/data/`) and of
//! malformed inputs.

use std::path::PathBuf;

use serde_json::{json, Value};
use winslow::boundary::validate::{inspect, Orientation};
use winslow::error::MAX_CONTROL_POINTS;
use winslow::io::{
    boundary_to_contour_json, boundary_to_json, checked_boundary, map_to_json, parse_document, parse_gismo_xml,
    parse_json, write_json, MAX_FILE_BYTES,
};
use winslow::testutil::{data, data_files, Lcg};
use winslow::{read, read_boundary, validate, Boundary, Document, Error, Point, ReadOptions, Side, SideCurve};

fn all_shared_files() -> Vec<PathBuf> {
    let mut v = data_files("", "json");
    v.extend(data_files("gismo", "json"));
    v.extend(data_files("gismo/xml", "xml"));
    v
}

#[test]
fn every_shared_geometry_loads_and_validates() {
    let files = all_shared_files();
    assert_eq!(files.len(), 6 + 13 + 13, "{files:?}");
    assert!(data("gismo/NOTICE.md").exists());
    for f in files {
        let t = std::time::Instant::now();
        let b = read_boundary(&f, &ReadOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        let r = validate(&b).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        assert_eq!(r.orientation, Orientation::CounterClockwise);
        assert!(r.signed_area > 0.0);
        assert!(r.corner_angles.iter().all(|a| a.is_finite() && *a > 0.0 && *a < 360.0), "{}: {r:?}", f.display());
        assert!(!b.name.is_empty());
        eprintln!(
            "{:<28} area {:>12.5e} diam {:>10.4} corners [{:.1}, {:.1}, {:.1}, {:.1}] deg, {} polyline points, {:.0} ms",
            f.strip_prefix(data("")).unwrap().display(),
            r.signed_area,
            r.diameter,
            r.corner_angles[0],
            r.corner_angles[1],
            r.corner_angles[2],
            r.corner_angles[3],
            r.polyline_points,
            t.elapsed().as_secs_f64() * 1e3
        );
    }
}

#[test]
fn corner_angles_of_known_geometries() {
    let angles =
        |rel: &str| validate(&read_boundary(&data(rel), &ReadOptions::default()).unwrap()).unwrap().corner_angles;
    // The disk: four quarter arcs meet at 180 degrees.
    for a in angles("gismo/disk.json") {
        assert!((a - 180.0).abs() < 1e-6, "{a}");
    }
    // Quarter annulus (arcs approximated by cubic splines): right angles.
    for a in angles("quarter_annulus.json") {
        assert!((a - 90.0).abs() < 0.05, "{a}");
    }
    // Cook's membrane: a quadrilateral with corners (0,0), (48,44), (48,60), (0,44).
    let c = angles("gismo/cooks_membrane.json");
    let sum: f64 = c.iter().sum();
    assert!((sum - 360.0).abs() < 1e-9, "{c:?}");
    assert!((c[0] - (90.0 - 44f64.atan2(48.0).to_degrees())).abs() < 1e-9, "{c:?}");
}

fn sides_agree(a: &Boundary, b: &Boundary, what: &str) {
    let diam = validate(a).unwrap().diameter;
    for s in Side::ALL {
        let (SideCurve::Spline(ca), SideCurve::Spline(cb)) = (a.side(s), b.side(s)) else {
            panic!("{what}: {s} is not a spline on both sides");
        };
        assert_eq!(ca.degree(), cb.degree(), "{what}: {s}");
        assert_eq!(ca.control_points.len(), cb.control_points.len(), "{what}: {s}");
        assert_eq!(ca.is_rational(), cb.is_rational(), "{what}: {s}");
        for (x, y) in ca.knots.knots().iter().zip(cb.knots.knots()) {
            assert!((x - y).abs() <= 1e-12, "{what}: {s} knots {x} vs {y}");
        }
        for k in 0..=200 {
            let u = k as f64 / 200.0;
            let (p, q) = (ca.eval(u), cb.eval(u));
            let d = (p[0] - q[0]).hypot(p[1] - q[1]);
            assert!(d <= 1e-12 * diam, "{what}: {s} at u = {u}: {p:?} vs {q:?}");
        }
    }
}

#[test]
fn gismo_xml_equals_json() {
    let xmls = data_files("gismo/xml", "xml");
    assert_eq!(xmls.len(), 13);
    for x in xmls {
        let stem = x.file_stem().unwrap().to_string_lossy().into_owned();
        let j = data(&format!("gismo/{stem}.json"));
        assert!(j.exists(), "{stem}");
        let from_xml = read_boundary(&x, &ReadOptions::default()).unwrap();
        let from_json = read_boundary(&j, &ReadOptions::default()).unwrap();
        assert_eq!(from_xml.name, stem);
        sides_agree(&from_xml, &from_json, &stem);
    }
}

#[test]
fn gismo_orientation_field_matches_the_assignment() {
    // The JSON files say whether xi and eta were swapped for counter-clockwise order; the
    // XML reader must reach the same conclusion (it does for male_casing_ring by transposing).
    for j in data_files("gismo", "json") {
        let v: Value = serde_json::from_str(&std::fs::read_to_string(&j).unwrap()).unwrap();
        let transposed = v["orientation"]["transposed_for_ccw"].as_bool().unwrap();
        let stem = j.file_stem().unwrap().to_string_lossy().into_owned();
        let text = std::fs::read_to_string(data(&format!("gismo/xml/{stem}.xml"))).unwrap();
        let raw = parse_gismo_xml(&text).unwrap();
        if let Document::Map { map, .. } = &raw {
            // transposed iff the file's patch has negative det J at its centre
            let d = map.derivs(0.5, 0.5, 1).det_j();
            assert!(transposed || d > 0.0 || stem == "lake", "{stem}: det J {d}");
        }
        assert_eq!(stem == "male_casing_ring", transposed, "{stem}");
    }
}

#[test]
fn map_round_trip_is_bit_exact() {
    for stem in ["rotor_sector", "plate_with_hole", "disk", "flapping_beam", "lake", "cooks_membrane"] {
        let Document::Map { name, map } = read(&data(&format!("gismo/xml/{stem}.xml"))).unwrap() else {
            panic!("{stem} is not a map");
        };
        assert_eq!(name, stem);
        let extra = json!({"report": {"iterations": 7, "residuals": [1e-3, 2.5e-9]}});
        let v = map_to_json(&name, &map, Some(extra.clone()));
        let text = serde_json::to_string_pretty(&v).unwrap();
        let Document::Map { name: name2, map: map2 } = parse_json(&text).unwrap() else { panic!() };
        assert_eq!(name2, name);
        assert_eq!(map2, map);
        let bits = |s: &winslow::Surface| -> Vec<u64> {
            let mut b: Vec<u64> = s.control_points.iter().flatten().map(|x| x.to_bits()).collect();
            b.extend(s.knots.iter().flat_map(|k| k.knots().iter().map(|x| x.to_bits())));
            b.extend(s.weights.iter().flatten().map(|x| x.to_bits()));
            b
        };
        assert_eq!(bits(&map2), bits(&map), "{stem}");
        let text2 = serde_json::to_string_pretty(&map_to_json(&name2, &map2, Some(extra))).unwrap();
        assert_eq!(text, text2, "{stem}");
        // The map document is also accepted as a boundary.
        let scratch = tempfile::tempdir().unwrap();
        let path = scratch.path().join(format!("{stem}-map.json"));
        write_json(&path, &v).unwrap();
        let b = read_boundary(&path, &ReadOptions::default()).unwrap();
        for s in Side::ALL {
            let SideCurve::Spline(c) = b.side(s) else { panic!() };
            let m = map.boundary(s);
            assert_eq!((&c.knots, &c.control_points), (&m.knots, &m.control_points), "{stem} {s}");
            let unit = |w: &Option<Vec<f64>>| w.clone().unwrap_or_else(|| vec![1.0; m.control_points.len()]);
            assert_eq!(unit(&c.weights), unit(&m.weights), "{stem} {s}");
        }
    }
}

#[test]
fn random_map_round_trip_is_bit_exact() {
    let mut rng = Lcg::new(7);
    let kv = |rng: &mut Lcg, p: usize| {
        let mut inner: Vec<f64> = (0..5).map(|_| rng.uniform()).collect();
        inner.sort_by(f64::total_cmp);
        let mut k = vec![0.0; p + 1];
        k.extend(inner);
        k.extend(vec![1.0; p + 1]);
        winslow::KnotVector::new(p, k).unwrap()
    };
    for _ in 0..20 {
        let (a, b) = (kv(&mut rng, 2), kv(&mut rng, 3));
        let n = a.num_basis() * b.num_basis();
        let cps: Vec<Point> = (0..n).map(|_| [rng.uniform() * 1e3 - 5e2, (rng.uniform() - 0.5) * 1e-7]).collect();
        let w: Vec<f64> = (0..n).map(|_| 0.1 + rng.uniform()).collect();
        let s = winslow::Surface::new([a, b], cps, Some(w)).unwrap();
        let text = serde_json::to_string(&map_to_json("r", &s, None)).unwrap();
        let Document::Map { map, .. } = parse_json(&text).unwrap() else { panic!() };
        assert_eq!(map, s);
    }
}

/// A star-shaped polygon with `n` vertices, counter-clockwise, first point repeated.
fn star(n: usize) -> Vec<Point> {
    let mut pts: Vec<Point> = (0..n)
        .map(|k| {
            let a = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
            let r = 1.0 + 0.2 * (5.0 * a).sin();
            [r * a.cos(), r * a.sin()]
        })
        .collect();
    pts.push(pts[0]);
    pts
}

#[test]
fn contour_document_round_trip() {
    let pts = star(64);
    let corners = [5usize, 20, 37, 50];
    let doc = json!({"name": "star", "note": "ignored", "contour": {"points": pts, "corners": corners}});
    let Document::Boundary(b) = parse_json(&doc.to_string()).unwrap() else { panic!() };
    assert_eq!(b.name, "star");
    let r = validate(&b).unwrap();
    assert!(r.signed_area > 3.0);
    let SideCurve::Points(south) = b.side(Side::South) else { panic!() };
    assert_eq!(south.len(), 16);
    assert_eq!(south[0], pts[5]);
    assert_eq!(south[15], pts[20]);
    let SideCurve::Points(north) = b.side(Side::North) else { panic!() };
    assert_eq!(north[0], pts[50]);
    assert_eq!(*north.last().unwrap(), pts[37]);
    let SideCurve::Points(west) = b.side(Side::West) else { panic!() };
    assert_eq!(west.len(), 64 - 50 + 5 + 1);
    assert_eq!(west[0], pts[5]);
    assert_eq!(*west.last().unwrap(), pts[50]);

    // boundary -> contour document -> boundary gives the same sides
    let back = boundary_to_contour_json(&b);
    let Document::Boundary(b2) = parse_json(&back.to_string()).unwrap() else { panic!() };
    // boundary -> boundary document -> boundary too
    let Document::Boundary(b3) = parse_json(&boundary_to_json(&b).to_string()).unwrap() else { panic!() };
    for s in Side::ALL {
        let (SideCurve::Points(p), SideCurve::Points(q), SideCurve::Points(r)) = (b.side(s), b2.side(s), b3.side(s))
        else {
            panic!()
        };
        assert_eq!(p, q, "{s}");
        assert_eq!(p, r, "{s}");
    }
    // Same polygon without the repeated point, through a file.
    let scratch = tempfile::tempdir().unwrap();
    let path = scratch.path().join("star-contour.json");
    write_json(&path, &json!({"name": "star", "contour": {"points": &pts[..64], "corners": corners}})).unwrap();
    let b4 = read_boundary(&path, &ReadOptions::default()).unwrap();
    for s in Side::ALL {
        let (SideCurve::Points(p), SideCurve::Points(q)) = (b.side(s), b4.side(s)) else { panic!() };
        assert_eq!(p, q, "{s}");
    }
}

#[test]
fn clockwise_contour_is_rejected_or_reoriented() {
    let mut pts = star(40);
    pts.reverse();
    // corners in the order of the (clockwise) polygon
    let doc = json!({"name": "cw", "contour": {"points": pts, "corners": [0, 10, 20, 30]}});
    let scratch = tempfile::tempdir().unwrap();
    let path = scratch.path().join("cw.json");
    write_json(&path, &doc).unwrap();
    let e = read_boundary(&path, &ReadOptions::default()).unwrap_err();
    assert!(matches!(e, Error::Clockwise { area } if area < 0.0), "{e}");
    assert!(e.to_string().contains("reorient"));
    let b = read_boundary(&path, &ReadOptions { reorient: true }).unwrap();
    let r = validate(&b).unwrap();
    assert_eq!(r.orientation, Orientation::CounterClockwise);
    assert!(r.signed_area > 0.0);
    // the transposed boundary: new south = old west
    let Document::Boundary(orig) = parse_json(&doc.to_string()).unwrap() else { panic!() };
    let (SideCurve::Points(s), SideCurve::Points(w)) = (b.side(Side::South), orig.side(Side::West)) else { panic!() };
    assert_eq!(s, w);
}

// ---------------------------------------------------------------------------------
// Bad inputs: the error kind, and the side named in the message.

fn line(a: Point, b: Point) -> Value {
    json!({"degree": 1, "knots": [0, 0, 1, 1], "control_points": [a, b], "weights": null})
}

fn square_doc() -> Value {
    json!({"name": "sq", "boundary": {
        "south": line([0., 0.], [1., 0.]),
        "east": line([1., 0.], [1., 1.]),
        "north": {"points": [[0., 1.], [0.5, 1.], [1., 1.]]},
        "west": line([0., 0.], [0., 1.]),
    }})
}

/// Parse a document and validate it as `read_boundary` does.
fn load(v: &Value) -> Result<Boundary, Error> {
    let doc = parse_json(&v.to_string())?;
    checked_boundary(doc.into_boundary()?, &ReadOptions::default()).map(|(b, _)| b)
}

#[test]
fn square_is_fine_and_extra_fields_are_ignored() {
    let mut d = square_doc();
    d["note"] = json!("x");
    d["report"] = json!({"a": 1});
    d["orientation"] = json!({"transposed_for_ccw": false});
    d["boundary"]["south"]["comment"] = json!("per-curve fields too");
    let b = load(&d).unwrap();
    assert_eq!(b.name, "sq");
}

#[test]
fn corner_gap_names_both_sides() {
    let mut d = square_doc();
    d["boundary"]["east"] = line([1.0 + 1e-6, 0.], [1., 1.]);
    let e = load(&d).unwrap_err();
    assert!(
        matches!(e, Error::CornerGap { ref side_a, ref side_b, gap, .. } if side_a == "south" && side_b == "east" && (gap - 1e-6).abs() < 1e-12),
        "{e}"
    );
    let msg = e.to_string();
    assert!(msg.contains("south") && msg.contains("east"), "{msg}");
    // a gap well inside the tolerance is fine
    d["boundary"]["east"] = line([1.0 + 1e-12, 0.], [1., 1.]);
    load(&d).unwrap();
}

#[test]
fn zero_length_side() {
    // a triangle whose south side collapsed into the south-west corner
    let d = json!({"name": "tri", "boundary": {
        "south": {"points": [[0., 0.], [0., 0.]]},
        "east": line([0., 0.], [1., 1.]),
        "north": line([0., 1.], [1., 1.]),
        "west": line([0., 0.], [0., 1.]),
    }});
    let e = load(&d).unwrap_err();
    assert!(matches!(e, Error::DegenerateSide { ref side, .. } if side == "south"), "{e}");
    assert!(e.to_string().contains("south"));
}

#[test]
fn too_few_points() {
    let mut d = square_doc();
    d["boundary"]["north"] = json!({"points": [[0., 1.]]});
    let e = load(&d).unwrap_err();
    assert!(matches!(e, Error::TooFewPoints { ref side, found: 1, .. } if side == "north"), "{e}");
    d["boundary"]["north"] = json!({"points": []});
    assert!(matches!(load(&d), Err(Error::TooFewPoints { found: 0, .. })));
}

#[test]
fn non_finite_numbers() {
    // JSON cannot carry NaN; an overflowing literal is a parse error (or infinity).
    let text = square_doc().to_string().replacen("0.5", "1e999", 1);
    assert!(text.contains("1e999"));
    let e = parse_json(&text).and_then(|d| checked_boundary(d.into_boundary()?, &ReadOptions::default()).map(|_| ()));
    assert!(matches!(e, Err(Error::Json { .. } | Error::NonFinite { .. })), "{e:?}");
    let text = square_doc().to_string().replacen("[0.0,0.0],[1.0,0.0]", "[0.0,0.0],[-1e400,0.0]", 1);
    assert!(matches!(parse_json(&text), Err(Error::Json { .. } | Error::NonFinite { .. })));
    assert!(matches!(parse_json(r#"{"boundary": NaN}"#), Err(Error::Json { .. })));
    // From the library a NaN can be built directly.
    let Document::Boundary(mut b) = parse_json(&square_doc().to_string()).unwrap() else { panic!() };
    b.sides[3] = SideCurve::Points(vec![[0., 0.], [f64::NAN, 0.5], [0., 1.]]);
    let e = validate(&b).unwrap_err();
    assert!(matches!(e, Error::NonFinite { .. }), "{e}");
    assert!(e.to_string().contains("boundary.west"), "{e}");
    // ... or an infinite control point
    let Document::Boundary(mut b) = parse_json(&square_doc().to_string()).unwrap() else { panic!() };
    if let SideCurve::Spline(c) = &mut b.sides[0] {
        c.control_points[1][0] = f64::INFINITY;
    }
    let e = validate(&b).unwrap_err();
    assert!(matches!(e, Error::NonFinite { .. }) && e.to_string().contains("boundary.south"), "{e}");
    // huge but finite coordinates: a size whose det J overflows f64 is out of range
    let mut d = square_doc();
    d["boundary"]["north"] = json!({"points": [[0., 1.], [1e308, -1e308], [-1e308, 1e308], [1., 1.]]});
    let e = load(&d).unwrap_err();
    assert!(matches!(e, Error::Range { .. }) && e.to_string().contains("half-width"), "{e}");
}

#[test]
fn self_intersection_names_the_sides() {
    let mut d = square_doc();
    // the north side dips below the south side
    d["boundary"]["north"] = json!({"points": [[0., 1.], [0.5, -0.5], [1., 1.]]});
    let e = load(&d).unwrap_err();
    assert!(
        matches!(e, Error::SelfIntersection { ref side_a, ref side_b, .. } if side_a == "south" && side_b == "north"),
        "{e}"
    );
    let msg = e.to_string();
    assert!(msg.contains("south") && msg.contains("north"), "{msg}");
    // a side crossing itself
    d["boundary"]["north"] = json!({"points": [[0., 1.], [0.6, 1.2], [0.6, 0.8], [0.4, 1.0], [1., 1.]]});
    let e = load(&d).unwrap_err();
    assert!(
        matches!(e, Error::SelfIntersection { ref side_a, ref side_b, .. } if side_a == "north" && side_b == "north"),
        "{e}"
    );
    // a spline side crossing: a quadratic bulging through the east side
    d["boundary"]["north"] = json!({"degree": 2, "knots": [0, 0, 0, 1, 1, 1],
        "control_points": [[0., 1.], [3., 0.5], [1., 1.]], "weights": null});
    let e = load(&d).unwrap_err();
    assert!(matches!(e, Error::SelfIntersection { .. }), "{e}");
    assert!(e.to_string().contains("east"), "{e}");
}

#[test]
fn narrow_gap_is_not_a_crossing() {
    // two concentric spline arcs 1e-4 apart (relative to the diameter) must pass
    let arc = |r: f64| {
        let m = 40;
        let cps: Vec<Point> = (0..=m)
            .map(|k| {
                let a = 1.5 * std::f64::consts::PI * k as f64 / m as f64;
                [r * a.cos(), r * a.sin()]
            })
            .collect();
        let mut knots = vec![0.0; 4];
        knots.extend((1..m - 2).map(|k| k as f64 / (m - 2) as f64));
        knots.extend([1.0; 4]);
        json!({"degree": 3, "knots": knots, "control_points": cps})
    };
    let (r0, r1) = (1.0, 1.0003);
    let a1 = 1.5 * std::f64::consts::PI;
    let d = json!({"name": "thin", "boundary": {
        "south": line([r0, 0.], [r1, 0.]),
        "east": arc(r1),
        "north": line([r0 * a1.cos(), r0 * a1.sin()], [r1 * a1.cos(), r1 * a1.sin()]),
        "west": arc(r0),
    }});
    let b = load(&d).unwrap();
    assert!(validate(&b).unwrap().signed_area > 0.0);
}

#[test]
fn wrong_lengths_decreasing_knots_weights_degree() {
    let mut d = square_doc();
    d["boundary"]["west"] = json!({"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0], [0, 0.5], [0, 1]]});
    let e = load(&d).unwrap_err();
    assert!(matches!(e, Error::Length { .. }) && e.to_string().contains("boundary.west"), "{e}");

    d["boundary"]["west"] =
        json!({"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0], [0, 1]], "weights": [1]});
    let e = load(&d).unwrap_err();
    assert!(matches!(e, Error::Length { .. }) && e.to_string().contains("boundary.west"), "{e}");

    d["boundary"]["west"] = json!({"degree": 1, "knots": [0, 0.6, 0.4, 1], "control_points": [[0, 0], [0, 1]]});
    let e = load(&d).unwrap_err();
    assert!(matches!(e, Error::Knots { .. }) && e.to_string().contains("boundary.west.knots"), "{e}");

    d["boundary"]["west"] =
        json!({"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0], [0, 1]], "weights": [1, -2]});
    let e = load(&d).unwrap_err();
    assert!(matches!(e, Error::Weight { index: 1, .. }) && e.to_string().contains("boundary.west"), "{e}");

    d["boundary"]["west"] =
        json!({"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0], [0, 1]], "weights": [1, 0]});
    assert!(matches!(load(&d), Err(Error::Weight { .. })));

    d["boundary"]["west"] = json!({"degree": 0, "knots": [0, 1], "control_points": [[0, 0]]});
    let e = load(&d).unwrap_err();
    assert!(matches!(e, Error::Degree { degree: 0, .. }) && e.to_string().contains("boundary.west"), "{e}");

    d["boundary"]["west"] = json!({"degree": -1, "knots": [0, 1], "control_points": [[0, 0]]});
    assert!(matches!(load(&d), Err(Error::Json { .. })));

    d["boundary"]["west"] = json!({"degree": 99, "knots": [0, 1], "control_points": [[0, 0]]});
    assert!(matches!(load(&d), Err(Error::Degree { .. })));

    d["boundary"]["west"] = json!({"points": [[0, 0, 3], [0, 1]]});
    let e = load(&d).unwrap_err();
    assert!(matches!(e, Error::Json { .. }) && e.to_string().contains("boundary.west"), "{e}");

    d["boundary"]["west"] = json!(42);
    assert!(matches!(load(&d), Err(Error::Json { .. })));

    let mut d = square_doc();
    d["boundary"].as_object_mut().unwrap().remove("east");
    let e = load(&d).unwrap_err();
    assert!(matches!(e, Error::Json { .. }) && e.to_string().contains("east"), "{e}");

    let e = load(&json!({"name": "nothing"})).unwrap_err();
    assert!(matches!(e, Error::Json { .. }));
    assert!(matches!(load(&json!({"name": 3, "boundary": {}})), Err(Error::Json { .. })));
    assert!(matches!(load(&json!([1, 2])), Err(Error::Json { .. })));
}

#[test]
fn bad_map_documents() {
    let good = json!({"name": "m", "map": {"degree": [1, 1], "knots": [[0, 0, 1, 1], [0, 0, 1, 1]],
        "control_points": [[0, 0], [1, 0], [0, 1], [1, 1]], "weights": null, "periodic": [false, false]}});
    assert!(parse_json(&good.to_string()).is_ok());
    let with = |path: &str, v: Value| {
        let mut d = good.clone();
        d["map"][path] = v;
        parse_json(&d.to_string()).unwrap_err()
    };
    assert!(matches!(with("control_points", json!([[0, 0], [1, 0], [0, 1]])), Error::Length { .. }));
    assert!(matches!(with("weights", json!([1, 1, 1, 0])), Error::Weight { index: 3, .. }));
    assert!(matches!(with("weights", json!([1, 1, 1])), Error::Length { .. }));
    assert!(matches!(with("degree", json!([0, 1])), Error::Degree { .. }));
    assert!(matches!(with("degree", json!([1])), Error::Json { .. }));
    assert!(matches!(with("knots", json!([[0, 0, 1, 1], [1, 1, 0, 0]])), Error::Knots { .. }));
    assert!(matches!(with("knots", json!([[0, 0, 1, 1]])), Error::Json { .. }));
    let e = with("knots", json!([[0, 0, 1, 1], [0, 0, 0, 0]]));
    assert!(e.to_string().contains("map.knots[1]"), "{e}");
}

#[test]
fn absurd_sizes() {
    // more points than MAX_CONTROL_POINTS
    let Document::Boundary(mut b) = parse_json(&square_doc().to_string()).unwrap() else { panic!() };
    let n = MAX_CONTROL_POINTS + 1;
    b.sides[2] = SideCurve::Points((0..n).map(|k| [k as f64 / (n - 1) as f64, 1.0]).collect());
    let e = validate(&b).unwrap_err();
    assert!(matches!(e, Error::TooLarge { .. }) && e.to_string().contains("boundary.north"), "{e}");
    // a contour with too many points
    let pts: Vec<Point> = (0..n).map(|k| [k as f64, 0.0]).collect();
    let e = winslow::io::split_contour(&pts, [0, 1, 2, 3]).unwrap_err();
    assert!(matches!(e, Error::TooLarge { .. }), "{e}");
    // a file larger than 256 MiB (sparse, so it costs no disk space)
    let scratch = tempfile::tempdir().unwrap();
    let path = scratch.path().join("huge.json");
    let f = std::fs::File::create(&path).unwrap();
    f.set_len(MAX_FILE_BYTES + 1).unwrap();
    drop(f);
    let e = read(&path).unwrap_err();
    assert!(matches!(e, Error::TooLarge { .. }), "{e}");
}

#[test]
fn truncated_and_mutated_inputs_never_panic() {
    let mut texts: Vec<String> = vec![square_doc().to_string()];
    for rel in ["gismo/xml/plate_with_hole.xml", "gismo/xml/duck.xml", "gismo/puzzle4.json", "gismo/xml/disk.xml"] {
        texts.push(std::fs::read_to_string(data(rel)).unwrap());
    }
    let mut rng = Lcg::new(42);
    let mut errors = 0;
    for t in &texts {
        let bytes = t.as_bytes();
        // every truncation point (on char boundaries)
        for cut in (0..bytes.len()).filter(|&c| t.is_char_boundary(c)) {
            if parse_document(&t[..cut]).and_then(|d| inspect(&d.into_boundary()?)).is_err() {
                errors += 1;
            }
        }
        // random byte replacements with structural characters and digits
        let alphabet = b"{}[]<>/\"=,.:-+e0123456789 \n";
        for _ in 0..400 {
            let mut b = bytes.to_vec();
            for _ in 0..1 + rng.below(4) {
                let i = rng.below(b.len());
                b[i] = alphabet[rng.below(alphabet.len())];
            }
            if let Ok(s) = String::from_utf8(b) {
                let _ = parse_document(&s).and_then(|d| inspect(&d.into_boundary()?));
            }
        }
    }
    assert!(errors > 1000);
}

#[test]
fn unnamed_documents_take_the_file_stem() {
    let mut d = square_doc();
    d.as_object_mut().unwrap().remove("name");
    let scratch = tempfile::tempdir().unwrap();
    let path = scratch.path().join("stemmed.json");
    write_json(&path, &d).unwrap();
    let b = read_boundary(&path, &ReadOptions::default()).unwrap();
    assert!(b.name.ends_with("stemmed"), "{}", b.name);
}

#[test]
fn analytic_sides_are_written_as_point_clouds() {
    let Document::Boundary(mut b) = parse_json(&square_doc().to_string()).unwrap() else { panic!() };
    b.sides[2] = SideCurve::Analytic(winslow::Analytic::new(|t| [t, 1.0 + 0.1 * (std::f64::consts::PI * t).sin()]));
    validate(&b).unwrap();
    let v = boundary_to_json(&b);
    assert_eq!(v["boundary"]["north"]["points"].as_array().unwrap().len(), 1025);
    let b2 = load(&v).unwrap();
    let SideCurve::Points(p) = b2.side(Side::North) else { panic!() };
    assert_eq!(p[512], [0.5, 1.1]);
}

/// `winslow::read` tells every kind of document apart: one bundled file of each kind,
/// and a solved multipatch result and a volume written by `winslow::write`.
#[test]
fn read_returns_the_kind_of_every_bundled_document() {
    for (rel, kind) in [
        ("wavy_lid.json", "boundary"),
        ("contours/star8.json", "boundary"),
        ("gismo/xml/duck.xml", "boundary"),
        ("maps/skewed_square.json", "map"),
        ("maps/quarter_annulus_nurbs.xml", "map"),
        ("gismo/xml/disk.xml", "map"),
        ("maps/skewed_square.igs", "map"),
        ("rings/eccentric_annulus.json", "ring"),
        ("gismo/xml/multipatch/plateWithHoleMP.xml", "multipatch layout"),
    ] {
        let doc = winslow::read(&data(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"));
        assert_eq!(doc.kind(), kind, "{rel}");
        assert!(!doc.name().is_empty(), "{rel}: named after the file at least");
    }
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    // a solved result: the G+Smo layout's patch maps as a JSON multipatch document
    let Document::Layout(layout) = winslow::read(&data("gismo/xml/multipatch/circleMP.xml")).unwrap() else {
        panic!("not a layout")
    };
    let n = layout.patches.len();
    let patches = winslow::io::Patches {
        layout: &layout,
        maps: layout.patches.iter().map(|p| p.map.clone().expect("G+Smo patches are maps")).collect(),
        reports: vec![Value::Null; n],
        messages: vec![String::new(); n],
        report: json!({}),
        message: String::new(),
    };
    let result = dir.join("result.json");
    winslow::write(&result, &winslow::Output::Multipatch(patches)).unwrap();
    assert_eq!(winslow::read(&result).unwrap().kind(), "multipatch result");
    // a volume, in JSON and G+Smo XML
    let k = winslow::KnotVector::open_uniform(1, 1);
    let cps = (0..8).map(|i| [(i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2) as f64]).collect();
    let volume = winslow::spline::volume::Volume::new([k.clone(), k.clone(), k], cps, None).unwrap();
    for file in ["cube.json", "cube.xml"] {
        let path = dir.join(file);
        winslow::write(&path, &winslow::Output::Volume { name: "cube", volume: &volume, label: "", extra: None })
            .unwrap();
        assert_eq!(winslow::read(&path).unwrap().kind(), "volume", "{file}");
    }
    // a general domain and a plane graph are read (and validated when laid out: a vertex
    // on no edge is named there)
    let domain = dir.join("domain.json");
    write_json(&domain, &json!({ "name": "d", "domain": { "outer": { "points": [[0, 0], [1, 0], [1, 1]] } } }))
        .unwrap();
    assert_eq!(winslow::read(&domain).unwrap().kind(), "domain");
    let graph = dir.join("graph.json");
    let triangle = json!([{ "from": 0, "to": 1 }, { "from": 1, "to": 2 }, { "from": 2, "to": 0 }]);
    write_json(&graph, &json!({ "name": "g", "graph": { "vertices": [[0, 0], [1, 0], [1, 1]], "edges": triangle } }))
        .unwrap();
    let Ok(winslow::Document::Graph(g)) = winslow::read(&graph) else { panic!("a graph") };
    let opts = winslow::domain::LayoutOptions::default();
    assert_eq!(winslow::domain::graph_layout(&g, &opts).unwrap().layout.patches.len(), 3);
    write_json(
        &graph,
        &json!({ "name": "g", "graph": { "vertices": [[0, 0], [1, 0], [1, 1], [2, 2]], "edges": triangle } }),
    )
    .unwrap();
    let Ok(winslow::Document::Graph(g)) = winslow::read(&graph) else { panic!("a graph") };
    let e = winslow::domain::graph_layout(&g, &opts).unwrap_err();
    assert!(matches!(&e, Error::Domain { .. }) && e.to_string().contains("vertex 3"), "{e}");
    // a ring is not a boundary: the error names both
    let e = read_boundary(&data("rings/eccentric_annulus.json"), &ReadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("a ring document, where a four-sided boundary"), "{e}");
}
