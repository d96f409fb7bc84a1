//! IGES 5.3 (Initial Graphics Exchange Specification): a map written as one rational
//! B-spline surface, entity type 128, which CAD systems and Gmsh import, and read back.
//!
//! A file is a sequence of 80-column records in five sections: Start (`S`, free text),
//! Global (`G`, delimiters, units, precision, author, version 11 = IGES 5.3), Directory
//! Entry (`D`, two records per entity), Parameter Data (`P`: the entity's numbers, in
//! columns 1-64, the directory pointer in 66-72) and Terminate (`T`, the record counts).
//!
//! Entity 128's parameters (IGES 5.3, §4.24): `128, K1, K2, M1, M2, PROP1..PROP5`, the
//! knot sequences `S(-M1)..S(N1+M1)` and `T(-M2)..T(N2+M2)` (`K + M + 2` values each),
//! the weights `W(i, j)` and control points `X, Y, Z` with the first index fastest, then
//! the parameter range `U0, U1, V0, V1`. `K1 + 1` is the number of control points in
//! `xi`, `M1` the degree; `PROP3 = 1` when the surface is polynomial (all weights 1).
//! Numbers are written in Rust's shortest round-trip form with `E` exponents, so the
//! round trip through [`parse_iges`] is exact.

use std::fmt::Write as _;

use super::gismo_writer::number;
use crate::error::{Error, Result, MAX_CONTROL_POINTS};
use crate::spline::knots::KnotVector;
use crate::spline::surface::Surface;

/// Entity type of a rational B-spline surface.
pub(crate) const RATIONAL_BSPLINE_SURFACE: usize = 128;

/// Hollerith string `nHtext` of the Global section.
fn hollerith(s: &str) -> String {
    format!("{}H{s}", s.len())
}

/// Cut `data` into records of `width` columns, breaking after a delimiter where possible,
/// each followed by `suffix(k)` (columns `width+1..=80`).
fn records(data: &str, width: usize, suffix: impl Fn(usize) -> String) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = data;
    while !rest.is_empty() {
        let cut = if rest.len() <= width {
            rest.len()
        } else {
            // last delimiter within the width; a token is never longer than the width
            rest[..width].rfind([',', ';']).map_or(width, |k| k + 1)
        };
        let (line, tail) = rest.split_at(cut);
        out.push(format!("{line:<width$}{}", suffix(out.len())));
        rest = tail;
    }
    out
}

fn section(letter: char, k: usize) -> String {
    format!("{letter}{:>7}", k + 1)
}

/// The IGES document of `map` as one entity 128. `comment` goes into the Start section
/// (e.g. the certificate's verdict); `name` is the file name of the Global section.
pub(crate) fn surface_to_iges(map: &Surface, name: &str, comment: &str) -> String {
    let e = |x: f64| number(x).replace('e', "E");
    let [kx, ky] = &map.knots;
    let (n1, n2) = (kx.num_basis(), ky.num_basis());
    let polynomial = map.weights.as_ref().is_none_or(|w| w.iter().all(|&v| v == 1.0));
    let mut p = format!(
        "{RATIONAL_BSPLINE_SURFACE},{},{},{},{},0,0,{},0,0",
        n1 - 1,
        n2 - 1,
        kx.degree(),
        ky.degree(),
        u8::from(polynomial)
    );
    for kv in [kx, ky] {
        for &k in kv.knots() {
            let _ = write!(p, ",{}", e(k));
        }
    }
    for k in 0..n1 * n2 {
        let _ = write!(p, ",{}", e(map.weights.as_ref().map_or(1.0, |w| w[k])));
    }
    for c in &map.control_points {
        let _ = write!(p, ",{},{},0.", e(c[0]), e(c[1]));
    }
    let (u, v) = (kx.domain(), ky.domain());
    let _ = write!(p, ",{},{},{},{};", e(u.0), e(u.1), e(v.0), e(v.1));

    let start = if comment.is_empty() { "winslow map".to_string() } else { format!("winslow map: {comment}") };
    let start: Vec<String> = records(&start, 72, |k| section('S', k));
    // the largest coordinate, for the Global section's "maximum coordinate value"
    let max = map.control_points.iter().fold(0.0f64, |m, c| m.max(c[0].abs()).max(c[1].abs()));
    let global = [
        "1H,".to_string(),
        "1H;".to_string(),
        hollerith("winslow"),
        hollerith(name),
        hollerith("winslow"),
        hollerith(env!("CARGO_PKG_VERSION")),
        "32".into(),
        "308".into(),
        "15".into(),
        "308".into(),
        "15".into(),
        hollerith("winslow"),
        "1.".into(),
        "1".into(),
        hollerith("MM"),
        "1".into(),
        "0.".into(),
        hollerith("20260101.000000"),
        "1.E-12".into(),
        e(max.max(1.0)),
        hollerith("winslow"),
        hollerith("winslow"),
        "11".into(),
        "0".into(),
        hollerith("20260101.000000"),
    ]
    .join(",")
        + ";";
    let global = records(&global, 72, |k| section('G', k));
    let params = records(&p, 64, |k| format!(" {:>7}{}", 1, section('P', k)));
    let directory = [
        format!(
            "{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{}",
            128,
            1,
            0,
            0,
            0,
            0,
            0,
            0,
            "00000000",
            section('D', 0)
        ),
        format!(
            "{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{}",
            128,
            0,
            0,
            params.len(),
            0,
            "",
            "",
            "",
            0,
            section('D', 1)
        ),
    ];
    let terminate = format!(
        "S{:>7}G{:>7}D{:>7}P{:>7}{:>40}{}",
        start.len(),
        global.len(),
        directory.len(),
        params.len(),
        "",
        section('T', 0)
    );
    let mut out = String::new();
    for line in start.iter().chain(&global).chain(&directory).chain(&params).chain(std::iter::once(&terminate)) {
        debug_assert_eq!(line.len(), 80, "{line:?}");
        out.push_str(line);
        out.push('\n');
    }
    out
}

