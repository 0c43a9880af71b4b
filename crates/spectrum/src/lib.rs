//! The 2D Gaussian light-transport algebra.
