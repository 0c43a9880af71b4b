//! Photon and hitpoint storage with range queries: not yet built; filled by the issue
//! "`photon` and `ppm`: PPM, SPPM and frequency-guided PPM".
