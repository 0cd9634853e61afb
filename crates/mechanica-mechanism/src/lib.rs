//! Whole mechanisms (chapter 8): potentials with exact gradients and Hessians on a kinematic
//! tree, equilibrium, stability, and the small-oscillation modes of the mechanism.
