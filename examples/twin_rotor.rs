//! A four-patch layout around two rotor contours (paper §11.2, Fig. 24-29), built from
//! the shared male rotor (`tests/data/rings/male_rotor_in_casing.json`, G+Smo's
//! `male_bdry2`) and solved with the multipatch machinery:
//!
//! 1. two rotors: the contour centred at `(-c, 0)` and its mirror image at `(c, 0)`, in a
//!    casing of two circles of radius `R` about the rotor centres, which meet at the two
//!    cusps `(0, ±sqrt(R² - c²))`;
//! 2. the **separator**: the four-sided domain between the rotors, bounded by the rotor
//!    pieces facing each other and two small curves through the cusps (from the rotor
//!    point nearest to a cusp, through the cusp, to the mirror point), solved as one
//!    patch and certified;
//! 3. the separator **split** by the image of a parameter curve from the top cusp to the
//!    bottom cusp (`--path shortest`: the shortest path in the map's metric) into two
//!    patches that share the splitting curve;
//! 4. two **C-grids**: the rest of each rotor against its casing arc, ending on the two
//!    small curves, which they share with the middle patches;
//! 5. the four-patch layout solved with fixed and with free interfaces, every patch
//!    certified.
//!
//! The paper's compressor has a female rotor and a clearance of a fraction of a
//! millimetre; the shared data have one (male) rotor, so the second rotor here is its
//! mirror image, and the casing radius is `R = 40` for rotors of radius 36 (centre
//! distance `2c = 76`), so that the rotors do not touch.
//!
//! `cargo run --release --example twin_rotor -- [OUT_DIR] [shortest|straight]`

use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::time::Instant;

use winslow::boundary::fit::{fit_side, FitOptions};
use winslow::boundary::ring::ClosedContour;
use winslow::io::Output;
use winslow::multipatch::split::{nearest_boundary_point, split_map, SplitOptions, SplitPath};
use winslow::multipatch::{Interface, Interfaces, Layout, Patch, PatchSide};
use winslow::solve::improve::Improve;
use winslow::solve::options::SolveOptions;
use winslow::{Analytic, Boundary, Curve, Pipeline, Point, Side, SideCurve, Solved};

type Res<T> = Result<T, Box<dyn std::error::Error>>;

const C: f64 = 38.0;
const R: f64 = 40.0;

/// A closed curve `t ∈ [0, 1) -> point` (wrapping).
#[derive(Clone)]
struct Closed(Curve);

impl Closed {
    fn at(&self, t: f64) -> Point {
        self.0.eval(t.rem_euclid(1.0))
    }
}

fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The parameter of the point of `c` nearest to `x` (sampled, then golden section).
fn nearest(c: &Closed, x: Point) -> f64 {
    let n = 20000;
    let k = (0..n)
        .min_by(|&a, &b| dist(c.at(a as f64 / n as f64), x).total_cmp(&dist(c.at(b as f64 / n as f64), x)))
        .unwrap();
    let (mut a, mut b) = ((k as f64 - 1.0) / n as f64, (k as f64 + 1.0) / n as f64);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..80 {
        let (c1, c2) = (b - g * (b - a), a + g * (b - a));
        if dist(c.at(c1), x) < dist(c.at(c2), x) {
            b = c2;
        } else {
            a = c1;
        }
    }
    0.5 * (a + b)
}

/// A cubic spline within `tol` of `f` on `[0, 1]`, with the ends `f(0)`, `f(1)` exactly.
fn fitted(f: impl Fn(f64) -> Point + Send + Sync + 'static, ends: (Point, Point), tol: f64) -> Res<Curve> {
    let mut opts = FitOptions::default();
    (opts.degree, opts.tol) = (3, tol);
    let fit = fit_side(Side::South, &SideCurve::Analytic(Analytic::new(f)), ends, &opts, tol)?;
    let mut c = fit.finest().clone();
    let last = c.control_points.len() - 1;
    c.control_points[0] = ends.0;
    c.control_points[last] = ends.1;
    Ok(c)
}

