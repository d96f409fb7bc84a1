//! Local defect correction with THB-splines (paper §8.2 on a THB basis, issue 35) on a
//! shared geometry whose EGG map folds: puzzle4 solved without tensor repair folds next
//! to a puzzle neck; the pipeline's THB rounds refine only around the folded cells, solve EGG on the THB
//! discretization and end with a certified map that has fewer unknowns than the tensor
//! repair's.

use winslow::io::{read_boundary, ReadOptions};
use winslow::solve::options::{Refinement, SolveOptions};
use winslow::solve::report::Verdict;
use winslow::verify::certificate::hierarchical::certify_hierarchical;
use winslow::{Pipeline, Solved};

#[test]
fn puzzle4_is_repaired_with_fewer_unknowns_than_tensor_refinement() {
    let boundary = read_boundary(&winslow::testutil::data("gismo/puzzle4.json"), &ReadOptions::default()).unwrap();
    let mut thb_opts = SolveOptions::default();
    thb_opts.repair.refinement = Refinement::Thb;
    let Solved::Thb(out) = Pipeline::new(boundary.clone(), thb_opts).solve().unwrap() else {
        panic!("puzzle4 folds without tensor repair: the pipeline repairs it by THB refinement")
    };
    // the tensor solve without repair folds (or is undecided)
    assert!(
        matches!(out.report.solve.outcome.verdict, Verdict::Folded | Verdict::Undecided),
        "{:?}",
        out.report.solve.outcome.verdict
    );
    let tensor = Pipeline::new(boundary, SolveOptions::default()).solve().unwrap().into_map().unwrap();
    assert!(matches!(tensor.report.outcome.verdict, Verdict::Certified | Verdict::DegenerateCorner));
    let tensor_unknowns = 2 * tensor.map.control_points.len();

    assert!(out.success(), "{}", out.report.message);
    assert!(!out.report.thb_rounds.is_empty());
    // certified again from the map alone (what `winslow check` does with the file)
    let again = certify_hierarchical(&out.map, &Default::default()).unwrap();
    assert_eq!(Verdict::of_finding(&again.verdict), out.report.verdict);
    let thb_unknowns = 2 * out.map.basis.len();
    assert!(thb_unknowns < tensor_unknowns, "THB {thb_unknowns} vs tensor {tensor_unknowns}");
    // on its input basis (15 quadratic elements) the rounds start from the contour basis on
    // the input's coarsened levels (8, then 16 elements), smaller than the tensor map,
    // and end with at least 3x fewer functions than the tensor repair (BENCHMARKS.md "THB:
    // the contour start on input bases": 800 against 2,491)
    let start = &out.report.start;
    assert_eq!(start.basis, "contour", "{:?}", start.reason);
    assert!(
        start.functions < out.report.solve.setup.basis_functions,
        "{} vs {}",
        start.functions,
        out.report.solve.setup.basis_functions
    );
    assert_eq!(out.map.basis.knots(0)[0].num_elements(), 8);
    assert!(
        3 * out.map.basis.len() <= tensor.map.control_points.len(),
        "{} vs {}",
        out.map.basis.len(),
        tensor.map.control_points.len()
    );
}