fn iges_err(message: impl Into<String>) -> Error {
    Error::Invalid(format!("IGES: {}", message.into()))
}

/// Whether `text` looks like an IGES file: its first record has the section letter `S`
/// in column 73.
pub(crate) fn is_iges(text: &str) -> bool {
    text.lines().next().is_some_and(|l| l.len() >= 73 && l.as_bytes()[72] == b'S')
}

/// The first entity 128 of an IGES file, as a map on `[0, 1]²` (its parameter range
/// mapped there). Other entities are ignored; `Z` must be zero (a planar map).
pub fn parse_iges(text: &str) -> Result<Surface> {
    let mut params = String::new();
    let mut found = false;
    for (k, line) in text.lines().enumerate() {
        if line.len() < 73 {
            continue;
        }
        let Some(letter) = line.get(72..73) else {
            return Err(iges_err(format!("record {} is not ASCII", k + 1)));
        };
        if letter == "P" {
            let data = line.get(..64).ok_or_else(|| iges_err(format!("record {} is not ASCII", k + 1)))?;
            let owner = line.get(64..72).unwrap_or("").trim();
            if !found && data.trim_start().starts_with("128,") {
                found = true;
            }
            if found {
                params.push_str(data.trim_end());
                if data.contains(';') && owner == "1" {
                    break;
                }
            }
        }
    }
    if !found {
        return Err(iges_err("no rational B-spline surface (entity 128) in the Parameter Data section"));
    }
    let body = params.split(';').next().unwrap_or("");
    let values: Vec<f64> = body
        .split(',')
        .map(|t| {
            let t = t.trim().replace(['D', 'd'], "E");
            t.parse::<f64>().map_err(|_| iges_err(format!("not a number in entity 128: {t:?}")))
        })
        .collect::<Result<_>>()?;
    let int = |k: usize, what: &str| -> Result<usize> {
        let v = *values.get(k).ok_or_else(|| iges_err(format!("entity 128 ends before {what}")))?;
        if v < 0.0 || v.fract() != 0.0 || v > MAX_CONTROL_POINTS as f64 {
            return Err(iges_err(format!("{what} is {v}, expected a count")));
        }
        Ok(v as usize)
    };
    let (k1, k2, m1, m2) = (int(1, "K1")?, int(2, "K2")?, int(3, "M1")?, int(4, "M2")?);
    let (n1, n2) = (k1 + 1, k2 + 1);
    if n1.saturating_mul(n2) > MAX_CONTROL_POINTS {
        return Err(Error::TooLarge {
            context: "IGES entity 128".into(),
            what: "control points".into(),
            found: n1.saturating_mul(n2),
            limit: MAX_CONTROL_POINTS,
        });
    }
    let (a, b) = (n1 + m1 + 1, n2 + m2 + 1);
    let need = 10 + a + b + 4 * n1 * n2 + 4;
    if values.len() < need {
        return Err(iges_err(format!("entity 128 has {} values, expected {need}", values.len())));
    }
    let mut at = 10;
    let mut take = |n: usize| {
        let s = &values[at..at + n];
        at += n;
        s.to_vec()
    };
    let (su, sv) = (take(a), take(b));
    let w = take(n1 * n2);
    let xyz = take(3 * n1 * n2);
    let kv = |knots: Vec<f64>, p: usize, dir: &str| -> Result<KnotVector> {
        let kv = KnotVector::new(p, knots).map_err(|e| e.within(&format!("IGES entity 128, {dir} knots")))?;
        let (lo, hi) = kv.domain();
        super::normalized_knots(&kv).map_err(|e| e.within(&format!("IGES entity 128, {dir} knots [{lo}, {hi}]")))
    };
    let knots = [kv(su, m1, "first")?, kv(sv, m2, "second")?];
    let mut cps = Vec::with_capacity(n1 * n2);
    for (k, c) in xyz.chunks(3).enumerate() {
        if c[2] != 0.0 {
            return Err(iges_err(format!("control point {k} has z = {}: only planar maps are supported", c[2])));
        }
        cps.push([c[0], c[1]]);
    }
    let weights = w.iter().any(|&x| x != 1.0).then_some(w);
    Surface::new(knots, cps, weights).map_err(|e| e.within("IGES entity 128"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::Lcg;

    fn map(rational: bool) -> Surface {
        let mut rng = Lcg::new(3);
        let kx = KnotVector::open_uniform(3, 5).with_inserted(&[0.123456789]);
        let ky = KnotVector::open_uniform(2, 2);
        let (gx, gy) = (kx.greville(), ky.greville());
        let cps: Vec<[f64; 2]> = gy
            .iter()
            .flat_map(|&v| gx.iter().map(move |&u| [3e5 + u + v * v / 7.0, 2.0 * v - u / 3.0]))
            .map(|p| [p[0] + 1e-3 * rng.uniform(), p[1]])
            .collect();
        let weights = rational.then(|| (0..cps.len()).map(|k| 1.0 + 0.01 * k as f64).collect());
        Surface::new([kx, ky], cps, weights).unwrap()
    }

    /// Every record is 80 columns with its section letter and sequence number; the
    /// Terminate record counts the sections; the round trip is exact.
    #[test]
    fn records_and_round_trip() {
        for rational in [false, true] {
            let m = map(rational);
            let text = surface_to_iges(&m, "map.igs", "verdict certified, det J >= 0.1");
            let lines: Vec<&str> = text.lines().collect();
            let mut counts = std::collections::BTreeMap::new();
            for l in &lines {
                assert_eq!(l.len(), 80, "{l:?}");
                let letter = &l[72..73];
                let n = counts.entry(letter.to_string()).or_insert(0usize);
                *n += 1;
                assert_eq!(l[73..].trim().parse::<usize>().unwrap(), *n, "sequence numbers of {letter}");
            }
            let t = lines.last().unwrap();
            for (k, s) in ["S", "G", "D", "P"].iter().enumerate() {
                assert_eq!(&t[8 * k..8 * k + 1], *s);
                assert_eq!(t[8 * k + 1..8 * k + 8].trim().parse::<usize>().unwrap(), counts[*s]);
            }
            // the directory entry points at the first P record and gives their count
            let d: Vec<&str> = lines.iter().filter(|l| &l[72..73] == "D").copied().collect();
            assert_eq!(d[0][..8].trim(), "128");
            assert_eq!(d[1][24..32].trim().parse::<usize>().unwrap(), counts["P"]);
            assert!(is_iges(&text));
            let back = parse_iges(&text).unwrap();
            assert_eq!(back.knots, m.knots);
            assert_eq!(back.weights, m.weights);
            assert_eq!(back.control_points, m.control_points);
            // PROP3: polynomial flag
            let p: Vec<&str> = text.lines().filter(|l| &l[72..73] == "P").collect();
            assert_eq!(p[0].split(',').nth(7).unwrap(), if rational { "0" } else { "1" });
        }
    }

    #[test]
    fn malformed_files_are_errors() {
        assert!(parse_iges("hello").is_err());
        let good = surface_to_iges(&map(false), "m", "");
        let cut: String = good.lines().take(6).map(|l| format!("{l}\n")).collect();
        assert!(parse_iges(&cut).is_err());
        let bad = good.replacen("128,", "128,-3", 1);
        assert!(parse_iges(&bad).is_err());
    }
}