/// The piece `[t0, t1]` of `c`, parameterized by arc length and fitted by a cubic within
/// `tol` (its ends `c(t0)`, `c(t1)` exactly).
fn by_arc_length(c: &Curve, t0: f64, t1: f64, tol: f64) -> Res<Curve> {
    let n = 20000;
    let ts: Vec<f64> = (0..=n).map(|k| t0 + (t1 - t0) * k as f64 / n as f64).collect();
    let mut s = vec![0.0];
    for w in ts.windows(2) {
        s.push(s[s.len() - 1] + dist(c.eval(w[0]), c.eval(w[1])));
    }
    let total = s[n];
    let c2 = c.clone();
    let at = move |u: f64| {
        let x = u.clamp(0.0, 1.0) * total;
        let k = s.partition_point(|&v| v < x).clamp(1, n);
        let f = (x - s[k - 1]) / (s[k] - s[k - 1]).max(f64::MIN_POSITIVE);
        c2.eval(ts[k - 1] + f * (ts[k] - ts[k - 1]))
    };
    fitted(at, (c.eval(t0), c.eval(t1)), tol)
}

/// The quadratic through `a`, `m` (at t = 1/2) and `b`.
fn through(a: Point, m: Point, b: Point) -> Curve {
    let mid = [2.0 * m[0] - 0.5 * (a[0] + b[0]), 2.0 * m[1] - 0.5 * (a[1] + b[1])];
    Curve::new(winslow::KnotVector::open_uniform(2, 1), vec![a, mid, b], None).expect("three points")
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().collect();
    let out = PathBuf::from(args.get(1).map_or("out/twin_rotor", String::as_str));
    let path = match args.get(2).map(String::as_str) {
        Some("straight") => SplitPath::Straight,
        _ => SplitPath::Shortest,
    };
    std::fs::create_dir_all(&out)?;
    let t0 = Instant::now();
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/rings/male_rotor_in_casing.json");
    let winslow::Document::Ring(ring) = winslow::read(&data)? else { return Err("not a ring".into()) };
    let ClosedContour::Spline(rotor) = ring.inner else { return Err("the rotor is not a spline".into()) };
    let h = (R * R - C * C).sqrt();
    let (top, bot) = ([0.0, h], [0.0, -h]);
    // turn the rotor so that its seam (the ends of the clamped closed curve) is the corner
    // where the separator, the left C-grid and the curve through the top cusp meet: it
    // points from the left rotor's centre at the cusp
    let raw = rotor.normalized();
    let seam = raw.control_points[0];
    let phi = h.atan2(C) - seam[1].atan2(seam[0]);
    let (co, si) = (phi.cos(), phi.sin());
    let turned = Curve {
        control_points: raw.control_points.iter().map(|p| [co * p[0] - si * p[1], si * p[0] + co * p[1]]).collect(),
        ..raw.clone()
    };
    // left rotor at (-C, 0), counter-clockwise from and to the seam; the right one its
    // mirror image, reversed so that it runs counter-clockwise too
    let shift = |f: &dyn Fn(Point) -> Point| Curve {
        control_points: turned.control_points.iter().map(|&p| f(p)).collect(),
        ..turned.clone()
    };
    let left = shift(&|p| [p[0] - C, p[1]]);
    let right = shift(&|p| [C - p[0], p[1]]).reversed();
    let tb = nearest(&Closed(left.clone()), bot);
    // pieces by arc length, fitted (as the ring solve does with its contours): [0, tb]
    // runs from the seam the long way round the left rotor to the point nearest the
    // bottom cusp, [tb, 1] back up its right side; the right rotor likewise, mirrored
    let tol = 1e-4 * 4.0 * R;
    let l_long = by_arc_length(&left, 0.0, tb, tol)?;
    let l_short = by_arc_length(&left, tb, 1.0, tol)?;
    let r_short_down = by_arc_length(&right, 0.0, 1.0 - tb, tol)?;
    let r_long = by_arc_length(&right, 1.0 - tb, 1.0, tol)?;
    let (a_bot, a_top) = l_short.endpoints();
    let (b_top, b_bot) = r_short_down.endpoints();
    // separator: south and north through the cusps, west and east the facing rotor pieces
    let separator = Boundary {
        name: "separator".into(),
        sides: [through(a_bot, bot, b_bot), r_short_down.reversed(), through(a_top, top, b_top), l_short]
            .map(SideCurve::Spline),
    };
    let sep = winslow::solve(&separator, &SolveOptions::default())?;
    println!(
        "separator: {} ({:.3} s, {} functions, basis {})",
        sep.report.outcome.message,
        sep.report.solve.seconds,
        sep.report.setup.basis_functions,
        sep.report.setup.basis.used.name()
    );
    let separator_map =
        Output::Map { name: "separator", map: &sep.map, label: &sep.report.outcome.message, extra: None };
    winslow::write(&out.join("separator.json"), &separator_map)?;
    // split it from the top cusp to the bottom cusp through the map
    let (from, _) = nearest_boundary_point(&sep.map, top);
    let (to, _) = nearest_boundary_point(&sep.map, bot);
    let opts = SplitOptions { path, ..Default::default() };
    let split = split_map("middle", &sep.map, &sep.report.outcome.certificate, from, to, &opts)?;
    println!(
        "split ({:?}): curve of {} elements, length {:.4}, areas {:.3} / {:.3}",
        path, split.report.elements, split.report.length, split.report.areas[0], split.report.areas[1]
    );
    let [m1, m2] = [&split.layout.patches[0], &split.layout.patches[1]];
    // the C-grids: the rest of each rotor against its casing arc, ending on the pieces of
    // the curves through the cusps that the middle patches have
    let (top_l, bot_l) = (m1.side(Side::North).clone(), m1.side(Side::South).clone());
    let (top_r, bot_r) = (m2.side(Side::North).clone(), m2.side(Side::South).clone());
    let theta = h.atan2(C);
    let arc_l = fitted(
        move |t| {
            let a = theta + (2.0 * PI - 2.0 * theta) * t;
            [-C + R * a.cos(), R * a.sin()]
        },
        (top_l.endpoints().1, bot_l.endpoints().1),
        tol,
    )?;
    let arc_r = fitted(
        move |t| {
            let a = PI + theta + (2.0 * PI - 2.0 * theta) * t;
            [C + R * a.cos(), R * a.sin()]
        },
        (bot_r.endpoints().0, top_r.endpoints().0),
        tol,
    )?;
    let cl = Patch::from_sides("c-grid-left", [top_l, arc_l, bot_l, l_long]);
    let cr = Patch::from_sides("c-grid-right", [bot_r.reversed(), arc_r, top_r.reversed(), r_long]);
    let ps = |patch: usize, side: Side| PatchSide { patch, side };
    let iface = |a: PatchSide, b: PatchSide, reversed: bool| Interface { first: a, second: b, reversed };
    let layout = Layout {
        name: "twin-rotor".into(),
        patches: vec![cl, m1.clone(), m2.clone(), cr],
        interfaces: vec![
            iface(ps(1, Side::East), ps(2, Side::West), false),
            iface(ps(0, Side::South), ps(1, Side::North), false),
            iface(ps(0, Side::North), ps(1, Side::South), false),
            iface(ps(3, Side::South), ps(2, Side::South), true),
            iface(ps(3, Side::North), ps(2, Side::North), true),
        ],
    };
    winslow::write(&out.join("layout.json"), &Output::Layout(&layout))?;
    println!("layout written: {}", out.join("layout.json").display());
    for interfaces in [Interfaces::Fixed, Interfaces::Free] {
        // free interfaces: the layout improved by the Winslow functional
        let improve = (interfaces == Interfaces::Free).then_some(Improve::Winslow);
        let mut opts = SolveOptions::default();
        opts.improve = improve;
        let Solved::Layout { solution: sol, .. } = Pipeline::new(layout.clone(), opts).solve()? else {
            unreachable!("a layout's solve")
        };
        let r = &sol.report;
        println!("{} interfaces: {} ({:.3} s)", interfaces.name(), r.message, r.seconds);
        for p in &sol.patches {
            let [nx, ny] = p.map.shape();
            println!("  {:<13} {nx:>3}x{ny:<4} {}", p.name, p.certificate.message());
        }
        let img = winslow::io::picture::render_layout(&sol.maps(), &Default::default());
        winslow::write(&out.join(format!("twin_rotor_{}.png", interfaces.name())), &Output::Picture(&img))?;
    }
    println!("total {:.3} s", t0.elapsed().as_secs_f64());
    Ok(())
}
