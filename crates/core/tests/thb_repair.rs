//! Local defect correction with THB-splines (paper §8.2 on a THB basis, issue 35) on a
//! shared geometry whose EGG map folds: puzzle4 solved without tensor repair folds next
//! to a puzzle neck; THB rounds refine only around the folded cells, solve EGG on the THB
//! discretization and end with a certified map that has fewer unknowns than the tensor
//! repair's.

use winslow::io::{read_boundary, ReadOptions};
use winslow::solve::hierarchical::{accepted, repair_thb, ThbRepairOptions};
use winslow::solve::options::{Refinement, SolveOptions};
use winslow::solve::report::Verdict;
use winslow::spline::hierarchical::map::HierarchicalMap;
use winslow::verify::certificate::hierarchical::certify_hierarchical;
use winslow::Pipeline;

#[test]
fn puzzle4_is_repaired_with_fewer_unknowns_than_tensor_refinement() {
    let boundary = read_boundary(&winslow::testutil::data("gismo/puzzle4.json"), &ReadOptions::default()).unwrap();
    let mut thb_opts = SolveOptions::default();
    thb_opts.repair.refinement = Refinement::Thb;
    let unrepaired = Pipeline::new(boundary.clone(), thb_opts.clone()).solve().unwrap().into_map().unwrap();
    assert!(
        matches!(unrepaired.report.verdict, Verdict::Folded | Verdict::Undecided),
        "{:?}",
        unrepaired.report.verdict
    );
    let tensor = Pipeline::new(boundary, SolveOptions::default()).solve().unwrap().into_map().unwrap();
    assert!(matches!(tensor.report.verdict, Verdict::Certified | Verdict::DegenerateCorner));
    let tensor_unknowns = 2 * tensor.map.control_points.len();

    let start = HierarchicalMap::from_surface(&unrepaired.map).unwrap();
    let out = repair_thb(start, &ThbRepairOptions::default()).unwrap();
    assert!(accepted(&out.certificate), "{}", out.certificate.message());
    assert!(!out.rounds.is_empty());
    // certified again from the map alone (what `winslow check` does with the file)
    assert!(accepted(&certify_hierarchical(&out.map, &Default::default()).unwrap()));
    let thb_unknowns = 2 * out.map.basis.len();
    assert!(thb_unknowns < tensor_unknowns, "THB {thb_unknowns} vs tensor {tensor_unknowns}");
}
