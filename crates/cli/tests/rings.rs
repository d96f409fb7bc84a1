//! `winslow solve` on ring (O-grid) documents with a narrow gap: the §7.2 matching of
//! the two closed contours (`--reparam auto`) against arc length (`--reparam arclength`).

mod common;

use common::{bin, data};

/// A ring with a narrow gap (`rings/lobed_gap.json`): `--reparam auto` matches facing
/// points of the two contours at the same `eta` (§7.2 on closed curves), the map is
/// certified and its smallest scaled Jacobian beats arc length's (`--reparam
/// arclength`, no matches); the PNG is written with the pairs drawn.
#[test]
fn solve_ring_matches_a_narrow_gap() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path().join("ringmatch");
    let mut sj = Vec::new();
    for method in ["auto", "arclength"] {
        let map = dir.join(format!("{method}.json"));
        let png = dir.join(format!("{method}.png"));
        let out = bin()
            .arg("solve")
            .arg(data().join("rings/lobed_gap.json"))
            .args(["--reparam", method, "-o"])
            .arg(&map)
            .arg("--png")
            .arg(&png)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{}{err}", String::from_utf8_lossy(&out.stdout));
        assert_eq!(&std::fs::read(&png).unwrap()[1..4], b"PNG");
        let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&map).unwrap()).unwrap();
        let r = &doc["report"];
        let rp = &r["reparam"];
        // the report spells the methods in kebab case
        assert_eq!(rp["requested"], if method == "auto" { "auto" } else { "arc-length" });
        let gap = rp["gap_ratio"][1].as_f64().unwrap();
        assert!((gap - 0.002 / 8f64.sqrt()).abs() < 5e-5, "gap ratio {gap}");
        let matches = rp["matches"].as_array().unwrap();
        if method == "auto" {
            assert_eq!(rp["used"], "constrained");
            assert!(err.contains("reparameterization: constrained (requested auto)"), "{err}");
            let text = String::from_utf8_lossy(&out.stdout);
            assert!(text.contains("gap/diameter inner-outer ") && text.contains("inner/outer at "), "{text}");
            assert_eq!(format!("{gap:.2e}"), "7.20e-4", "the gap ratio the summary prints");
            assert!(matches.len() >= 3, "{matches:?}");
            assert_eq!(r["verdict"], "certified", "{}", r["message"]);
            for m in matches {
                assert_eq!(m["sides"], serde_json::json!(["inner", "outer"]));
                let t = m["parameter"].as_f64().unwrap();
                let p: Vec<Vec<f64>> = serde_json::from_value(m["points"].clone()).unwrap();
                assert!(t > 0.0 && t < 1.0 && p[1][0] > 0.9, "{m}");
                assert!((p[0][0] - p[1][0]).hypot(p[0][1] - p[1][1]) <= 0.02 * r["diameter"].as_f64().unwrap());
            }
        } else {
            assert_eq!(rp["used"], "arc-length");
            assert!(matches.is_empty());
        }
        sj.push(r["quality"]["scaled_jacobian"]["min"].as_f64().unwrap());
    }
    assert!(sj[0] > 10.0 * sj[1], "min scaled J matched {} vs arc length {}", sj[0], sj[1]);
}

/// A ring whose outer contour is a point cloud of a square with tight fillets (radius
/// 0.05 and 0.02 at spacing 0.02: four and two points per quarter circle) around a
/// circle: the fillets are roundings, not kinks, the ring fit follows them to its
/// tolerance (it bisects elements below `p + 1` samples near a rounded corner), and the
/// map certifies with its boundary within the fit tolerance: exit 0.
#[test]
fn a_ring_with_tight_fillets_certifies_within_the_fit_tolerance() {
    let scratch = tempfile::tempdir().unwrap();
    for (r, per_fillet) in [(0.05, 4), (0.02, 2)] {
        let outer = winslow::testutil::rounded_square(r, 0.02);
        let inner: Vec<[f64; 2]> = (0..256)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / 256.0 + 0.3;
                [t.cos(), t.sin()]
            })
            .collect();
        let ring =
            serde_json::json!({"name": "fillets", "ring": {"inner": {"points": inner}, "outer": {"points": outer}}});
        let input = scratch.path().join(format!("fillets-{per_fillet}.json"));
        winslow::io::write_bytes(&input, ring.to_string().as_bytes()).unwrap();
        let map = scratch.path().join(format!("fillets-{per_fillet}.map.json"));
        let out = bin().arg("solve").arg(&input).arg("-o").arg(&map).arg("--json").output().unwrap();
        let r = common::stdout_json(&out);
        assert_eq!(out.status.code(), Some(0), "{per_fillet} points per fillet: {}", r["message"]);
        assert_eq!(r["verdict"], "certified");
        assert_eq!(r["boundary_kept"], true);
        assert_eq!(r["kinks"].as_array().unwrap().len(), 0, "{}", r["kinks"]);
        assert_eq!(r["roundings"].as_array().unwrap().len(), 4, "{}", r["roundings"]);
        let tol = r["fit_tolerance"].as_f64().unwrap();
        let dev = r["boundary_deviation"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).fold(0.0, f64::max);
        assert!(dev <= tol, "{per_fillet} points per fillet: boundary {dev:e} from the cloud, tolerance {tol:e}");
        assert!(map.exists());
    }
}
