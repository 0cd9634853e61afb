//! C entry points of the mechanism crate: potentials, equilibrium, stability and modes on a
//! kinematic tree handle.
