//! Progressive photon mapping integrators: not yet built; filled by the issue
//! "`photon` and `ppm`: PPM, SPPM and frequency-guided PPM".
