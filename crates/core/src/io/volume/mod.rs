//! Trivariate maps (volumes, [`crate::spline::volume::Volume`]) in files: the JSON map
//! document with three degrees and knot vectors ([`json`], the format of `formats.md`'s
//! "Trivariate map", plus a `periodic` field), G+Smo XML `TensorBSpline3` /
//! `TensorNurbs3` (read here in [`gismo`], written by
//! [`crate::io::gismo_writer::volume_to_gismo_xml`]) and VTK ([`vtk`]: a sampled
//! structured grid with `det J`, and the exact map as Bézier hexahedra).
//!
//! The six boundary faces of a volume (`formats-extensions.md`, "Volume boundary") are read from
//! JSON in [`boundary`], and from and to a G+Smo `<MultiPatch>` of six surfaces in
//! [`boundary_gismo`] (any order and orientation, identified by their shared edges).
//!
//! Volumes are read by [`crate::io::read`] (a JSON `map` whose `degree` has three
//! entries, or an XML file with a `TensorBSpline3` / `TensorNurbs3` geometry, gives a
//! [`crate::io::Document::Volume`]) and written by [`crate::io::write`].

pub mod boundary;
pub mod boundary_gismo;
pub mod gismo;
pub mod json;
pub mod vtk;

pub use boundary::volume_boundary_to_json;
pub use boundary_gismo::volume_boundary_to_gismo_xml;
