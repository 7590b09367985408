//! Parametric CAD from boundary loops (Liu et al. 2018, step 3): closed cubic B-spline curves
//! fitted to a tolerance, uniformly and with adaptive knots ([`fit`], on [`bspline`]), written as IGES
//! entity 126 ([`iges`]) and DXF SPLINE ([`dxf`]).

pub mod bspline;
pub mod dxf;
pub mod fit;
pub mod iges;
